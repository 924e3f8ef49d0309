#pragma once
/// A timed sequence of poses (map <- sensor), as estimated by odometry or surveyed as ground
/// truth, and the error raised when a trajectory file or pair cannot be evaluated.

#include <Eigen/Geometry>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace featsense::slam {

/// A trajectory file that cannot be read, or two trajectories that cannot be compared.
class TrajectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Trajectory {
  std::vector<int64_t> stamps_ns;        ///< one per pose, nanoseconds, increasing
  std::vector<Eigen::Isometry3d> poses;  ///< T_map_sensor, metres
  /// False for formats without time (KITTI poses without a times file): such trajectories are
  /// associated by index, and stamps_ns holds the index.
  bool has_stamps = true;

  size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  /// Appends a pose; stamps must increase (checked by the readers, not here).
  void push_back(int64_t stamp_ns, const Eigen::Isometry3d& T_map_sensor) {
    stamps_ns.push_back(stamp_ns);
    poses.push_back(T_map_sensor);
  }
};

/// Length of the path through the positions, metres.
double path_length_m(const Trajectory& trajectory);

}  // namespace featsense::slam
