#include "json_output.hpp"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <stdexcept>

namespace featsense::app {

void write_json(const nlohmann::json& document, const std::string& path) {
  const std::string text = document.dump(2) + "\n";
  if (path == "-") {
    std::cout << text << std::flush;
    return;
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw std::runtime_error(path + ": cannot write the JSON output");
  file << text;
  file.close();
  if (!file) throw std::runtime_error(path + ": writing the JSON output failed (disk full?)");
}

void print_bench_result(const nlohmann::json& result, const std::optional<std::string>& json_path) {
  if (json_path && *json_path != "-") write_json(result, *json_path);
  std::cout << result.dump(2) << "\n";
}

}  // namespace featsense::app
