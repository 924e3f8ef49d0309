#pragma once
// The text header of a PLY file: format, elements and their properties.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cloud/scalar_type.hpp"

namespace featsense::slam::cloud {

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::kF32;  ///< of the value, or of a list's items
  bool is_list = false;
  ScalarType count_type = ScalarType::kU8;  ///< of a list's item count
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;

  bool has_lists() const;
  /// Bytes of one binary record, lists counted as empty (their least).
  size_t min_record_bytes() const;
};

struct PlyHeader {
  enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
  Format format = Format::kAscii;
  std::vector<PlyElement> elements;
  size_t data_offset = 0;           ///< first byte after "end_header"
  std::optional<int64_t> stamp_ns;  ///< from a "comment featsense stamp_ns N"
};

/// Parses and checks the header; throws InputError naming `origin`, the line and the problem.
PlyHeader parse_ply_header(std::string_view bytes, const std::string& origin);

}  // namespace featsense::slam::cloud
