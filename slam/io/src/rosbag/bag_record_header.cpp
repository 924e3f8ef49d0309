#include "rosbag/bag_record_header.hpp"

#include <cstring>

namespace featsense::slam {

BagRecordHeader BagRecordHeader::parse(ByteView bytes) {
  BagRecordHeader header;
  RosDeserializer in(bytes);
  while (in.remaining() > 0) {
    const size_t at = in.position();
    if (in.remaining() < 4) {
      throw BagFormatError("header field at byte " + std::to_string(at) +
                           " is cut off before its length");
    }
    const uint32_t length = in.u32("header field length");
    if (length > in.remaining()) {
      throw BagFormatError("header field at byte " + std::to_string(at) + " claims " +
                           std::to_string(length) + " bytes but only " +
                           std::to_string(in.remaining()) + " remain in the header");
    }
    const ByteView field = in.bytes(length, "header field");
    const void* equals = length > 0 ? std::memchr(field.data, '=', field.size) : nullptr;
    if (equals == nullptr) {
      throw BagFormatError("header field at byte " + std::to_string(at) + " has no '='");
    }
    const size_t name_size = static_cast<size_t>(static_cast<const uint8_t*>(equals) - field.data);
    header.fields_.push_back(
        {std::string_view(reinterpret_cast<const char*>(field.data), name_size),
         ByteView{field.data + name_size + 1, field.size - name_size - 1}});
  }
  return header;
}

std::optional<ByteView> BagRecordHeader::find(std::string_view name) const {
  for (const Field& field : fields_) {
    if (field.name == name) return field.value;
  }
  return std::nullopt;
}

ByteView BagRecordHeader::sized(std::string_view name, size_t size) const {
  const std::optional<ByteView> value = find(name);
  if (!value) throw BagFormatError("header field '" + std::string(name) + "' is missing");
  if (value->size != size) {
    throw BagFormatError("header field '" + std::string(name) + "' has " +
                         std::to_string(value->size) + " bytes, expected " + std::to_string(size));
  }
  return *value;
}

uint8_t BagRecordHeader::u8(std::string_view name) const {
  return load_le<uint8_t>(sized(name, 1).data);
}

uint32_t BagRecordHeader::u32(std::string_view name) const {
  return load_le<uint32_t>(sized(name, 4).data);
}

uint64_t BagRecordHeader::u64(std::string_view name) const {
  return load_le<uint64_t>(sized(name, 8).data);
}

int64_t BagRecordHeader::time_ns(std::string_view name) const {
  const ByteView value = sized(name, 8);
  const uint32_t sec = load_le<uint32_t>(value.data);
  const uint32_t nsec = load_le<uint32_t>(value.data + 4);
  return static_cast<int64_t>(sec) * 1000000000 + static_cast<int64_t>(nsec);
}

std::string BagRecordHeader::string(std::string_view name) const {
  const std::optional<ByteView> value = find(name);
  if (!value) throw BagFormatError("header field '" + std::string(name) + "' is missing");
  return std::string(value->as_string_view());
}

}  // namespace featsense::slam
