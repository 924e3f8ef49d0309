// decode_pcd(): the data section of a PCD file, ascii, binary or binary_compressed.

#include <lzf.h>

#include <cstring>

#include "cloud/cloud_assembler.hpp"
#include "cloud/pcd_header.hpp"
#include "cloud/text_lines.hpp"

namespace featsense::slam {
namespace {

using cloud::ByteOrder;
using cloud::CloudAssembler;
using cloud::PcdHeader;

/// LZF turns 3 bytes into at most 264 (a back reference of the longest length), so no
/// honest block expands by more than this.
constexpr uint64_t kMaxLzfRatio = 88;

/// Where the values of one field lie: the value of point i at base + i * stride.
struct FieldColumn {
  size_t field;
  const uint8_t* base;
  size_t stride;
  cloud::ScalarType type;
};

void read_columns(const std::vector<FieldColumn>& columns, CloudAssembler& assembler) {
  for (const FieldColumn& c : columns) {
    assembler.set_column(c.field, c.base, c.stride, c.type, ByteOrder::kLittle);
  }
}

/// Checks what the header promises against the bytes present, before anything is sized by
/// it: no lying header makes the reader allocate more than the file can fill.
void check_data_size(const PcdHeader& header, std::string_view data, const std::string& origin) {
  const uint64_t need = header.points * header.point_size;
  switch (header.data) {
    case PcdHeader::Data::kBinary:
      if (data.size() < need) {
        throw InputError(
            origin + ": binary data holds " + std::to_string(data.size()) +
            " bytes; the header promises POINTS x point size = " + std::to_string(header.points) +
            " x " + std::to_string(header.point_size) + " = " + std::to_string(need));
      }
      return;
    case PcdHeader::Data::kAscii: {
      size_t values_per_point = 0;
      for (const cloud::FileField& f : header.fields) values_per_point += f.count;
      // Each value takes a character and a separator at least.
      if (header.points * values_per_point > data.size()) {
        throw InputError(origin + ": ascii data of " + std::to_string(data.size()) +
                         " bytes cannot hold the " + std::to_string(header.points) +
                         " points the header promises");
      }
      return;
    }
    case PcdHeader::Data::kBinaryCompressed: {
      if (need == 0 && data.size() < 8) return;  // no points, no block
      if (data.size() < 8) {
        throw InputError(origin + ": binary_compressed data lacks its two sizes (" +
                         std::to_string(data.size()) + " bytes after the header)");
      }
      const auto* bytes = reinterpret_cast<const uint8_t*>(data.data());
      const uint64_t compressed = cloud::load_bits(bytes, 4, ByteOrder::kLittle);
      const uint64_t uncompressed = cloud::load_bits(bytes + 4, 4, ByteOrder::kLittle);
      if (compressed > data.size() - 8) {
        throw InputError(origin + ": binary_compressed block of " + std::to_string(compressed) +
                         " bytes, but only " + std::to_string(data.size() - 8) + " follow");
      }
      if (uncompressed != need) {
        throw InputError(origin + ": binary_compressed uncompressed size " +
                         std::to_string(uncompressed) +
                         " differs from POINTS x point size = " + std::to_string(need));
      }
      if (need > compressed * kMaxLzfRatio) {
        throw InputError(origin + ": binary_compressed block of " + std::to_string(compressed) +
                         " bytes cannot hold " + std::to_string(need) + " uncompressed bytes");
      }
      return;
    }
  }
}

void read_binary(const PcdHeader& header, std::string_view data, CloudAssembler& assembler) {
  const uint64_t need = header.points * header.point_size;
  if (data.size() > need) {
    assembler.warn(std::to_string(data.size() - need) + " bytes after the points ignored");
  }
  const auto* base = reinterpret_cast<const uint8_t*>(data.data());
  std::vector<FieldColumn> columns;
  for (size_t f = 0; f < header.fields.size(); ++f) {
    if (!assembler.used(f)) continue;
    columns.push_back({f, base + header.offsets[f], header.point_size, header.fields[f].type});
  }
  read_columns(columns, assembler);
}

void read_compressed(const PcdHeader& header, std::string_view data, const std::string& origin,
                     CloudAssembler& assembler) {
  const uint64_t need = header.points * header.point_size;
  if (need == 0) return;  // check_data_size() has made sure of the rest
  const auto* bytes = reinterpret_cast<const uint8_t*>(data.data());
  const uint32_t compressed = static_cast<uint32_t>(cloud::load_bits(bytes, 4, ByteOrder::kLittle));
  const uint32_t uncompressed =
      static_cast<uint32_t>(cloud::load_bits(bytes + 4, 4, ByteOrder::kLittle));
  std::vector<uint8_t> plain(static_cast<size_t>(need));
  const unsigned int got = lzf_decompress(bytes + 8, compressed, plain.data(), uncompressed);
  if (got != uncompressed) {
    throw InputError(origin + ": binary_compressed data is corrupt (LZF gave " +
                     std::to_string(got) + " of " + std::to_string(uncompressed) + " bytes)");
  }
  // Fields one after another: all values of field 0, then all of field 1, ...
  std::vector<FieldColumn> columns;
  size_t block = 0;
  for (size_t f = 0; f < header.fields.size(); ++f) {
    const size_t stride = cloud::size_of(header.fields[f].type) * header.fields[f].count;
    if (assembler.used(f))
      columns.push_back({f, plain.data() + block, stride, header.fields[f].type});
    block += stride * static_cast<size_t>(header.points);
  }
  read_columns(columns, assembler);
}

void read_ascii(const PcdHeader& header, std::string_view data, const std::string& origin,
                CloudAssembler& assembler) {
  size_t values_per_point = 0;
  for (const cloud::FileField& f : header.fields) values_per_point += f.count;
  cloud::LineReader lines(data);
  size_t point = 0;
  while (const std::optional<std::string_view> line = lines.next()) {
    const std::vector<std::string_view> words = cloud::split_words(*line);
    if (words.empty()) continue;
    if (point == header.points) {
      throw InputError(origin + ": ascii data holds more than the " +
                       std::to_string(header.points) + " points the header promises");
    }
    if (words.size() != values_per_point) {
      throw InputError(origin + ": ascii point " + std::to_string(point) + " has " +
                       std::to_string(words.size()) + " values, the header promises " +
                       std::to_string(values_per_point));
    }
    size_t word = 0;
    for (size_t f = 0; f < header.fields.size(); ++f) {
      if (assembler.used(f)) {
        const std::optional<double> value = cloud::parse_number(words[word]);
        if (!value) {
          throw InputError(origin + ": ascii point " + std::to_string(point) + ": '" +
                           std::string(words[word].substr(0, 40)) + "' is not a number");
        }
        assembler.set(point, f, *value);
      }
      word += header.fields[f].count;
    }
    ++point;
  }
  if (point != header.points) {
    throw InputError(origin + ": ascii data holds " + std::to_string(point) +
                     " points; the header promises " + std::to_string(header.points));
  }
}

}  // namespace

DecodedCloud decode_pcd(std::string_view bytes, const std::string& origin) {
  const PcdHeader header = cloud::parse_pcd_header(bytes, origin);
  const std::string_view data = bytes.substr(header.data_offset);
  const size_t points = static_cast<size_t>(header.points);
  check_data_size(header, data, origin);
  CloudAssembler assembler(header.fields, points, origin, /*require_float_xyz=*/true);
  if (!header.viewpoint_identity) assembler.warn("VIEWPOINT is not the identity; ignored");
  switch (header.data) {
    case PcdHeader::Data::kAscii:
      read_ascii(header, data, origin, assembler);
      break;
    case PcdHeader::Data::kBinary:
      read_binary(header, data, assembler);
      break;
    case PcdHeader::Data::kBinaryCompressed:
      read_compressed(header, data, origin, assembler);
      break;
  }
  const bool organized = header.height > 1;
  DecodedCloud decoded = assembler.finish("pcd", static_cast<int>(header.width),
                                          organized ? static_cast<int>(header.height) : 1);
  if (!organized) decoded.width = static_cast<int>(points);
  if (header.stamp_ns) decoded.stamp_ns = header.stamp_ns;
  return decoded;
}

}  // namespace featsense::slam
