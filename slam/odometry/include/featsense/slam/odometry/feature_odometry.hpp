#pragma once
/// F-LOAM-style odometry: each scan's features registered against the local feature map,
/// from a constant-velocity prediction. Not thread-safe: one scan at a time, in order.

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <vector>

#include "featsense/slam/feature_set.hpp"
#include "featsense/slam/imu_sample.hpp"
#include "featsense/slam/odometry/odometry_result.hpp"
#include "featsense/slam/odometry/odometry_settings.hpp"
#include "featsense/slam/odometry/stand_detector.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::slam::odometry {

class LocalFeatureMap;
class RecentFits;
struct TimedFeatures;
struct RegistrationStart;

class FeatureOdometry {
 public:
  explicit FeatureOdometry(const OdometrySettings& settings);
  ~FeatureOdometry();
  FeatureOdometry(const FeatureOdometry&) = delete;
  FeatureOdometry& operator=(const FeatureOdometry&) = delete;

  /// Registers one scan: its pose at the stamp, never NaN. The first scan starts the map at
  /// the identity. An empty scan, too few correspondences or a diverging solve (a correction
  /// of the prediction beyond max_speed / max_turn_rate over the elapsed time, or a cost
  /// above the prediction's) give the prediction, with converged=false and the reason.
  /// In degenerate directions the pose keeps the prediction. A registration that fits far
  /// worse than the last scans' (odometry.poor_fit_ratio), or does not converge, is registered
  /// again from the prediction turned about the vertical (odometry.turn_search), and the
  /// best clearly better fit kept (turn_searched / turn_found). Every scan with features is
  /// then added to the map at the pose given. The second scan restarts the map with the
  /// first one deskewed, once the motion is known, and is registered again.
  /// With hold_still, a sensor that stands still (StandDetector) keeps the stand's pose and
  /// adds nothing to the map until its registration leaves the noise about that pose.
  /// `imu`: the IMU's samples of this sweep (Scan::imu), where the source has them: with
  /// the last sweep's they bend the deskewing motion by the measured turn (SweepMotion), and
  /// with the two sweeps before they turn the prediction as the gyroscope measured.
  OdometryResult register_scan(const FeatureSet& features, const std::vector<ImuSample>& imu = {});

 private:
  std::unique_ptr<LocalFeatureMap> new_map() const;
  Eigen::Isometry3d restart_map(const TimedFeatures& raw, const RegistrationStart& start,
                                const Eigen::Isometry3d& pose, const std::vector<ImuSample>& imu,
                                OdometryResult& result);
  /// The pose and precision a stand is judged by (see still_test in the source).
  struct StillTest {
    Eigen::Isometry3d pose;
    Eigen::Matrix<double, 6, 6> precision;
    bool converged;  ///< converged and observed well in every direction (see the source)
  };
  StillTest still_test(const TimedFeatures& raw, const RegistrationStart& start,
                       const Eigen::Isometry3d& pose, const OdometryResult& result) const;
  /// The motion from the last stamp to this one: the last motion at constant velocity, its
  /// rotation the gyroscope's turn where the samples cover this period and the last.
  Eigen::Isometry3d predicted_motion(int64_t stamp_ns, double elapsed_s,
                                     const std::vector<ImuSample>& imu) const;
  /// A registration that fits far worse than the last scans' searched again from turned
  /// starts (turn_search.hpp); the pose to keep.
  Eigen::Isometry3d search_if_poor(const TimedFeatures& raw, const RegistrationStart& start,
                                   const Eigen::Isometry3d& pose, OdometryResult& result);
  void hold(const Eigen::Isometry3d& pose, int64_t stamp_ns, OdometryResult& result);
  void add_to_map(const TimedFeatures& raw, const SweepMotion& sweep, const Eigen::Isometry3d& pose,
                  int64_t stamp_ns, OdometryResult& result);

  OdometrySettings settings_;
  std::unique_ptr<LocalFeatureMap> map_;
  /// The first scan's features as measured, until the second scan has restarted the map.
  std::unique_ptr<TimedFeatures> first_scan_;
  bool started_ = false;
  int64_t last_stamp_ns_ = 0;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  /// The last motion (previous <- current) and the time it took, for the prediction.
  Eigen::Isometry3d last_motion_ = Eigen::Isometry3d::Identity();
  double last_motion_s_ = 0.0;
  /// The last sweep's IMU samples: the gyroscope's mean rate over the period before a stamp.
  std::vector<ImuSample> last_imu_;
  /// The sweep's before it: with last_imu_, the gyroscope's turn over the last period.
  std::vector<ImuSample> earlier_imu_;
  /// The last pose's precision (OdometryResult::precision), for the stand detector.
  Eigen::Matrix<double, 6, 6> last_precision_ = Eigen::Matrix<double, 6, 6>::Zero();
  StandDetector stand_;
  /// The fits of the last registrations, against which a poor one is told.
  std::unique_ptr<RecentFits> recent_fits_;
};

}  // namespace featsense::slam::odometry
