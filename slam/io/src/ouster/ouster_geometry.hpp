#pragma once
// Per-pixel geometry of an Ouster sensor, computed once from its metadata so that decoding a
// frame costs one multiply-add per point instead of trigonometry.

#include <Eigen/Core>

#include <vector>

#include "featsense/slam/io/ouster_metadata.hpp"

namespace featsense::slam::detail {

/// For the pixel of beam `row` measured at measurement id `m`, the point of range r (metres,
/// as reported) is `r * direction(row, m) + offset(row, m)` in the sensor frame (metres).
/// This is PACKET_FORMAT.md's formula regrouped: the beam origin offset, the beam-to-lidar z offset
/// and the lidar-to-sensor transform do not depend on r.
class OusterPixelGeometry {
 public:
  explicit OusterPixelGeometry(const OusterMetadata& metadata);

  const Eigen::Vector3f& direction(int row, int measurement_id) const {
    return directions_[index(row, measurement_id)];
  }
  const Eigen::Vector3f& offset(int row, int measurement_id) const {
    return offsets_[index(row, measurement_id)];
  }

 private:
  size_t index(int row, int measurement_id) const {
    return static_cast<size_t>(row) * static_cast<size_t>(columns_) +
           static_cast<size_t>(measurement_id);
  }

  int columns_ = 0;
  std::vector<Eigen::Vector3f> directions_;  ///< unit vectors, sensor frame
  std::vector<Eigen::Vector3f> offsets_;     ///< metres, sensor frame
};

}  // namespace featsense::slam::detail
