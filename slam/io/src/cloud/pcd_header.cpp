#include "cloud/pcd_header.hpp"

#include <map>

#include "cloud/text_lines.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam::cloud {
namespace {

constexpr size_t kMaxFields = 1024;
constexpr uint64_t kMaxCount = 1 << 16;

/// The header lines by keyword, each with its line number for messages.
struct HeaderLines {
  std::map<std::string, std::pair<std::vector<std::string_view>, size_t>> values;
  std::optional<int64_t> stamp_ns;
  size_t data_offset = 0;
};

HeaderLines read_lines(std::string_view bytes, const std::string& origin) {
  static const char* const kKeywords[] = {"VERSION",   "FIELDS", "COLUMNS", "SIZE",
                                          "TYPE",      "COUNT",  "WIDTH",   "HEIGHT",
                                          "VIEWPOINT", "POINTS", "DATA"};
  HeaderLines header;
  LineReader lines(bytes);
  while (const std::optional<std::string_view> line = lines.next()) {
    const std::string where = origin + ": line " + std::to_string(lines.line_number());
    if (!line->empty() && line->front() == '#') {
      if (!header.stamp_ns) header.stamp_ns = stamp_from_comment(line->substr(1));
      continue;
    }
    std::vector<std::string_view> words = split_words(*line);
    if (words.empty()) continue;
    std::string keyword(words.front());
    words.erase(words.begin());
    bool known = false;
    for (const char* k : kKeywords) known = known || keyword == k;
    if (!known) {
      throw InputError(where + ": '" + keyword.substr(0, 40) +
                       "' is not a PCD header keyword (no DATA line before it)");
    }
    if (keyword == "COLUMNS") keyword = "FIELDS";  // the name of PCD 0.5
    if (header.values.count(keyword)) throw InputError(where + ": " + keyword + " given twice");
    header.values[keyword] = {words, lines.line_number()};
    if (keyword == "DATA") {
      header.data_offset = lines.position();
      return header;
    }
  }
  throw InputError(origin + ": not a PCD file or a truncated header (no DATA line)");
}

uint64_t unsigned_value(const HeaderLines& header, const std::string& key,
                        const std::string& origin) {
  const auto& [words, line] = header.values.at(key);
  if (words.size() != 1) {
    throw InputError(origin + ": line " + std::to_string(line) + ": " + key + " needs one number");
  }
  const std::optional<uint64_t> value = parse_unsigned(words.front());
  if (!value) {
    throw InputError(origin + ": line " + std::to_string(line) + ": " + key + " '" +
                     std::string(words.front().substr(0, 40)) + "' is not a non-negative integer");
  }
  return *value;
}

}  // namespace

