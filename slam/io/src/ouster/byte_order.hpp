#pragma once
// Reads and writes of unaligned integers in byte buffers in a stated byte order. Callers
// check the bounds first; these never touch more than the bytes they name.

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace featsense::slam::detail {

/// The little-endian unsigned integer of sizeof(T) bytes at `data`.
template <typename T>
T load_le(const uint8_t* data) {
  static_assert(std::is_unsigned_v<T>, "unsigned integers only");
  T value = 0;
  for (size_t i = 0; i < sizeof(T); ++i)
    value |= static_cast<T>(static_cast<T>(data[i]) << (8 * i));
  return value;
}

/// The big-endian (network order) unsigned integer of sizeof(T) bytes at `data`.
template <typename T>
T load_be(const uint8_t* data) {
  static_assert(std::is_unsigned_v<T>, "unsigned integers only");
  T value = 0;
  for (size_t i = 0; i < sizeof(T); ++i) value = static_cast<T>((value << 8) | data[i]);
  return value;
}

/// A `bytes`-byte (<= 8) little-endian unsigned field at `data`, e.g. the u24 / u40 fields of
/// Ouster packet headers.
inline uint64_t load_le_bytes(const uint8_t* data, size_t bytes) {
  uint64_t value = 0;
  for (size_t i = 0; i < bytes && i < 8; ++i) value |= static_cast<uint64_t>(data[i]) << (8 * i);
  return value;
}

/// Writes the low `bytes` (<= 8) bytes of `value` little-endian at `data`: load_le_bytes's
/// inverse, for the packet and capture writers.
inline void store_le_bytes(uint8_t* data, uint64_t value, size_t bytes) {
  for (size_t i = 0; i < bytes && i < 8; ++i) data[i] = static_cast<uint8_t>(value >> (8 * i));
}

/// Byte-swaps a 32-bit value (pcap files written on big-endian hosts).
inline uint32_t byte_swap32(uint32_t v) {
  return ((v & 0xFFu) << 24) | ((v & 0xFF00u) << 8) | ((v >> 8) & 0xFF00u) | (v >> 24);
}

inline uint16_t byte_swap16(uint16_t v) { return static_cast<uint16_t>((v << 8) | (v >> 8)); }

}  // namespace featsense::slam::detail
