#include "ros2/cdr_deserializer.hpp"

namespace featsense::slam {
namespace {

constexpr size_t kEncapsulationBytes = 4;

}  // namespace

CdrDeserializer::CdrDeserializer(ByteView message) {
  if (message.size < kEncapsulationBytes) {
    throw SerializationError("CDR encapsulation header needs 4 bytes but the message has " +
                             std::to_string(message.size));
  }
  // Representation identifiers of the DDS-XTypes specification: CDR_BE 00 00, CDR_LE 00 01.
  if (message.data[0] != 0 || message.data[1] > 1) {
    throw SerializationError("CDR encapsulation " + std::to_string(message.data[0]) + " " +
                             std::to_string(message.data[1]) +
                             " is not plain CDR (00 00 or 00 01)");
  }
  big_endian_ = message.data[1] == 0;
  body_ = {message.data + kEncapsulationBytes, message.size - kEncapsulationBytes};
}

std::string CdrDeserializer::string(const char* what) {
  const uint32_t length = u32(what);
  const ByteView view = bytes(length, what);
  std::string text(view.as_string_view());
  if (!text.empty() && text.back() == '\0') text.pop_back();
  return text;
}

void CdrDeserializer::align(size_t size, const char* what) {
  const size_t padding = (size - position_ % size) % size;
  take(padding, what);
}

const uint8_t* CdrDeserializer::take(size_t count, const char* what) {
  if (count > remaining()) {
    throw SerializationError(std::string(what) + " needs " + std::to_string(count) +
                             " bytes at CDR byte " + std::to_string(position_) + " but only " +
                             std::to_string(remaining()) + " remain");
  }
  const uint8_t* p = body_.data + position_;
  position_ += count;
  return p;
}

}  // namespace featsense::slam
