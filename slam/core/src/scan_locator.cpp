#include "featsense/slam/scan_locator.hpp"

namespace featsense::slam {

std::vector<Eigen::Isometry3d> column_poses(
    const Scan& scan, const Eigen::Isometry3d& at_stamp,
    const std::function<std::optional<Eigen::Isometry3d>(double seconds_after_stamp)>& pose_at) {
  std::vector<Eigen::Isometry3d> poses(static_cast<size_t>(scan.cols), at_stamp);
  const std::vector<std::optional<float>> times = scan.column_time_offsets_s();
  for (size_t col = 0; col < times.size(); ++col) {
    if (!times[col]) continue;
    if (const std::optional<Eigen::Isometry3d> pose = pose_at(static_cast<double>(*times[col]))) {
      poses[col] = *pose;
    }
  }
  return poses;
}

}  // namespace featsense::slam
