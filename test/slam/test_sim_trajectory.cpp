// Splines through waypoints (C2, constant speed, yaw along travel), TUM files and their errors.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"

namespace featsense::slam {
namespace {

const std::vector<Eigen::Vector3d> kWaypoints = {
    Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(5, 1, 1.5), Eigen::Vector3d(8, 6, 1),
    Eigen::Vector3d(3, 9, 2), Eigen::Vector3d(-2, 7, 1)};
constexpr double kSpeed = 1.5;

Eigen::Vector3d position(const PoseCurve& t, double s) { return t.pose(s).translation(); }

/// The time at which the path passes closest to `p` (golden-section search around `guess`).
double time_nearest(const PoseCurve& t, const Eigen::Vector3d& p, double lo, double hi) {
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int k = 0; k < 200; ++k) {
    const double a = hi - g * (hi - lo);
    const double b = lo + g * (hi - lo);
    if ((position(t, a) - p).norm() < (position(t, b) - p).norm())
      hi = b;
    else
      lo = a;
  }
  return 0.5 * (lo + hi);
}

TEST(SimTrajectory, SplinePassesThroughWaypointsAtConstantSpeed) {
  const auto t = make_spline_trajectory(kWaypoints, kSpeed);
  EXPECT_NEAR((position(*t, 0.0) - kWaypoints.front()).norm(), 0.0, 1e-9);
  EXPECT_NEAR((position(*t, t->duration_s()) - kWaypoints.back()).norm(), 0.0, 1e-9);
  // The path is longer than the polyline through the waypoints.
  double polyline = 0.0;
  for (size_t i = 1; i < kWaypoints.size(); ++i)
    polyline += (kWaypoints[i] - kWaypoints[i - 1]).norm();
  EXPECT_GT(t->duration_s() * kSpeed, polyline);
  const double h = 1e-4;
  for (double s = 0.01; s < t->duration_s() - 0.01; s += 0.0731) {
    const double speed = (position(*t, s + h) - position(*t, s - h)).norm() / (2.0 * h);
    EXPECT_NEAR(speed, kSpeed, 1e-5) << "at t = " << s;
  }
  // Every interior waypoint lies on the path.
  for (size_t i = 1; i + 1 < kWaypoints.size(); ++i) {
    const double tw = time_nearest(*t, kWaypoints[i], 0.0, t->duration_s());
    EXPECT_LT((position(*t, tw) - kWaypoints[i]).norm(), 1e-6) << "waypoint " << i;
  }
}

TEST(SimTrajectory, AccelerationIsContinuousAtWaypoints) {
  const auto t = make_spline_trajectory(kWaypoints, kSpeed);
  const double h = 2e-3;
  for (size_t i = 1; i + 1 < kWaypoints.size(); ++i) {
    const double tw = time_nearest(*t, kWaypoints[i], 0.0, t->duration_s());
    const Eigen::Vector3d p0 = position(*t, tw);
    // One-sided second differences from each side of the waypoint.
    const Eigen::Vector3d left =
        (p0 - 2.0 * position(*t, tw - h) + position(*t, tw - 2.0 * h)) / (h * h);
    const Eigen::Vector3d right =
        (position(*t, tw + 2.0 * h) - 2.0 * position(*t, tw + h) + p0) / (h * h);
    // A C1-only join would jump by the order of speed^2 / radius (~0.5 m/s^2 here); a C2
    // one differs by the jerk times the stencil width only.
    EXPECT_LT((left - right).norm(), 0.03) << "waypoint " << i;
    EXPECT_GT(left.norm(), 0.01);  // the path does turn there
  }
}

TEST(SimTrajectory, YawFollowsTheDirectionOfTravelAndTiltLeansIntoTurns) {
  const auto flat = make_spline_trajectory(kWaypoints, kSpeed);
  const auto tilted = make_spline_trajectory(kWaypoints, kSpeed, true);
  for (double s = 0.5; s < flat->duration_s() - 0.5; s += 0.9) {
    const Eigen::Vector3d v = position(*flat, s + 1e-4) - position(*flat, s - 1e-4);
    const Eigen::Vector3d x_axis = flat->pose(s).rotation().col(0);
    EXPECT_NEAR(std::atan2(x_axis.y(), x_axis.x()), std::atan2(v.y(), v.x()), 1e-4);
    EXPECT_NEAR(flat->pose(s).rotation().col(2).z(), 1.0, 1e-12);  // upright
    // The tilted sensor's forward axis follows the velocity, climbs included.
    EXPECT_NEAR(tilted->pose(s).rotation().col(0).dot(v.normalized()), 1.0, 1e-6);
  }
  // Turning left (towards +y after the first waypoint): the sensor's up axis leans left.
  const double tw = time_nearest(*tilted, kWaypoints[2], 0.0, tilted->duration_s());
  const Eigen::Matrix3d r = tilted->pose(tw).rotation();
  const Eigen::Vector3d left = r.col(1);
  EXPECT_GT(r.col(2).dot(left - left.z() * Eigen::Vector3d::UnitZ()), 0.0);
}

TEST(SimTrajectory, APausedPathBrakesStandsAndGoesOn) {
  // Stand 3 s where the path is at 4 s, braking over 2 s: the path's own time is warped.
  const auto path = make_spline_trajectory(kWaypoints, kSpeed);
  const double duration_s = path->duration_s();
  const auto paused =
      make_paused_trajectory(make_spline_trajectory(kWaypoints, kSpeed), 5.0, 3.0, 2.0);
  EXPECT_NEAR(paused->duration_s(), duration_s + 5.0, 1e-12);
  // Before braking and after starting again: the path itself, shifted by the stand and a ramp.
  EXPECT_TRUE(paused->pose(2.5).isApprox(path->pose(2.5), 1e-12));
  EXPECT_TRUE(paused->pose(12.0).isApprox(path->pose(7.0), 1e-12));
  // Standing where the path is at 4 s, for the whole stand.
  for (double t = 5.0; t <= 8.0; t += 0.5) {
    EXPECT_TRUE(paused->pose(t).isApprox(path->pose(4.0), 1e-12)) << t;
  }
  // The speed falls and rises smoothly: no jump between samples 10 ms apart, and the braking
  // peaks at pi / 2 times the mean deceleration (1.5 m/s over 2 s: 1.18 m/s^2).
  const double h = 0.01;
  double last_speed = kSpeed;
  double largest_change = 0.0;
  for (double t = 2.0; t < 11.0; t += h) {
    const double speed = (position(*paused, t + h) - position(*paused, t)).norm() / h;
    largest_change = std::max(largest_change, std::abs(speed - last_speed) / h);
    last_speed = speed;
  }
  EXPECT_LT(largest_change, 1.3);
  EXPECT_GT(largest_change, 1.0);
  EXPECT_THROW(make_paused_trajectory(make_spline_trajectory(kWaypoints, kSpeed), 1.0, 3.0, 2.0),
               std::invalid_argument);  // braking would start before the path
  EXPECT_THROW(make_paused_trajectory(make_spline_trajectory(kWaypoints, kSpeed), 5.0, 0.0, 2.0),
               std::invalid_argument);
}

TEST(SimTrajectory, BadSplinesAreRefused) {
  EXPECT_THROW(make_spline_trajectory({Eigen::Vector3d::Zero()}, 1.0), std::invalid_argument);
  EXPECT_THROW(make_spline_trajectory(kWaypoints, 0.0), std::invalid_argument);
  EXPECT_THROW(make_spline_trajectory({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, 1.0),
               std::invalid_argument);
}

TEST(SimTrajectory, TumRoundTripAndInterpolation) {
  const auto dir = test::scratch_dir("sim_tum");
  const auto spline = make_spline_trajectory(kWaypoints, kSpeed, true);
  std::vector<StampedPose> poses;
  for (int k = 0; k <= 20; ++k) {
    StampedPose p;
    p.t_s = 1700000000.0 + 0.5 * k;
    p.T_map_sensor = spline->pose(0.5 * k);
    poses.push_back(p);
  }
  const std::string path = (dir / "poses.tum").string();
  write_tum(to_trajectory(poses), path);
  const std::vector<StampedPose> back = to_stamped_poses(read_tum(path));
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(back[i].t_s, poses[i].t_s, 1e-6);
    // TUM files keep 9 decimals: nanometres, and quaternions to 1e-9.
    EXPECT_TRUE(back[i].T_map_sensor.isApprox(poses[i].T_map_sensor, 1e-8));
  }
  const auto sampled = make_sampled_trajectory(back);
  EXPECT_NEAR(sampled->duration_s(), 10.0, 1e-6);
  // Half way between samples: the mean of the positions.
  const Eigen::Vector3d mid =
      0.5 * (poses[3].T_map_sensor.translation() + poses[4].T_map_sensor.translation());
  EXPECT_LT((sampled->pose(1.75).translation() - mid).norm(), 1e-6);
}

}  // namespace
}  // namespace featsense::slam
