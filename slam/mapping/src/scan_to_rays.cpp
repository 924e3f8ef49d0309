#include "featsense/mapping/scan_to_rays.hpp"

#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/tsdf/scan_rays.hpp"

namespace featsense::mapping {
namespace {

tsdf::Vec3 to_vec(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

std::vector<uint8_t> interpolation_flags(const slam::Scan& scan) {
  tsdf::OrganizedScanView view;
  view.rows = scan.rows;
  view.cols = scan.cols;
  view.xyz_m = scan.xyz.empty() ? nullptr : scan.xyz.front().data();
  view.valid = scan.valid.data();
  return tsdf::vertical_interpolation_flags(view);
}

}  // namespace

tsdf::RayBatch scan_to_rays(const slam::Scan& scan, const slam::ScanPlacement& placement) {
  const bool deskewed = placement.deskewed();
  if (deskewed && placement.column_T_map_sensor.size() != static_cast<size_t>(scan.cols)) {
    throw std::invalid_argument("scan " + std::to_string(scan.sequence) + " has " +
                                std::to_string(scan.cols) + " columns but its placement " +
                                std::to_string(placement.column_T_map_sensor.size()) +
                                " column poses");
  }
  tsdf::RayBatch rays;
  rays.up = to_vec(placement.T_map_sensor.linear().col(2));
  if (!deskewed) rays.origins_m.push_back(to_vec(placement.T_map_sensor.translation()));
  rays.endpoints_m.reserve(scan.valid_count());
  if (deskewed) rays.origins_m.reserve(scan.valid_count());
  rays.interpolate.reserve(scan.valid_count());
  rays.carving_level.reserve(scan.valid_count());
  const std::vector<uint8_t> flags = interpolation_flags(scan);
  // Row by row: neighbouring rays are the same beam in neighbouring columns, of about the
  // same length and through the same bricks, so the rays a GPU warp walks together take about
  // as long (column by column, a warp held 32 beams from the sky to the ground, and the GPU
  // took 15 % longer outdoors, 25 % indoors).
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      const Eigen::Isometry3d& pose = deskewed
                                          ? placement.column_T_map_sensor[static_cast<size_t>(col)]
                                          : placement.T_map_sensor;
      rays.endpoints_m.push_back(to_vec(pose * scan.xyz[i].cast<double>()));
      if (deskewed) rays.origins_m.push_back(to_vec(pose.translation()));
      rays.interpolate.push_back(flags[i]);
      rays.carving_level.push_back(tsdf::carving_level(row, col));
    }
  }
  return rays;
}

}  // namespace featsense::mapping
