#include "featsense/slam/trajectory/scan_motions.hpp"

#include <string>
#include <utility>

#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam {

void ScanMotions::add(const Scan& scan, const ScanPlacement& placement) {
  if (!placement.deskewed()) return;
  const std::vector<std::optional<float>> times = scan.column_time_offsets_s();
  size_t last = times.size();
  for (size_t col = 0; col < times.size(); ++col) {
    if (times[col] && (last == times.size() || *times[col] > *times[last])) last = col;
  }
  if (last == times.size() || !(*times[last] > 0.f)) return;
  ScanMotion kept;
  kept.motion = placement.T_map_sensor.inverse() * placement.column_T_map_sensor[last];
  kept.span_s = static_cast<double>(*times[last]);
  motions_[placement.stamp_ns] = kept;
}

std::optional<ScanMotion> ScanMotions::at(int64_t stamp_ns) const {
  const auto found = motions_.find(stamp_ns);
  if (found == motions_.end()) return std::nullopt;
  return found->second;
}

namespace {

class ReplayLocator final : public ScanLocator {
 public:
  ReplayLocator(Trajectory trajectory, ScanMotions motions)
      : at_stamps_(make_given_pose_locator(trajectory, false)),
        interpolated_(make_given_pose_locator(std::move(trajectory), true)),
        motions_(std::move(motions)) {}

  std::optional<ScanPlacement> locate(const Scan& scan, std::string& why) override {
    const std::optional<ScanMotion> kept = motions_.at(scan.stamp_ns);
    if (!kept) return interpolated_->locate(scan, why);
    // Only the pose at the stamp from the trajectory: the columns follow the kept motion.
    std::optional<ScanPlacement> placed = at_stamps_->locate(scan, why);
    if (!placed) return placed;
    const Eigen::Isometry3d at_stamp = placed->T_map_sensor;
    placed->column_T_map_sensor = column_poses(scan, at_stamp, [&](double t) {
      return std::optional<Eigen::Isometry3d>(at_stamp *
                                              motion_fraction(kept->motion, t / kept->span_s));
    });
    return placed;
  }

  std::string description() const override {
    return "corrected poses, each scan deskewed with its first placement's motion";
  }

 private:
  std::unique_ptr<ScanLocator> at_stamps_;     ///< the poses at the stamps, scans rigid
  std::unique_ptr<ScanLocator> interpolated_;  ///< for a scan without a kept motion
  ScanMotions motions_;
};

}  // namespace

std::unique_ptr<ScanLocator> make_replay_locator(Trajectory trajectory, ScanMotions motions) {
  return std::make_unique<ReplayLocator>(std::move(trajectory), std::move(motions));
}

}  // namespace featsense::slam
