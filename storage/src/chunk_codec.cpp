#include "chunk_codec.hpp"

#include <zlib.h>

#include <stdexcept>
#include <string>

namespace featsense::storage::detail {

std::vector<uint8_t> compress_bytes(const uint8_t* data, std::size_t size, int level) {
  uLongf out_size = compressBound(static_cast<uLong>(size));
  std::vector<uint8_t> out(out_size);
  const int rc = compress2(out.data(), &out_size, data, static_cast<uLong>(size), level);
  if (rc != Z_OK)
    throw std::runtime_error("zlib compression failed (code " + std::to_string(rc) + ")");
  out.resize(out_size);
  return out;
}

std::vector<uint8_t> decompress_bytes(const std::vector<uint8_t>& data, std::size_t expected_size) {
  std::vector<uint8_t> out(expected_size);
  uLongf out_size = static_cast<uLongf>(expected_size);
  const int rc = uncompress(out.data(), &out_size, data.data(), static_cast<uLong>(data.size()));
  if (rc != Z_OK || out_size != expected_size) {
    throw std::runtime_error("corrupt compressed chunk (zlib code " + std::to_string(rc) + ", " +
                             std::to_string(out_size) + " of " + std::to_string(expected_size) +
                             " bytes)");
  }
  return out;
}

uint32_t crc32_update(uint32_t crc, const void* data, std::size_t size) {
  return static_cast<uint32_t>(
      crc32_z(crc, static_cast<const Bytef*>(data), static_cast<z_size_t>(size)));
}

}  // namespace featsense::storage::detail