PcdHeader parse_pcd_header(std::string_view bytes, const std::string& origin) {
  const HeaderLines lines = read_lines(bytes, origin);
  auto require = [&](const char* key) -> const std::vector<std::string_view>& {
    const auto it = lines.values.find(key);
    if (it == lines.values.end()) throw InputError(origin + ": PCD header lacks " + key);
    return it->second.first;
  };
  auto line_of = [&](const char* key) {
    return origin + ": line " + std::to_string(lines.values.at(key).second) + ": ";
  };

  const auto& names = require("FIELDS");
  const auto& sizes = require("SIZE");
  const auto& types = require("TYPE");
  if (names.empty()) throw InputError(line_of("FIELDS") + "FIELDS lists no fields");
  if (names.size() > kMaxFields) throw InputError(line_of("FIELDS") + "too many FIELDS");
  auto check_length = [&](const char* key, size_t length) {
    if (length != names.size()) {
      throw InputError(line_of(key) + key + " lists " + std::to_string(length) + " values for " +
                       std::to_string(names.size()) + " FIELDS");
    }
  };
  check_length("SIZE", sizes.size());
  check_length("TYPE", types.size());
  const auto counts_it = lines.values.find("COUNT");
  if (counts_it != lines.values.end()) check_length("COUNT", counts_it->second.first.size());

  PcdHeader header;
  header.stamp_ns = lines.stamp_ns;
  for (size_t f = 0; f < names.size(); ++f) {
    const std::string name(names[f].substr(0, 64));
    const std::optional<uint64_t> size = parse_unsigned(sizes[f]);
    if (!size || *size > 8) {
      throw InputError(line_of("SIZE") + "SIZE of field '" + name + "' is not 1, 2, 4 or 8");
    }
    if (types[f].size() != 1) {
      throw InputError(line_of("TYPE") + "TYPE of field '" + name + "' is not F, U or I");
    }
    const std::optional<ScalarType> type =
        pcd_scalar_type(types[f].front(), static_cast<long>(*size));
    if (!type) {
      throw InputError(line_of("TYPE") + "field '" + name + "' has TYPE " + std::string(types[f]) +
                       " with SIZE " + std::to_string(*size) + ", which PCD does not allow");
    }
    uint64_t count = 1;
    if (counts_it != lines.values.end()) {
      const std::optional<uint64_t> c = parse_unsigned(counts_it->second.first[f]);
      if (!c || *c == 0 || *c > kMaxCount) {
        throw InputError(line_of("COUNT") + "COUNT of field '" + name + "' must be 1 .. " +
                         std::to_string(kMaxCount));
      }
      count = *c;
    }
    header.fields.push_back({name, *type, static_cast<size_t>(count)});
    header.offsets.push_back(header.point_size);
    header.point_size += static_cast<size_t>(*size * count);
    if (header.point_size > kMaxPointBytes) {
      throw InputError(line_of("SIZE") + "a point record of more than " +
                       std::to_string(kMaxPointBytes) + " bytes");
    }
  }

  require("WIDTH");
  header.width = unsigned_value(lines, "WIDTH", origin);
  if (lines.values.count("HEIGHT")) header.height = unsigned_value(lines, "HEIGHT", origin);
  if (header.width > kMaxPoints || header.height > kMaxPoints ||
      header.width * header.height > kMaxPoints) {
    throw InputError(line_of("WIDTH") + "WIDTH x HEIGHT = " + std::to_string(header.width) + " x " +
                     std::to_string(header.height) + " is beyond " + std::to_string(kMaxPoints) +
                     " points");
  }
  if (header.height == 0 && header.width != 0) {
    throw InputError(line_of("WIDTH") + "HEIGHT 0 with WIDTH " + std::to_string(header.width));
  }
  header.points = header.width * header.height;
  if (lines.values.count("POINTS")) {
    const uint64_t points = unsigned_value(lines, "POINTS", origin);
    if (points != header.points) {
      throw InputError(line_of("POINTS") + "POINTS " + std::to_string(points) +
                       " differs from WIDTH x HEIGHT = " + std::to_string(header.points));
    }
  }

  if (const auto it = lines.values.find("VIEWPOINT"); it != lines.values.end()) {
    const auto& words = it->second.first;
    if (words.size() != 7) throw InputError(line_of("VIEWPOINT") + "VIEWPOINT needs 7 numbers");
    static const double kIdentity[7] = {0, 0, 0, 1, 0, 0, 0};
    for (size_t i = 0; i < 7; ++i) {
      const std::optional<double> v = parse_number(words[i]);
      if (!v) throw InputError(line_of("VIEWPOINT") + "VIEWPOINT needs 7 numbers");
      header.viewpoint_identity = header.viewpoint_identity && *v == kIdentity[i];
    }
  }

  const auto& data = require("DATA");
  if (data.size() != 1) throw InputError(line_of("DATA") + "DATA needs one word");
  if (data.front() == "ascii") {
    header.data = PcdHeader::Data::kAscii;
  } else if (data.front() == "binary") {
    header.data = PcdHeader::Data::kBinary;
  } else if (data.front() == "binary_compressed") {
    header.data = PcdHeader::Data::kBinaryCompressed;
  } else {
    throw InputError(line_of("DATA") + "DATA '" + std::string(data.front().substr(0, 40)) +
                     "' is not ascii, binary or binary_compressed");
  }
  header.data_offset = lines.data_offset;
  return header;
}

}  // namespace featsense::slam::cloud
