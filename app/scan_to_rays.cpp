#include "scan_to_rays.hpp"

#include <optional>

namespace featsense::app {
namespace {

tsdf::Vec3 to_vec(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

}  // namespace

tsdf::RayBatch scan_to_rays(const slam::Scan& scan, const Eigen::Isometry3d& T_map_sensor) {
  tsdf::RayBatch rays;
  rays.origins_m.push_back(to_vec(T_map_sensor.translation()));
  rays.up = to_vec(T_map_sensor.linear().col(2));
  rays.endpoints_m.reserve(scan.valid_count());
  for (size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i])
      rays.endpoints_m.push_back(to_vec(T_map_sensor * scan.xyz[i].cast<double>()));
  }
  return rays;
}

tsdf::RayBatch deskewed_scan_to_rays(const slam::Scan& scan, const PoseAt& pose_at) {
  tsdf::RayBatch rays;
  rays.up = to_vec(pose_at(0.0).linear().col(2));
  rays.endpoints_m.reserve(scan.valid_count());
  rays.origins_m.reserve(scan.valid_count());
  for (int col = 0; col < scan.cols; ++col) {
    // All rows of a column share the column's time in the layout of scan.hpp; take the time
    // of the first valid point so sources with per-point times are honoured per column.
    std::optional<Eigen::Isometry3d> pose;
    for (int row = 0; row < scan.rows; ++row) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      if (!pose) pose = pose_at(static_cast<double>(scan.time_offset_s[i]));
      rays.endpoints_m.push_back(to_vec(*pose * scan.xyz[i].cast<double>()));
      rays.origins_m.push_back(to_vec(pose->translation()));
    }
  }
  return rays;
}

}  // namespace featsense::app
