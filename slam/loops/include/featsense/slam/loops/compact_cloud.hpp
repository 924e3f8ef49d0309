#pragma once
/// A keyframe's points kept small for a long run: one point per voxel, each stored as three
/// 16-bit integers in centimetres in the keyframe's sensor frame (6 bytes a point, +/- 327 m),
/// about 25 kB for an outdoor OS1-128 scan at 0.4 m voxels. Covariances are made again when the
/// keyframe is registered.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace featsense::slam::loops {

class CompactCloud {
 public:
  static constexpr double kResolutionM = 0.01;

  CompactCloud() = default;
  /// Points beyond the 16-bit range, or not finite, are dropped.
  explicit CompactCloud(const std::vector<Eigen::Vector3f>& points);
  /// The cloud a map file kept (coordinates()); a count that is not a multiple of 3 drops the
  /// incomplete last point.
  static CompactCloud from_coordinates(std::vector<int16_t> coordinates);

  std::vector<Eigen::Vector3f> points() const;
  size_t size() const { return coordinates_.size() / 3; }
  size_t bytes() const { return coordinates_.size() * sizeof(int16_t); }
  /// x y z of each point in units of kResolutionM, as a map file keeps them.
  const std::vector<int16_t>& coordinates() const { return coordinates_; }

 private:
  std::vector<int16_t> coordinates_;  ///< x y z of each point
};

}  // namespace featsense::slam::loops
