#include "featsense/slam/trajectory/given_pose_locator.hpp"

#include <cstdio>
#include <string>

#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam {
namespace {

std::string seconds(int64_t ns) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", static_cast<double>(ns) * 1e-9);
  return text;
}

class StampedPoses final : public ScanLocator {
 public:
  StampedPoses(Trajectory trajectory, bool deskew)
      : poses_(std::move(trajectory)), deskew_(deskew) {}

  std::optional<ScanPlacement> locate(const Scan& scan, std::string& why) override {
    const std::optional<Eigen::Isometry3d> pose = poses_.at(scan.stamp_ns);
    if (!pose) {
      why = "no pose for scan " + std::to_string(scan.sequence) +
            " at t = " + seconds(scan.stamp_ns) + " s: the trajectory covers " +
            seconds(poses_.trajectory().stamps_ns.front()) + " .. " +
            seconds(poses_.trajectory().stamps_ns.back()) + " s";
      return std::nullopt;
    }
    ScanPlacement placed;
    placed.sequence = scan.sequence;
    placed.stamp_ns = scan.stamp_ns;
    placed.T_map_sensor = *pose;
    if (deskew_ && !scan.time_offset_s.empty())
      placed.column_T_map_sensor = column_poses(scan, *pose);
    return placed;
  }

  std::string description() const override {
    return "given poses (" + std::to_string(poses_.trajectory().size()) + " stamped poses, " +
           (deskew_ ? "interpolated per column: deskewed" : "interpolated per scan") + ")";
  }

 private:
  /// The pose at each column's time (Scan::column_time_offsets_s); columns without a valid
  /// point, and times outside the trajectory, keep the scan's pose.
  std::vector<Eigen::Isometry3d> column_poses(const Scan& scan, const Eigen::Isometry3d& at_stamp) {
    std::vector<Eigen::Isometry3d> poses(static_cast<size_t>(scan.cols), at_stamp);
    const std::vector<std::optional<float>> times = scan.column_time_offsets_s();
    for (size_t col = 0; col < times.size(); ++col) {
      if (!times[col]) continue;
      const double offset_s = static_cast<double>(*times[col]);
      const auto at = poses_.at(scan.stamp_ns + static_cast<int64_t>(offset_s * 1e9));
      if (at) poses[col] = *at;
    }
    return poses;
  }

  PoseInterpolator poses_;
  bool deskew_;
};

/// KITTI poses without times: pose i is scan i's.
class IndexedPoses final : public ScanLocator {
 public:
  explicit IndexedPoses(Trajectory trajectory) : trajectory_(std::move(trajectory)) {}

  std::optional<ScanPlacement> locate(const Scan& scan, std::string& why) override {
    if (scan.sequence >= trajectory_.size()) {
      why = "no pose for scan " + std::to_string(scan.sequence) + ": the trajectory has " +
            std::to_string(trajectory_.size()) + " poses (one per scan, by index)";
      return std::nullopt;
    }
    ScanPlacement placed;
    placed.sequence = scan.sequence;
    placed.stamp_ns = scan.stamp_ns;
    placed.T_map_sensor = trajectory_.poses[scan.sequence];
    return placed;
  }

  std::string description() const override {
    return "given poses (" + std::to_string(trajectory_.size()) +
           " poses without times, one per scan; not deskewed)";
  }

 private:
  Trajectory trajectory_;
};

}  // namespace

std::unique_ptr<ScanLocator> make_given_pose_locator(Trajectory trajectory, bool deskew) {
  if (trajectory.has_stamps) return std::make_unique<StampedPoses>(std::move(trajectory), deskew);
  return std::make_unique<IndexedPoses>(std::move(trajectory));
}

}  // namespace featsense::slam
