#pragma once
// A test-side PCD writer, independent of the production one: fields of any type and count,
// ascii / binary / binary_compressed (LZF literal runs, which any LZF decoder must accept,
// or a real compressor passed in). Assumes a little-endian host, as the tests do.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace featsense::test {

struct TestField {
  std::string name;
  char type;  // F U I
  int size;   // bytes
  int count = 1;
};

enum class Mode { kAscii, kBinary, kCompressed, kCompressedLzf };

inline void put_value(std::string& out, const TestField& f, double v) {
  uint8_t bytes[8];
  if (f.type == 'F' && f.size == 4) {
    const float x = static_cast<float>(v);
    std::memcpy(bytes, &x, 4);
  } else if (f.type == 'F') {
    std::memcpy(bytes, &v, 8);
  } else if (f.type == 'U') {
    const uint64_t x = static_cast<uint64_t>(v);
    std::memcpy(bytes, &x, 8);  // little-endian host: the low bytes first
  } else {
    const int64_t x = static_cast<int64_t>(v);
    std::memcpy(bytes, &x, 8);
  }
  out.append(reinterpret_cast<const char*>(bytes), static_cast<size_t>(f.size));
}

inline std::string lzf_literal_runs(const std::string& plain) {
  std::string out;
  for (size_t i = 0; i < plain.size(); i += 32) {
    const size_t n = std::min<size_t>(32, plain.size() - i);
    out += static_cast<char>(n - 1);
    out += plain.substr(i, n);
  }
  return out;
}

/// A compressor for kCompressedLzf (liblzf's, in the tests that link it).
using Compressor = std::function<std::string(const std::string&)>;

/// values[i] holds point i's values, field after field, `count` values each.
inline std::string pcd_bytes(const std::vector<TestField>& fields,
                             const std::vector<std::vector<double>>& values, Mode mode,
                             int width = -1, int height = 1, const Compressor& lzf = nullptr) {
  std::ostringstream h;
  h << "# .PCD v0.7 - test\nVERSION 0.7\nFIELDS";
  for (const auto& f : fields) h << " " << f.name;
  h << "\nSIZE";
  for (const auto& f : fields) h << " " << f.size;
  h << "\nTYPE";
  for (const auto& f : fields) h << " " << f.type;
  h << "\nCOUNT";
  for (const auto& f : fields) h << " " << f.count;
  if (width < 0) width = static_cast<int>(values.size());
  h << "\nWIDTH " << width << "\nHEIGHT " << height << "\nVIEWPOINT 0 0 0 1 0 0 0\n"
    << "POINTS " << values.size() << "\nDATA "
    << (mode == Mode::kAscii    ? "ascii"
        : mode == Mode::kBinary ? "binary"
                                : "binary_compressed")
    << "\n";
  std::string out = h.str();
  if (mode == Mode::kAscii) {
    std::ostringstream data;
    data.precision(17);
    for (const auto& point : values) {
      for (size_t k = 0; k < point.size(); ++k) data << (k ? " " : "") << point[k];
      data << "\n";
    }
    return out + data.str();
  }
  if (mode == Mode::kBinary) {
    for (const auto& point : values) {
      size_t k = 0;
      for (const auto& f : fields) {
        for (int c = 0; c < f.count; ++c) put_value(out, f, point[k++]);
      }
    }
    return out;
  }
  std::string plain;
  size_t first = 0;
  for (const auto& f : fields) {
    for (const auto& point : values) {
      for (int c = 0; c < f.count; ++c) put_value(plain, f, point[first + static_cast<size_t>(c)]);
    }
    first += static_cast<size_t>(f.count);
  }
  const std::string packed =
      mode == Mode::kCompressed || !lzf ? lzf_literal_runs(plain) : lzf(plain);
  const uint32_t sizes[2] = {static_cast<uint32_t>(packed.size()),
                             static_cast<uint32_t>(plain.size())};
  out.append(reinterpret_cast<const char*>(sizes), 8);
  return out + packed;
}

}  // namespace featsense::test
