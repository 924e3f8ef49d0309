#pragma once
// Scans of the built-in box room as TSDF rays, for the tests that compare integrators.

#include <vector>

#include "analytic_rays.hpp"
#include "featsense/slam/io/box_room_source.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::tsdf::test {

/// The carving level of the ray of (row, col), counted here by hand: the largest L with both
/// multiples of 2^L.
inline uint8_t lattice_level(int row, int col) {
  int level = 0;
  while (level < kFullCarvingLevel && row % (2 << level) == 0 && col % (2 << level) == 0) ++level;
  return static_cast<uint8_t>(level);
}

/// `frames` scans of an OS1-128 moving through the box room (per-point origins from the true
/// motion, so the rays of one scan start at many points); `outdoor` is its 120 x 80 m yard
/// open to the sky, where rays leave the map. With `carving_levels`, each ray carries its
/// place in the lattice of sparse carving.
inline std::vector<RayBatch> box_room_rays(int frames, bool outdoor, bool carving_levels = false) {
  slam::BoxRoomSettings settings = slam::default_box_room();
  settings.frames = frames;
  settings.velocity_mps = Eigen::Vector3d(1.5, 0.5, 0.1);
  if (outdoor) {
    settings.room_min_m = Eigen::Vector3d(-60, -40, 0);
    settings.room_max_m = Eigen::Vector3d(60, 40, 1e4);
    settings.velocity_mps = Eigen::Vector3d(5, 0.3, 0);
  }
  auto source = slam::make_box_room_source(settings);
  std::vector<RayBatch> batches;
  int frame = 0;
  while (auto scan = source->next()) {
    RayBatch rays;
    for (size_t i = 0; i < scan->size(); ++i) {
      if (!scan->valid[i]) continue;
      const double t = frame / settings.sensor.rate_hz + scan->time_offset_s[i];
      const Eigen::Isometry3d pose = slam::box_room_pose(settings, t);
      const Eigen::Vector3d p = pose * scan->xyz[i].cast<double>();
      rays.endpoints_m.push_back(make_vec(p.x(), p.y(), p.z()));
      const Eigen::Vector3d o = pose.translation();
      rays.origins_m.push_back(make_vec(o.x(), o.y(), o.z()));
      const int row = static_cast<int>(i) / scan->cols;
      if (carving_levels)
        rays.carving_level.push_back(lattice_level(row, static_cast<int>(i) % scan->cols));
    }
    batches.push_back(std::move(rays));
    ++frame;
  }
  return batches;
}

/// The `frames` scans of box_room_rays, `passes` times over: a sensor that keeps seeing the
/// same free space (with a weight cap of 2, free space seen twice is settled).
inline std::vector<RayBatch> box_room_passes(int frames, int passes) {
  const std::vector<RayBatch> room = box_room_rays(frames, false);
  std::vector<RayBatch> scans;
  for (int pass = 0; pass < passes; ++pass) scans.insert(scans.end(), room.begin(), room.end());
  return scans;
}

}  // namespace featsense::tsdf::test
