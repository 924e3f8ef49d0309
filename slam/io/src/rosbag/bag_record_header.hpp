#pragma once
/// The header of a bag record: a sequence of fields, each a u32 length then `name=value`
/// (the value binary). Also used for the data of connection records, which has the same
/// layout.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// Record op codes of bag format 2.0.
enum class BagOp : uint8_t {
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07,
};

/// A record header that cannot be parsed; the message says which field and why.
class BagFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parsed header fields, viewing the bytes they were parsed from (which must outlive it).
class BagRecordHeader {
 public:
  struct Field {
    std::string_view name;
    ByteView value;
  };

  /// Splits `bytes` into fields; throws BagFormatError when a field length runs past the end
  /// or a field has no '='.
  static BagRecordHeader parse(ByteView bytes);

  /// The value of the first field of that name, if any.
  std::optional<ByteView> find(std::string_view name) const;
  /// Typed values; throw BagFormatError naming the field when it is missing or has the
  /// wrong size.
  uint8_t u8(std::string_view name) const;
  uint32_t u32(std::string_view name) const;
  uint64_t u64(std::string_view name) const;
  /// A ROS time field (u32 sec + u32 nsec) as nanoseconds since the epoch.
  int64_t time_ns(std::string_view name) const;
  std::string string(std::string_view name) const;

  /// The `op` field as a record type.
  BagOp op() const { return static_cast<BagOp>(u8("op")); }

  const std::vector<Field>& fields() const { return fields_; }

 private:
  ByteView sized(std::string_view name, size_t size) const;

  std::vector<Field> fields_;
};

}  // namespace featsense::slam
