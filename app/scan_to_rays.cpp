#include "scan_to_rays.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace featsense::app {
namespace {

tsdf::Vec3 to_vec(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

/// Whether the beam above or below disagrees in range by more than a surface facing the
/// sensor at >= ~27 deg can explain (2 x range x the angle between the two beams).
bool grazing_or_edge(const slam::Scan& scan, size_t i, size_t j) {
  if (!scan.valid[j]) return false;
  const float r = scan.xyz[i].norm();
  const float rn = scan.xyz[j].norm();
  if (!(r > 0.0f) || !(rn > 0.0f)) return false;
  const float cos_angle = std::clamp(scan.xyz[i].dot(scan.xyz[j]) / (r * rn), -1.0f, 1.0f);
  const float angle = std::acos(cos_angle);
  constexpr float kMaxRangeStep = 2.0f;  // in units of range x angle: tan(27 deg) = 1 / 2
  return std::abs(r - rn) > kMaxRangeStep * std::min(r, rn) * angle;
}

/// Per cell (row-major), 1 where the ray may interpolate vertically: the paper's band runs
/// perpendicular to the ray towards the neighbouring beams, which fills the gap between scan
/// lines on a surface facing the sensor but crosses a surface seen at a grazing angle (the
/// ground far away) and a depth edge, giving cells on the far side of it the wrong sign.
std::vector<uint8_t> interpolation_flags(const slam::Scan& scan) {
  std::vector<uint8_t> flags(scan.size(), 1);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      const bool above = row > 0 && grazing_or_edge(scan, i, scan.index(row - 1, col));
      const bool below = row + 1 < scan.rows && grazing_or_edge(scan, i, scan.index(row + 1, col));
      if (above || below) flags[i] = 0;
    }
  }
  return flags;
}

/// The ray's place in the lattice of sparse carving (tsdf::TsdfSettings::dense_range_m): the
/// largest L with both its beam and its column multiples of 2^L.
uint8_t carving_level(int row, int col) {
  const auto level = [](int index) {
    return index == 0 ? int{tsdf::kFullCarvingLevel} : __builtin_ctz(static_cast<unsigned>(index));
  };
  return static_cast<uint8_t>(std::min({level(row), level(col), int{tsdf::kFullCarvingLevel}}));
}

}  // namespace

tsdf::RayBatch scan_to_rays(const slam::Scan& scan, const Eigen::Isometry3d& T_map_sensor) {
  tsdf::RayBatch rays;
  rays.origins_m.push_back(to_vec(T_map_sensor.translation()));
  rays.up = to_vec(T_map_sensor.linear().col(2));
  rays.endpoints_m.reserve(scan.valid_count());
  rays.interpolate.reserve(scan.valid_count());
  rays.carving_level.reserve(scan.valid_count());
  const std::vector<uint8_t> flags = interpolation_flags(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      rays.endpoints_m.push_back(to_vec(T_map_sensor * scan.xyz[i].cast<double>()));
      rays.interpolate.push_back(flags[i]);
      rays.carving_level.push_back(carving_level(row, col));
    }
  }
  return rays;
}

tsdf::RayBatch deskewed_scan_to_rays(const slam::Scan& scan, const PoseAt& pose_at) {
  tsdf::RayBatch rays;
  rays.up = to_vec(pose_at(0.0).linear().col(2));
  rays.endpoints_m.reserve(scan.valid_count());
  rays.origins_m.reserve(scan.valid_count());
  rays.interpolate.reserve(scan.valid_count());
  rays.carving_level.reserve(scan.valid_count());
  const std::vector<uint8_t> flags = interpolation_flags(scan);
  // All rows of a column share the column's time in the layout of scan.hpp; take the time
  // of the first valid point so sources with per-point times are honoured per column.
  std::vector<std::optional<Eigen::Isometry3d>> column_pose(static_cast<size_t>(scan.cols));
  for (int col = 0; col < scan.cols; ++col) {
    for (int row = 0; row < scan.rows; ++row) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      column_pose[static_cast<size_t>(col)] = pose_at(static_cast<double>(scan.time_offset_s[i]));
      break;
    }
  }
  const auto add = [&](int row, int col) {
    const size_t i = scan.index(row, col);
    if (!scan.valid[i]) return;
    const Eigen::Isometry3d& pose = *column_pose[static_cast<size_t>(col)];
    rays.endpoints_m.push_back(to_vec(pose * scan.xyz[i].cast<double>()));
    rays.origins_m.push_back(to_vec(pose.translation()));
    rays.interpolate.push_back(flags[i]);
    rays.carving_level.push_back(carving_level(row, col));
  };
  // Row by row, as scan_to_rays: neighbouring rays are the same beam in neighbouring columns,
  // of about the same length and through the same bricks, so the rays a GPU warp walks
  // together take about as long (column by column, a warp held 32 beams from the sky to the
  // ground, and the GPU took 15 % longer outdoors, 25 % indoors).
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) add(row, col);
  }
  return rays;
}

}  // namespace featsense::app
