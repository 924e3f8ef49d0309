#include "rosbag/cloud_sensor_model.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include "rosbag/pointcloud2_convert.hpp"

namespace featsense::slam {
namespace {

constexpr std::pair<int, const char*> kPresetByBeams[] = {
    {16, "vlp16"}, {32, "hdl32"}, {64, "os1-64"}, {128, "os1-128"}};

}  // namespace

std::optional<std::string> preset_for_rings(int rings, bool round_up) {
  for (const auto& [beams, preset] : kPresetByBeams) {
    if (beams == rings || (round_up && rings > 0 && beams > rings)) return std::string(preset);
  }
  return std::nullopt;
}

std::optional<config::SensorModel> sensor_model_from_scan(const Scan& scan) {
  const std::vector<std::optional<double>> means = row_elevations(scan);
  std::vector<int> known;
  for (int row = 0; row < scan.rows; ++row) {
    if (means[static_cast<size_t>(row)]) known.push_back(row);
  }
  if (known.size() < 2) return std::nullopt;

  // Linear in the row index between the two known rows nearest to each row (outside the
  // known span: the two at that end).
  std::vector<double> elevation(static_cast<size_t>(scan.rows));
  size_t segment = 0;
  for (int row = 0; row < scan.rows; ++row) {
    while (segment + 2 < known.size() && row > known[segment + 1]) ++segment;
    const int r0 = known[segment];
    const int r1 = known[segment + 1];
    const double e0 = *means[static_cast<size_t>(r0)];
    const double e1 = *means[static_cast<size_t>(r1)];
    elevation[static_cast<size_t>(row)] =
        e0 + (e1 - e0) * static_cast<double>(row - r0) / static_cast<double>(r1 - r0);
  }
  // The model lists beams from the highest down; noise in the means must not break that.
  std::sort(elevation.begin(), elevation.end(), std::greater<double>());
  for (double& e : elevation) e = std::clamp(e, -M_PI / 2, M_PI / 2);

  config::SensorModel model;
  model.name = "estimated-" + std::to_string(scan.rows) + "x" + std::to_string(scan.cols);
  model.beams = scan.rows;
  model.columns = scan.cols;
  model.elevation_rad = std::move(elevation);
  model.azimuth_offset_rad.assign(static_cast<size_t>(scan.rows), 0.0);
  model.min_range_m = 0.0;
  model.max_range_m = 1000.0;
  return model;
}

}  // namespace featsense::slam
