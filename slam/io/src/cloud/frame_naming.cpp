#include "cloud/frame_naming.hpp"

#include <cctype>
#include <cstdint>

namespace featsense::slam::cloud {
namespace {

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

std::string_view trailing_digits(std::string_view text) {
  size_t start = text.size();
  while (start > 0 && is_digit(text[start - 1])) --start;
  return text.substr(start);
}

/// Digits as a number, nullopt beyond 19 digits (int64 reaches 9.2e18).
std::optional<int64_t> digits_value(std::string_view digits) {
  if (digits.empty() || digits.size() > 19) return std::nullopt;
  uint64_t value = 0;
  for (char c : digits) value = value * 10 + static_cast<uint64_t>(c - '0');
  if (value > static_cast<uint64_t>(INT64_MAX)) return std::nullopt;
  return static_cast<int64_t>(value);
}

constexpr int64_t kMinStampNs = 100'000'000'000'000'000;    // 1973
constexpr int64_t kMaxStampNs = 4'200'000'000'000'000'000;  // 2103
constexpr int64_t kMinStampS = 100'000'000;
constexpr int64_t kMaxStampS = 4'200'000'000;

}  // namespace

bool natural_less(std::string_view a, std::string_view b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      size_t i_end = i, j_end = j;
      while (i_end < a.size() && is_digit(a[i_end])) ++i_end;
      while (j_end < b.size() && is_digit(b[j_end])) ++j_end;
      // Compare as numbers: strip leading zeros, then the longer is larger.
      size_t i_lead = i, j_lead = j;
      while (i_lead + 1 < i_end && a[i_lead] == '0') ++i_lead;
      while (j_lead + 1 < j_end && b[j_lead] == '0') ++j_lead;
      const std::string_view x = a.substr(i_lead, i_end - i_lead);
      const std::string_view y = b.substr(j_lead, j_end - j_lead);
      if (x.size() != y.size()) return x.size() < y.size();
      if (x != y) return x < y;
      i = i_end;
      j = j_end;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i;
    ++j;
  }
  if (i < a.size() || j < b.size()) return j < b.size();
  return a < b;  // equal as numbers: a fixed order all the same
}

std::optional<int64_t> stamp_from_name(std::string_view stem) {
  const std::string_view last = trailing_digits(stem);
  if (last.empty()) return std::nullopt;
  const std::string_view before = stem.substr(0, stem.size() - last.size());
  if (!before.empty() && before.back() == '.') {
    const std::string_view whole = trailing_digits(before.substr(0, before.size() - 1));
    const std::optional<int64_t> seconds = digits_value(whole);
    if (seconds && *seconds >= kMinStampS && *seconds <= kMaxStampS) {
      int64_t fraction_ns = 0;
      for (size_t k = 0; k < 9; ++k) {
        fraction_ns = fraction_ns * 10 + (k < last.size() ? last[k] - '0' : 0);
      }
      return *seconds * 1'000'000'000 + fraction_ns;
    }
    return std::nullopt;
  }
  const std::optional<int64_t> ns = digits_value(last);
  if (ns && *ns >= kMinStampNs && *ns <= kMaxStampNs) return ns;
  return std::nullopt;
}

}  // namespace featsense::slam::cloud
