#pragma once
/// TUM and KITTI trajectory files.
///
/// TUM: one pose per line, `stamp_s tx ty tz qx qy qz qw` (seconds, metres, unit quaternion,
/// T_map_sensor); lines starting with '#' and blank lines are skipped.
/// KITTI: one pose per line, the first three rows of the 4x4 T_map_sensor, row-major (12
/// numbers), no time. With a times file (KITTI odometry's `times.txt`: one time in seconds
/// per line, as many lines as poses) the poses get those stamps; without one the trajectory
/// has no stamps (has_stamps = false) and is associated with another by index.

#include <optional>
#include <string>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

/// Reads a TUM file. Throws TrajectoryError naming the file and line on malformed input,
/// non-unit quaternions (|q| off by more than 1e-3), or stamps that do not increase.
Trajectory read_tum(const std::string& path);
/// Reads a KITTI poses file, with stamps from `times_path` when given. Throws TrajectoryError
/// naming the file and line on malformed input.
Trajectory read_kitti(const std::string& path, const std::optional<std::string>& times_path = {});
/// The format of a trajectory file from its content: "tum" when the first data line has 8
/// numbers, "kitti" for 12. Throws TrajectoryError naming the file otherwise.
std::string detect_trajectory_format(const std::string& path);
/// Reads a trajectory file in `format`: "tum", "kitti", or "auto" (detect_trajectory_format).
/// A times file (`times_path`) goes with KITTI poses only. Throws TrajectoryError.
Trajectory read_trajectory(const std::string& path, const std::string& format = "auto",
                           const std::optional<std::string>& times_path = {});

/// Writes TUM (stamps in seconds with nanosecond digits). Throws TrajectoryError on failure.
void write_tum(const Trajectory& trajectory, const std::string& path);

/// The header line write_tum starts with, and one pose's line as it writes it (both ending
/// in a newline): for files written a pose at a time.
extern const char* const kTumHeader;
std::string tum_line(int64_t stamp_ns, const Eigen::Isometry3d& T);
/// Writes KITTI (12 numbers a line). Throws TrajectoryError on failure.
void write_kitti(const Trajectory& trajectory, const std::string& path);

}  // namespace featsense::slam
