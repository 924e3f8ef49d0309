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

nlohmann::json min_median_max(std::vector<double> values) {
  if (values.empty()) return {{"min", 0}, {"median", 0}, {"max", 0}};
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  const double median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {{"min", values.front()}, {"median", median}, {"max", values.back()}};
}

}  // namespace featsense::app
