#include "cloud/scalar_type.hpp"

#include <string>

namespace featsense::slam::cloud {

const char* scalar_name(ScalarType type) {
  switch (type) {
    case ScalarType::kI8:
      return "I1";
    case ScalarType::kU8:
      return "U1";
    case ScalarType::kI16:
      return "I2";
    case ScalarType::kU16:
      return "U2";
    case ScalarType::kI32:
      return "I4";
    case ScalarType::kU32:
      return "U4";
    case ScalarType::kI64:
      return "I8";
    case ScalarType::kU64:
      return "U8";
    case ScalarType::kF32:
      return "F4";
    case ScalarType::kF64:
      return "F8";
  }
  return "?";
}

std::optional<ScalarType> ply_scalar_type(std::string_view name) {
  struct Entry {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", ScalarType::kI8},     {"int8", ScalarType::kI8},     {"uchar", ScalarType::kU8},
      {"uint8", ScalarType::kU8},    {"short", ScalarType::kI16},   {"int16", ScalarType::kI16},
      {"ushort", ScalarType::kU16},  {"uint16", ScalarType::kU16},  {"int", ScalarType::kI32},
      {"int32", ScalarType::kI32},   {"uint", ScalarType::kU32},    {"uint32", ScalarType::kU32},
      {"float", ScalarType::kF32},   {"float32", ScalarType::kF32}, {"double", ScalarType::kF64},
      {"float64", ScalarType::kF64},
  };
  for (const Entry& e : kTypes) {
    if (e.name == name) return e.type;
  }
  return std::nullopt;
}

std::optional<ScalarType> pcd_scalar_type(char type, long size) {
  switch (type) {
    case 'F':
      if (size == 4) return ScalarType::kF32;
      if (size == 8) return ScalarType::kF64;
      return std::nullopt;
    case 'U':
      if (size == 1) return ScalarType::kU8;
      if (size == 2) return ScalarType::kU16;
      if (size == 4) return ScalarType::kU32;
      if (size == 8) return ScalarType::kU64;
      return std::nullopt;
    case 'I':
      if (size == 1) return ScalarType::kI8;
      if (size == 2) return ScalarType::kI16;
      if (size == 4) return ScalarType::kI32;
      if (size == 8) return ScalarType::kI64;
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

}  // namespace featsense::slam::cloud
