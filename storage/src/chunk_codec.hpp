#pragma once
/// zlib compression of chunk payloads and the CRC-32 of journal records.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/storage/chunk.hpp"

namespace featsense::storage::detail {

std::vector<uint8_t> compress_bytes(const uint8_t* data, std::size_t size, int level);
/// Inflates `data`; throws std::runtime_error unless it yields exactly `expected_size` bytes.
std::vector<uint8_t> decompress_bytes(const std::vector<uint8_t>& data, std::size_t expected_size);

/// CRC-32 (zlib's polynomial) of `size` bytes, continuing from `crc` (0 to start).
uint32_t crc32_update(uint32_t crc, const void* data, std::size_t size);

}  // namespace featsense::storage::detail
