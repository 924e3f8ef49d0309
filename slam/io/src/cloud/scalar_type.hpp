#pragma once
// The numeric types point-cloud files store, and loads of them from unaligned bytes in
// either byte order.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>

namespace featsense::slam::cloud {

enum class ScalarType { kI8, kU8, kI16, kU16, kI32, kU32, kI64, kU64, kF32, kF64 };

enum class ByteOrder { kLittle, kBig };

inline size_t size_of(ScalarType type) {
  switch (type) {
    case ScalarType::kI8:
    case ScalarType::kU8:
      return 1;
    case ScalarType::kI16:
    case ScalarType::kU16:
      return 2;
    case ScalarType::kI32:
    case ScalarType::kU32:
    case ScalarType::kF32:
      return 4;
    case ScalarType::kI64:
    case ScalarType::kU64:
    case ScalarType::kF64:
      return 8;
  }
  return 1;
}

inline bool is_integer(ScalarType type) {
  return type != ScalarType::kF32 && type != ScalarType::kF64;
}

/// A short name for messages: "F4", "U1", ... (PCD's TYPE and SIZE).
const char* scalar_name(ScalarType type);

/// PLY's type names (char uchar short ushort int uint float double and the int8 ... float64
/// aliases); nullopt for anything else.
std::optional<ScalarType> ply_scalar_type(std::string_view name);

/// PCD's TYPE letter (F, U, I) with its SIZE in bytes; nullopt for combinations PCD cannot
/// store (F1, U3, ...).
std::optional<ScalarType> pcd_scalar_type(char type, long size);

/// The unsigned integer of `n` bytes at `p` in `order` (n <= 8), without alignment needs.
inline uint64_t load_bits(const uint8_t* p, size_t n, ByteOrder order) {
  uint64_t bits = 0;
  for (size_t i = 0; i < n; ++i) {
    const size_t shift = 8 * (order == ByteOrder::kLittle ? i : n - 1 - i);
    bits |= static_cast<uint64_t>(p[i]) << shift;
  }
  return bits;
}

/// The value at `p` as a double (64-bit integers above 2^53 round).
inline double load_scalar(const uint8_t* p, ScalarType type, ByteOrder order) {
  const uint64_t bits = load_bits(p, size_of(type), order);
  switch (type) {
    case ScalarType::kI8:
      return static_cast<int8_t>(static_cast<uint8_t>(bits));
    case ScalarType::kU8:
    case ScalarType::kU16:
    case ScalarType::kU32:
      return static_cast<double>(bits);
    case ScalarType::kI16:
      return static_cast<int16_t>(static_cast<uint16_t>(bits));
    case ScalarType::kI32:
      return static_cast<int32_t>(static_cast<uint32_t>(bits));
    case ScalarType::kI64:
      return static_cast<double>(static_cast<int64_t>(bits));
    case ScalarType::kU64:
      return static_cast<double>(bits);
    case ScalarType::kF32: {
      const uint32_t narrow = static_cast<uint32_t>(bits);
      float value;
      std::memcpy(&value, &narrow, sizeof value);
      return static_cast<double>(value);
    }
    case ScalarType::kF64: {
      double value;
      std::memcpy(&value, &bits, sizeof value);
      return value;
    }
  }
  return 0.0;
}

/// Little-endian stores for the writers.
inline void store_le(uint8_t* p, uint64_t bits, size_t n) {
  for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(bits >> (8 * i));
}
inline void store_f32_le(uint8_t* p, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  store_le(p, bits, 4);
}

}  // namespace featsense::slam::cloud
