#include "featsense/slam/loops/map_keyframe.hpp"

#include <algorithm>

namespace featsense::slam::loops {

void travelled_from_positions(std::vector<MapKeyframe>& keyframes) {
  for (size_t i = 0; i < keyframes.size(); ++i) {
    if (i == 0 || keyframes[i].session != keyframes[i - 1].session) {
      keyframes[i].travelled_m = 0.0;
      continue;
    }
    keyframes[i].travelled_m =
        keyframes[i - 1].travelled_m +
        (keyframes[i].T_map_sensor.translation() - keyframes[i - 1].T_map_sensor.translation())
            .norm();
  }
}

refine::GaussianCloud keyframe_target(const std::vector<MapKeyframe>& keyframes,
                                      const std::vector<Eigen::Isometry3d>& poses, size_t centre,
                                      size_t each_side, int neighbours) {
  const uint32_t session = keyframes[centre].session;
  size_t first = centre;
  while (first > 0 && centre - first < each_side && keyframes[first - 1].session == session)
    --first;
  size_t last = centre;
  while (last + 1 < keyframes.size() && last - centre < each_side &&
         keyframes[last + 1].session == session)
    ++last;
  const Eigen::Isometry3d T_centre_map = poses[centre].inverse();
  std::vector<Eigen::Vector3f> points;
  for (size_t j = first; j <= last; ++j) {
    const Eigen::Isometry3f T = (T_centre_map * poses[j]).cast<float>();
    for (const Eigen::Vector3f& p : keyframes[j].cloud.points()) points.push_back(T * p);
  }
  return refine::with_covariances(points, neighbours);
}

}  // namespace featsense::slam::loops
