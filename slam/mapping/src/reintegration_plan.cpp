#include "featsense/mapping/reintegration_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "featsense/config/sensor_model.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::mapping {
namespace {

/// Chunks lo..hi on each axis, inclusive.
struct ChunkBox {
  storage::ChunkKey lo;
  storage::ChunkKey hi;
};

/// An axis-aligned box in metres.
struct MetricBox {
  Eigen::Vector3d lo;
  Eigen::Vector3d hi;
};

template <typename Visit>
void for_each_chunk(const ChunkBox& box, const Visit& visit) {
  for (int32_t z = box.lo.z; z <= box.hi.z; ++z)
    for (int32_t y = box.lo.y; y <= box.hi.y; ++y)
      for (int32_t x = box.lo.x; x <= box.hi.x; ++x) visit(storage::ChunkKey{x, y, z});
}

/// The chunks a box in metres overlaps, a voxel more on every side (a voxel on the box's face
/// belongs to either side).
ChunkBox chunks_of(const MetricBox& box, double voxel_size_m) {
  const auto voxel = [&](double m, int64_t pad) {
    return static_cast<int64_t>(std::floor(m / voxel_size_m)) + pad;
  };
  return {
      storage::chunk_of_voxel(voxel(box.lo.x(), -1), voxel(box.lo.y(), -1), voxel(box.lo.z(), -1)),
      storage::chunk_of_voxel(voxel(box.hi.x(), 1), voxel(box.hi.y(), 1), voxel(box.hi.z(), 1))};
}

/// The chunks of a local map's voxels.
ChunkBox chunks_of(const tsdf::LocalMapGeometry& geometry) {
  const tsdf::Index3 lo = geometry.origin;
  const tsdf::Index3 hi = {lo.x + geometry.dim.x - 1, lo.y + geometry.dim.y - 1,
                           lo.z + geometry.dim.z - 1};
  return {storage::chunk_of_voxel(lo.x, lo.y, lo.z), storage::chunk_of_voxel(hi.x, hi.y, hi.z)};
}

MetricBox box_of(const tsdf::LocalMapGeometry& geometry) {
  const tsdf::Vec3 lo = geometry.min_corner();
  const tsdf::Vec3 hi = geometry.max_corner();
  return {{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}};
}

/// Where a scan at `position` may have written in the map before, wherever its local map had
/// followed the sensor to: the map's centre lies within the shift threshold of the sensor, or
/// in the sensor's brick.
MetricBox reach_around(const Eigen::Vector3d& position, const LocalMapReach& reach,
                       double voxel_size_m) {
  const double slack = reach.shift_threshold_m + tsdf::kBrickSize * voxel_size_m;
  const Eigen::Vector3d half(0.5 * reach.size_m[0] + slack, 0.5 * reach.size_m[1] + slack,
                             0.5 * reach.size_m[2] + slack);
  return {position - half, position + half};
}

MetricBox joined(const MetricBox& a, const MetricBox& b) {
  return {a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)};
}

/// How far `change` moves the farthest corner of `box` (|change * p - p| is convex in p, so a
/// corner is the farthest point of the box).
double largest_move(const Eigen::Isometry3d& change, const MetricBox& box) {
  double largest = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? box.hi.x() : box.lo.x(),
                            (corner & 2) ? box.hi.y() : box.lo.y(),
                            (corner & 4) ? box.hi.z() : box.lo.z());
    largest = std::max(largest, (change * p - p).norm());
  }
  return largest;
}

/// The same scans, by their stamps: a map's stored stamps come back within
/// storage::kStoredStampToleranceNs of the recording's.
bool same_scans(const slam::Trajectory& a, const slam::Trajectory& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k)
    if (std::abs(a.stamps_ns[k] - b.stamps_ns[k]) > storage::kStoredStampToleranceNs) return false;
  return true;
}

