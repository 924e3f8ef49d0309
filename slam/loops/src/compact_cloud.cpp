#include "featsense/slam/loops/compact_cloud.hpp"

#include <cmath>
#include <limits>
#include <utility>

namespace featsense::slam::loops {

CompactCloud::CompactCloud(const std::vector<Eigen::Vector3f>& points) {
  constexpr double kLimit = std::numeric_limits<int16_t>::max();
  coordinates_.reserve(points.size() * 3);
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d q = (p.cast<double>() / kResolutionM).array().round();
    if (!q.allFinite() || q.cwiseAbs().maxCoeff() > kLimit) continue;
    for (int axis = 0; axis < 3; ++axis) coordinates_.push_back(static_cast<int16_t>(q[axis]));
  }
  coordinates_.shrink_to_fit();
}

CompactCloud CompactCloud::from_coordinates(std::vector<int16_t> coordinates) {
  coordinates.resize(coordinates.size() / 3 * 3);
  CompactCloud cloud;
  cloud.coordinates_ = std::move(coordinates);
  return cloud;
}

std::vector<Eigen::Vector3f> CompactCloud::points() const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(size());
  for (size_t i = 0; i + 2 < coordinates_.size(); i += 3) {
    out.emplace_back(static_cast<float>(coordinates_[i] * kResolutionM),
                     static_cast<float>(coordinates_[i + 1] * kResolutionM),
                     static_cast<float>(coordinates_[i + 2] * kResolutionM));
  }
  return out;
}

}  // namespace featsense::slam::loops
