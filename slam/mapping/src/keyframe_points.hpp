#pragma once
// The points the saved map's keyframes saw, in the map's frame, for where its surface has
// nothing: the surface (the TSDF) holds what lay within the local map around the path (20 m
// either side by default), while a keyframe keeps its sweep's points out to the sensor's
// range. A sensor on a street the mapping run only looked down from a crossing sees walls the
// surface never held but the keyframes did. Thinned to one point per voxel across keyframes,
// sorted into square tiles so that a target takes those around its centre only.

#include <Eigen/Core>

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "featsense/slam/loops/map_keyframe.hpp"

namespace featsense::mapping {

class KeyframePoints {
 public:
  /// From `keyframes` at their poses, one point kept per `voxel_m` voxel, in tiles of `tile_m`.
  KeyframePoints(const std::vector<slam::loops::MapKeyframe>& keyframes, double voxel_m,
                 double tile_m = 20.0);

  /// The points within `radius_m` of `centre`, horizontally.
  std::vector<Eigen::Vector3f> near(const Eigen::Vector3d& centre, double radius_m) const;

  size_t size() const { return size_; }
  size_t bytes() const;

 private:
  double tile_m_;
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3f>> tiles_;
  size_t size_ = 0;
};

}  // namespace featsense::mapping
