#pragma once
// A file's whole contents as bytes, for tests that compare files or parse what was written.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace featsense::test {

/// Empty where the file cannot be read (a comparison with it then fails).
inline std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

}  // namespace featsense::test
