#pragma once
/// Reading ROS 2 messages serialized as CDR (OMG XCDR version 1, as Fast DDS and Cyclone
/// DDS write it for ROS 2): a 4-byte encapsulation header (00 01 = little-endian, 00 00 =
/// big-endian; options ignored), then the fields, each primitive aligned to its own size
/// counted from the end of that header. string = u32 length counting a trailing NUL, then the
/// bytes; sequence = u32 count + elements; fixed array = elements only. Every read is checked
/// against the end of the buffer (SerializationError naming the field).

#include <cstdint>
#include <string>

#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

class CdrDeserializer {
 public:
  /// Checks the encapsulation header; throws SerializationError for a message shorter than it
  /// or of another representation (parameter lists, XCDR2).
  explicit CdrDeserializer(ByteView message);

  uint8_t u8(const char* what) { return *take(1, what); }
  uint16_t u16(const char* what) { return load<uint16_t>(what); }
  uint32_t u32(const char* what) { return load<uint32_t>(what); }
  int32_t i32(const char* what) { return static_cast<int32_t>(load<uint32_t>(what)); }
  uint64_t u64(const char* what) { return load<uint64_t>(what); }
  /// builtin_interfaces/Time (int32 sec, uint32 nanosec) as ns since the epoch.
  int64_t time_ns(const char* what) {
    const int32_t sec = i32(what);
    const uint32_t nanosec = u32(what);
    return static_cast<int64_t>(sec) * 1000000000 + static_cast<int64_t>(nanosec);
  }
  /// A string without its trailing NUL.
  std::string string(const char* what);
  /// `count` raw bytes (a uint8 array), viewed in place.
  ByteView bytes(size_t count, const char* what) { return {take(count, what), count}; }
  /// A sequence<uint8> (u32 count + bytes), viewed in place.
  ByteView byte_sequence(const char* what) { return bytes(u32(what), what); }

  size_t remaining() const { return body_.size - position_; }
  bool big_endian() const { return big_endian_; }

 private:
  template <typename T>
  T load(const char* what) {
    align(sizeof(T), what);
    T value = load_le<T>(take(sizeof(T), what));
    if (big_endian_) value = swapped(value);
    return value;
  }
  template <typename T>
  static T swapped(T value) {
    T out = 0;
    for (size_t i = 0; i < sizeof(T); ++i) {
      out = static_cast<T>((out << 8) | ((value >> (8 * i)) & 0xFF));
    }
    return out;
  }
  void align(size_t size, const char* what);
  const uint8_t* take(size_t count, const char* what);

  ByteView body_;  ///< after the encapsulation header
  size_t position_ = 0;
  bool big_endian_ = false;
};

}  // namespace featsense::slam