/// Each scan's local map as a pass that integrates them all in order places it (its size and
/// voxel as a pass converts them; the sensor does not change them).
std::vector<tsdf::LocalMapGeometry> local_maps(const slam::Trajectory& poses,
                                               const config::MapConfig& map) {
  std::vector<tsdf::LocalMapGeometry> out;
  if (poses.empty()) return out;
  tsdf::LocalMapGeometry geometry =
      tsdf::centred_geometry(tsdf::TsdfSettings::from_config(map, config::SensorModel{}),
                             local_map_anchor(poses.poses.front()));
  for (const Eigen::Isometry3d& pose : poses.poses) {
    geometry.origin =
        storage::followed_origin(geometry, local_map_anchor(pose), map.shift_threshold_m);
    out.push_back(geometry);
  }
  return out;
}

}  // namespace

std::optional<tsdf::Index3> ScanReintegration::origin_at(int64_t stamp_ns) const {
  // The planned stamps are one scan period apart: at most one lies within the tolerance.
  const auto next = origins.lower_bound(stamp_ns - storage::kStoredStampToleranceNs);
  if (next == origins.end() || next->first > stamp_ns + storage::kStoredStampToleranceNs)
    return std::nullopt;
  return next->second;
}

tsdf::Vec3 local_map_anchor(const Eigen::Isometry3d& T_map_sensor) {
  const Eigen::Vector3d t = T_map_sensor.translation();
  return {static_cast<float>(t.x()), static_cast<float>(t.y()), static_cast<float>(t.z())};
}

LocalMapReach reach_before(const config::MapConfig& after, const config::MapConfig& before) {
  LocalMapReach reach;
  for (int axis = 0; axis < 3; ++axis)
    reach.size_m[axis] = std::max(after.size_m[axis], before.size_m[axis]);
  reach.shift_threshold_m = std::max(after.shift_threshold_m, before.shift_threshold_m);
  return reach;
}

ReintegrationPlan plan_reintegration(const std::vector<SessionPoses>& sessions,
                                     const config::MapConfig& after, const LocalMapReach& before) {
  ReintegrationPlan plan;
  const auto mark_changed = [&](const storage::ChunkKey& key) { plan.changed.insert(key); };
  const double voxel = after.voxel_size_m;
  const double quarter_voxel = 0.25 * voxel;
  std::vector<std::vector<tsdf::LocalMapGeometry>> maps_after;
  for (const SessionPoses& session : sessions) {
    maps_after.push_back(local_maps(session.after, after));
    const std::vector<tsdf::LocalMapGeometry>& maps = maps_after.back();
    const slam::Trajectory& old = session.before;
    const slam::Trajectory& now = session.after;
    plan.scans += now.size();
    if (!same_scans(old, now)) {
      // Not known scan by scan: whatever it wrote before and writes now changes.
      for (const Eigen::Isometry3d& pose : old.poses)
        for_each_chunk(chunks_of(reach_around(pose.translation(), before, voxel), voxel),
                       mark_changed);
      for (const tsdf::LocalMapGeometry& map : maps) for_each_chunk(chunks_of(map), mark_changed);
      plan.scans_moved += now.size();
      continue;
    }
    for (size_t k = 0; k < now.size(); ++k) {
      const MetricBox reach_old = reach_around(old.poses[k].translation(), before, voxel);
      const MetricBox reach = joined(reach_old, box_of(maps[k]));
      bool moved = false;
      const size_t first = k == 0 ? 0 : k - 1;
      const size_t last = std::min(k + 1, now.size() - 1);
      for (size_t j = first; j <= last && !moved; ++j)
        moved = largest_move(now.poses[j] * old.poses[j].inverse(), reach) > quarter_voxel;
      if (!moved) continue;
      ++plan.scans_moved;
      for_each_chunk(chunks_of(reach_old, voxel), mark_changed);
      for_each_chunk(chunks_of(maps[k]), mark_changed);
    }
  }
  for (size_t s = 0; s < sessions.size(); ++s) {
    ScanReintegration& scans = plan.sessions.emplace_back();
    const slam::Trajectory& now = sessions[s].after;
    for (size_t k = 0; k < now.size(); ++k) {
      bool meets = false;
      for_each_chunk(chunks_of(maps_after[s][k]), [&](const storage::ChunkKey& key) {
        meets = meets || plan.changed.count(key) > 0;
      });
      if (!meets) continue;
      scans.origins.emplace(now.stamps_ns[k], maps_after[s][k].origin);
      ++plan.scans_reintegrated;
    }
  }
  return plan;
}

}  // namespace featsense::mapping
