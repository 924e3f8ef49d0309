#include "featsense/slam/odometry/odometry_locator.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/odometry/feature_odometry.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::slam::odometry {
namespace {

double milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

/// The mean of `times` (seconds after the stamp), 0 when empty.
double mean_time(const std::vector<float>& edges, const std::vector<float>& surfaces) {
  double sum = 0.0;
  for (const float t : edges) sum += static_cast<double>(t);
  for (const float t : surfaces) sum += static_cast<double>(t);
  const size_t n = edges.size() + surfaces.size();
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

class FeatureOdometryLocator final : public OdometryLocator {
 public:
  FeatureOdometryLocator(features::FeatureSettings features, const OdometrySettings& odometry,
                         bool deskew, const Eigen::Isometry3d& T_map_first)
      : features_(features), odometry_(odometry), deskew_(deskew), T_map_first_(T_map_first) {}

  std::optional<ScanPlacement> locate(const Scan& scan, std::string& why) override {
    const auto start = std::chrono::steady_clock::now();
    const FeatureSet found = features::extract_features(scan, features_);
    const auto extracted = std::chrono::steady_clock::now();
    // With odometry.deskew the registration deskews the features with the motion it is
    // estimating for this scan (FeatureOdometry) and gives the pose at the stamp. Without it
    // the features are registered as measured, over the whole sweep: the pose that fits them
    // best is the sensor's at about their mean time, and the pose at the stamp follows from
    // the motion between the scans. (Deskewing the features with the last scan's motion
    // before registration fed each motion error into the next estimate and made it oscillate.)
    const OdometryResult result = odometry_.register_scan(found, scan.imu);
    counts_.features_ms.push_back(milliseconds(extracted - start));
    counts_.registration_ms.push_back(milliseconds(std::chrono::steady_clock::now() - extracted));
    counts_.association_ms.push_back(result.timing.association_ms);
    counts_.solve_ms.push_back(result.timing.solve_ms);
    counts_.map_update_ms.push_back(result.timing.map_update_ms);
    counts_.features_per_scan.push_back(static_cast<double>(found.size()));
    counts_.map_edges = result.map_edges;
    counts_.map_surfaces = result.map_surfaces;
    ++counts_.scans;
    counts_.features_sum += static_cast<double>(found.size());
    if (found.intensity_confirmed) ++counts_.intensity_confirmed_scans;
    if (result.diagnostics.degenerate) ++counts_.degenerate_scans;
    if (result.turn_searched) ++counts_.turn_searches;
    if (result.turn_found) ++counts_.turns_found;
    const std::string jump = time_jump(result.elapsed_s, counts_.scans > 1, scan.sequence);
    if (!result.diagnostics.converged && counts_.scans > 1) {
      ++counts_.failed_scans;
      why = "scan " + std::to_string(scan.sequence) + " not registered (" + result.reason +
            "): the pose is the prediction";
    }
    if (!jump.empty()) why = why.empty() ? jump : why + "; " + jump;
    if (result.standing) {
      if (!last_standing_) ++counts_.stands;
      ++counts_.standing_scans;
      counts_.standing_s += result.elapsed_s;
    }
    last_standing_ = result.standing;
    // A standing scan is placed as measured: the sensor did not move within it.
    if (result.standing) last_sweep_ = SweepMotion();
    if (result.sweep.moving()) last_sweep_ = result.sweep;
    const bool moving = last_sweep_.moving();

    ScanPlacement placed;
    placed.sequence = scan.sequence;
    placed.stamp_ns = scan.stamp_ns;
    placed.T_map_sensor = T_map_first_ * result.T_map_sensor;
    if (moving && !deskew_) {
      const double fit_time_s = mean_time(found.edge_time_s, found.surface_time_s);
      placed.T_map_sensor = placed.T_map_sensor * last_sweep_.at(-fit_time_s);
    }
    placed.diagnostics = result.diagnostics;
    if (deskew_ && moving) {
      placed.column_T_map_sensor = column_poses(scan, placed.T_map_sensor, [&](double t) {
        return std::optional<Eigen::Isometry3d>(placed.T_map_sensor * last_sweep_.at(t));
      });
    }
    return placed;
  }

  std::string description() const override {
    return std::string("odometry (features") +
           (features_.intensity_fusion ? " with intensity edges" : "") +
           ", point-to-line / point-to-plane registration" +
           (deskew_ ? ", scans deskewed for the map)" : ")");
  }

  OdometryCounts counts() const override { return counts_; }

 private:
  /// A warning when the time since the last scan is not one scan period: frames dropped (more
  /// than 1.5 periods: the prediction was scaled to the gap) or a stamp that does not grow.
  /// The period is the shortest gap seen so far.
  std::string time_jump(double elapsed_s, bool after_first, uint64_t sequence) {
    if (!after_first) return {};
    if (!(elapsed_s > 0.0)) {
      ++counts_.time_jumps;
      return "scan " + std::to_string(sequence) +
             ": its stamp is not after the last scan's: no motion predicted";
    }
    if (!(period_s_ > 0.0) || elapsed_s < period_s_) period_s_ = elapsed_s;
    if (elapsed_s <= 1.5 * period_s_) return {};
    ++counts_.time_jumps;
    char text[160];
    std::snprintf(text, sizeof(text),
                  "scan %llu: %.3f s since the last scan, %.1f scan periods (frames dropped?): "
                  "the motion was predicted over the gap",
                  static_cast<unsigned long long>(sequence), elapsed_s, elapsed_s / period_s_);
    return text;
  }

  features::FeatureSettings features_;
  FeatureOdometry odometry_;
  bool deskew_;
  Eigen::Isometry3d T_map_first_;
  /// The motion within the last scan whose stamp advanced (a scan stamped like the last one
  /// is deskewed with it).
  SweepMotion last_sweep_;
  double period_s_ = 0.0;  ///< the shortest time between two scans so far
  bool last_standing_ = false;
  OdometryCounts counts_;
};

}  // namespace

std::unique_ptr<OdometryLocator> make_odometry_locator(const config::Config& config,
                                                       const Eigen::Isometry3d& T_map_first) {
  return std::make_unique<FeatureOdometryLocator>(
      features::from_config(config), from_config(config), config.odometry.deskew, T_map_first);
}

}  // namespace featsense::slam::odometry
