#include "cloud/ply_header.hpp"

#include "cloud/text_lines.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam::cloud {
namespace {

constexpr size_t kMaxProperties = 1024;
constexpr size_t kMaxElements = 64;

}  // namespace

bool PlyElement::has_lists() const {
  for (const PlyProperty& p : properties) {
    if (p.is_list) return true;
  }
  return false;
}

size_t PlyElement::min_record_bytes() const {
  size_t bytes = 0;
  for (const PlyProperty& p : properties) bytes += size_of(p.is_list ? p.count_type : p.type);
  return bytes;
}

PlyHeader parse_ply_header(std::string_view bytes, const std::string& origin) {
  LineReader lines(bytes);
  const std::optional<std::string_view> magic = lines.next();
  if (!magic || *magic != "ply") throw InputError(origin + ": not a PLY file (no 'ply' line)");
  PlyHeader header;
  bool have_format = false;
  while (const std::optional<std::string_view> line = lines.next()) {
    const std::string where = origin + ": line " + std::to_string(lines.line_number()) + ": ";
    const std::vector<std::string_view> words = split_words(*line);
    if (words.empty()) continue;
    const std::string_view keyword = words.front();
    if (keyword == "comment" || keyword == "obj_info") {
      if (!header.stamp_ns && keyword == "comment") {
        header.stamp_ns = stamp_from_comment(line->substr(line->find("comment") + 7));
      }
      continue;
    }
    if (keyword == "end_header") {
      if (!have_format) throw InputError(where + "end_header before any format line");
      header.data_offset = lines.position();
      return header;
    }
    if (keyword == "format") {
      if (have_format) throw InputError(where + "format given twice");
      if (words.size() != 3 || words[2] != "1.0") {
        throw InputError(where +
                         "expected 'format ascii|binary_little_endian|"
                         "binary_big_endian 1.0'");
      }
      if (words[1] == "ascii") {
        header.format = PlyHeader::Format::kAscii;
      } else if (words[1] == "binary_little_endian") {
        header.format = PlyHeader::Format::kBinaryLittleEndian;
      } else if (words[1] == "binary_big_endian") {
        header.format = PlyHeader::Format::kBinaryBigEndian;
      } else {
        throw InputError(where + "unknown format '" + std::string(words[1].substr(0, 40)) + "'");
      }
      have_format = true;
      continue;
    }
    if (keyword == "element") {
      if (words.size() != 3) throw InputError(where + "expected 'element NAME COUNT'");
      const std::optional<uint64_t> count = parse_unsigned(words[2]);
      if (!count) {
        throw InputError(where + "element count '" + std::string(words[2].substr(0, 40)) +
                         "' is not a non-negative integer");
      }
      if (header.elements.size() == kMaxElements) throw InputError(where + "too many elements");
      header.elements.push_back({std::string(words[1].substr(0, 64)), *count, {}});
      continue;
    }
    if (keyword == "property") {
      if (header.elements.empty()) throw InputError(where + "property before any element");
      PlyElement& element = header.elements.back();
      if (element.properties.size() == kMaxProperties) {
        throw InputError(where + "too many properties");
      }
      PlyProperty property;
      if (words.size() == 5 && words[1] == "list") {
        const std::optional<ScalarType> count_type = ply_scalar_type(words[2]);
        const std::optional<ScalarType> item_type = ply_scalar_type(words[3]);
        if (!count_type || !item_type) {
          throw InputError(where + "unknown type in list property '" +
                           std::string(words[4].substr(0, 64)) + "'");
        }
        if (!is_integer(*count_type)) {
          throw InputError(where + "a list count must have an integer type");
        }
        property = {std::string(words[4].substr(0, 64)), *item_type, true, *count_type};
      } else if (words.size() == 3) {
        const std::optional<ScalarType> type = ply_scalar_type(words[1]);
        if (!type) {
          throw InputError(where + "unknown type '" + std::string(words[1].substr(0, 40)) +
                           "' of property '" + std::string(words[2].substr(0, 64)) + "'");
        }
        property = {std::string(words[2].substr(0, 64)), *type, false, ScalarType::kU8};
      } else {
        throw InputError(where +
                         "expected 'property TYPE NAME' or 'property list "
                         "COUNT_TYPE TYPE NAME'");
      }
      element.properties.push_back(property);
      continue;
    }
    throw InputError(where + "'" + std::string(keyword.substr(0, 40)) +
                     "' is not a PLY header keyword");
  }
  throw InputError(origin + ": truncated PLY header (no end_header)");
}

}  // namespace featsense::slam::cloud
