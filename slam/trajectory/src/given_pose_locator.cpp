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
    if (deskew_ && !scan.time_offset_s.empty()) {
      // Times outside the trajectory keep the scan's pose.
      placed.column_T_map_sensor = column_poses(scan, *pose, [&](double offset_s) {
        return poses_.at(scan.stamp_ns + static_cast<int64_t>(offset_s * 1e9));
      });
    }
    return placed;
  }

  std::string description() const override {
    return "given poses (" + std::to_string(poses_.trajectory().size()) + " stamped poses, " +
           (deskew_ ? "interpolated per column: deskewed" : "interpolated per scan") + ")";
  }

 private:
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
