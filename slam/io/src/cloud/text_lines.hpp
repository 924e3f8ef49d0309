#pragma once
// Line and word splitting for the text headers of PCD and PLY files.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace featsense::slam::cloud {

/// Reads `bytes` line by line; lines end at '\n', a trailing '\r' is dropped.
class LineReader {
 public:
  explicit LineReader(std::string_view bytes) : bytes_(bytes) {}

  /// The next line, or nullopt at the end of the bytes.
  std::optional<std::string_view> next() {
    if (pos_ >= bytes_.size()) return std::nullopt;
    const size_t end = bytes_.find('\n', pos_);
    const size_t stop = end == std::string_view::npos ? bytes_.size() : end;
    std::string_view line = bytes_.substr(pos_, stop - pos_);
    pos_ = end == std::string_view::npos ? bytes_.size() : end + 1;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  }
  /// Offset of the first byte after the last line returned.
  size_t position() const { return pos_; }
  /// 1-based number of the last line returned.
  size_t line_number() const { return line_number_; }

 private:
  std::string_view bytes_;
  size_t pos_ = 0;
  size_t line_number_ = 0;
};

/// The words of a line, split at spaces and tabs.
inline std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

/// The whole word as a non-negative integer, or nullopt (signs, junk, overflow).
inline std::optional<uint64_t> parse_unsigned(std::string_view word) {
  uint64_t value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) return std::nullopt;
  return value;
}

/// The whole word as a signed integer, or nullopt.
inline std::optional<int64_t> parse_signed(std::string_view word) {
  int64_t value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) return std::nullopt;
  return value;
}

/// The whole word as a number ("nan" and "inf" included, a leading '+' allowed), or nullopt.
inline std::optional<double> parse_number(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (end != word.data() + word.size() || word.empty()) return std::nullopt;
  // Out of range (1e400, 1e-400): from_chars leaves the value alone; strtod gives the
  // infinity or zero such a number rounds to.
  if (error == std::errc::result_out_of_range)
    return std::strtod(std::string(word).c_str(), nullptr);
  if (error != std::errc()) return std::nullopt;
  return value;
}

/// "featsense stamp_ns N" in a header comment (the writers put it there), else nullopt.
inline std::optional<int64_t> stamp_from_comment(std::string_view comment) {
  const std::vector<std::string_view> words = split_words(comment);
  if (words.size() == 3 && words[0] == "featsense" && words[1] == "stamp_ns") {
    return parse_signed(words[2]);
  }
  return std::nullopt;
}

}  // namespace featsense::slam::cloud
