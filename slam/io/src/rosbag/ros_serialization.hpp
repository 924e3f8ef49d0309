#pragma once
/// Reading ROS1-serialized data: little-endian, unpadded; string = u32 length + bytes;
/// variable array = u32 count + elements; time = u32 sec + u32 nsec. Every read is checked
/// against the end of its buffer, so a corrupt length can never read past it.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

namespace featsense::slam {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "ROS data is little-endian; the readers load it with memcpy as host order");

/// A read-only view of bytes owned elsewhere (a chunk buffer, a message).
struct ByteView {
  const uint8_t* data = nullptr;
  size_t size = 0;

  std::string_view as_string_view() const { return {reinterpret_cast<const char*>(data), size}; }
};

/// A little-endian value of type T at `p` (any alignment).
template <typename T>
T load_le(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

/// Serialized data that ends before a field does.
class SerializationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A cursor over one serialized message (or header); throws SerializationError naming the
/// field when a read would pass the end.
class RosDeserializer {
 public:
  explicit RosDeserializer(ByteView bytes) : bytes_(bytes) {}

  uint8_t u8(const char* what) { return load_le<uint8_t>(take(1, what)); }
  uint16_t u16(const char* what) { return load_le<uint16_t>(take(2, what)); }
  uint32_t u32(const char* what) { return load_le<uint32_t>(take(4, what)); }
  uint64_t u64(const char* what) { return load_le<uint64_t>(take(8, what)); }
  /// A ROS time (u32 sec, u32 nsec) as nanoseconds since the epoch.
  int64_t time_ns(const char* what) {
    const uint32_t sec = u32(what);
    const uint32_t nsec = u32(what);
    return static_cast<int64_t>(sec) * 1000000000 + static_cast<int64_t>(nsec);
  }
  /// A string: u32 length + bytes.
  std::string string(const char* what) {
    const ByteView view = bytes(u32(what), what);
    return std::string(view.as_string_view());
  }
  /// `count` raw bytes, viewed in place.
  ByteView bytes(size_t count, const char* what) { return {take(count, what), count}; }
  /// A u8[] (u32 count + bytes), viewed in place.
  ByteView byte_array(const char* what) { return bytes(u32(what), what); }

  size_t remaining() const { return bytes_.size - position_; }
  size_t position() const { return position_; }

 private:
  const uint8_t* take(size_t count, const char* what) {
    if (count > remaining()) {
      throw SerializationError(std::string(what) + " needs " + std::to_string(count) +
                               " bytes at byte " + std::to_string(position_) + " but only " +
                               std::to_string(remaining()) + " remain");
    }
    const uint8_t* p = bytes_.data + position_;
    position_ += count;
    return p;
  }

  ByteView bytes_;
  size_t position_ = 0;
};

}  // namespace featsense::slam
