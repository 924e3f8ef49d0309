#include "featsense/slam/trajectory/scan_motions.hpp"

#include <algorithm>
#include <iterator>
#include <map>
#include <string>
#include <utility>

#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam {

namespace {

/// Knots over the sweep besides the stamp.
constexpr int kKnots = 8;

Eigen::Isometry3d pose_of(const Eigen::Quaternionf& rotation, const Eigen::Vector3f& translation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation.cast<double>().normalized().toRotationMatrix();
  pose.translation() = translation.cast<double>();
  return pose;
}

}  // namespace

ScanMotion ScanMotion::of(const Scan& scan, const ScanPlacement& placement) {
  ScanMotion kept;
  if (!placement.deskewed()) return kept;
  const std::vector<std::optional<float>> times = scan.column_time_offsets_s();
  std::map<float, size_t> columns;  // by time: the knots come out in time order
  float first = 0.f, last = 0.f;
  for (size_t col = 0; col < times.size() && col < placement.column_T_map_sensor.size(); ++col) {
    if (!times[col]) continue;
    columns.emplace(*times[col], col);
    first = std::min(first, *times[col]);
    last = std::max(last, *times[col]);
  }
  if (!(last > first)) return kept;
  // The stamp (identity) and the columns nearest to kKnots instants spread over the sweep.
  std::map<float, Eigen::Isometry3d> knots{{0.f, Eigen::Isometry3d::Identity()}};
  const Eigen::Isometry3d from_map = placement.T_map_sensor.inverse();
  for (int k = 0; k < kKnots; ++k) {
    const float want = first + (last - first) * static_cast<float>(k) / (kKnots - 1);
    auto near = columns.lower_bound(want);
    if (near == columns.end() ||
        (near != columns.begin() && want - std::prev(near)->first < near->first - want)) {
      near = std::prev(near);
    }
    knots.emplace(near->first, from_map * placement.column_T_map_sensor[near->second]);
  }
  for (const auto& [time_s, pose] : knots) {
    kept.times_s_.push_back(time_s);
    kept.rotations_.push_back(Eigen::Quaterniond(pose.linear()).normalized().cast<float>());
    kept.translations_.push_back(pose.translation().cast<float>());
  }
  return kept;
}

Eigen::Isometry3d ScanMotion::at(double t_s) const {
  if (times_s_.size() < 2) return Eigen::Isometry3d::Identity();
  size_t k = 1;
  while (k + 1 < times_s_.size() && times_s_[k] < t_s) ++k;
  const double t0 = times_s_[k - 1], t1 = times_s_[k];
  return interpolate_pose(pose_of(rotations_[k - 1], translations_[k - 1]),
                          pose_of(rotations_[k], translations_[k]), (t_s - t0) / (t1 - t0));
}

void ScanMotions::add(const Scan& scan, const ScanPlacement& placement) {
  ScanMotion kept = ScanMotion::of(scan, placement);
  if (!kept.empty()) motions_[placement.stamp_ns] = std::move(kept);
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
      return std::optional<Eigen::Isometry3d>(at_stamp * kept->at(t));
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
