#pragma once
// Reads a JSON file a command wrote (a report, a benchmark's figures).

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace featsense::test {

/// The file's JSON; throws nlohmann::json::parse_error where it is missing or malformed.
inline nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace featsense::test
