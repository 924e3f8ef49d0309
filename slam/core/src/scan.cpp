#include "featsense/slam/scan.hpp"

#include <algorithm>

namespace featsense::slam {

Scan Scan::allocate(int rows, int cols) {
  Scan scan;
  scan.rows = rows;
  scan.cols = cols;
  const size_t n = scan.size();
  scan.xyz.assign(n, Eigen::Vector3f::Zero());
  scan.range_m.assign(n, 0.0f);
  scan.time_offset_s.assign(n, 0.0f);
  scan.valid.assign(n, 0);
  return scan;
}

size_t Scan::valid_count() const {
  return static_cast<size_t>(std::count(valid.begin(), valid.end(), uint8_t{1}));
}

std::vector<std::optional<float>> Scan::column_time_offsets_s() const {
  std::vector<std::optional<float>> times(static_cast<size_t>(cols));
  if (time_offset_s.size() != size()) return times;
  for (int col = 0; col < cols; ++col) {
    for (int row = 0; row < rows; ++row) {
      const size_t i = index(row, col);
      if (!valid[i]) continue;
      times[static_cast<size_t>(col)] = time_offset_s[i];
      break;
    }
  }
  return times;
}

const ScanChannel* Scan::channel(std::string_view name) const {
  for (const auto& c : channels) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

ScanChannel* Scan::channel(std::string_view name) {
  for (auto& c : channels) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

ScanChannel& Scan::add_channel(std::string_view name) {
  if (ScanChannel* existing = channel(name)) return *existing;
  channels.push_back({std::string(name), std::vector<float>(size(), 0.0f)});
  return channels.back();
}

const ScanChannel* Scan::intensity() const {
  for (const char* name : {"reflectivity", "intensity", "signal"}) {
    if (const ScanChannel* c = channel(name)) return c;
  }
  return nullptr;
}

void Scan::invalidate(size_t i) {
  valid[i] = 0;
  xyz[i].setZero();
  range_m[i] = 0.0f;
}

}  // namespace featsense::slam
