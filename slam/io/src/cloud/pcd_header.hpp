#pragma once
// The text header of a PCD file (v0.7, and the older ones without VERSION), checked for
// consistency before any data is touched.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cloud/cloud_assembler.hpp"
#include "cloud/cloud_limits.hpp"

namespace featsense::slam::cloud {

struct PcdHeader {
  enum class Data { kAscii, kBinary, kBinaryCompressed };

  std::vector<FileField> fields;
  std::vector<size_t> offsets;  ///< byte offset of each field in a point record
  size_t point_size = 0;        ///< bytes per point record (sum of SIZE x COUNT)
  uint64_t width = 0;
  uint64_t height = 1;
  uint64_t points = 0;
  Data data = Data::kBinary;
  size_t data_offset = 0;           ///< first byte after the DATA line
  std::optional<int64_t> stamp_ns;  ///< from a "# featsense stamp_ns N" comment
  bool viewpoint_identity = true;
};

/// Parses and checks the header; throws InputError naming `origin`, the line and the lie.
PcdHeader parse_pcd_header(std::string_view bytes, const std::string& origin);

}  // namespace featsense::slam::cloud
