// The simulator against an empty box room: exact geometry, the noise bounds, beam
// elevations, and motion distortion undone with the ground-truth poses.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/slam/sim/lidar_simulator.hpp"
#include "sim_test_util.hpp"

namespace featsense::slam {
namespace {

using test::Box;

struct BoxScene {
  Box box;
  mesh::TriangleMesh mesh = test::box_mesh(box);
  RayCaster caster{mesh};
};

/// Beam origin of column c in the sensor frame, from the sensor model's definition.
Eigen::Vector3d beam_origin(const config::SensorModel& s, int col) {
  const double encoder = -2.0 * M_PI * col / s.columns;
  return s.beam_origin_offset_m * Eigen::Vector3d(std::cos(encoder), std::sin(encoder), 0.0);
}

TEST(SimBoxRoom, NoiseOffEveryReturnLiesOnAWall) {
  BoxScene setup;
  const auto trajectory =
      make_spline_trajectory({Eigen::Vector3d(-2, -1, 1.4), Eigen::Vector3d(2, 1, 1.6)}, 1.0);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement = MeasurementSettings::exact();
  const LidarSimulator sim(setup.mesh, setup.caster, *trajectory, settings);
  const SimulatedFrame frame = sim.simulate(0);
  const Scan& scan = frame.scan;
  ASSERT_EQ(scan.rows, 32);
  ASSERT_EQ(scan.cols, 256);
  EXPECT_EQ(scan.valid_count(), scan.size());  // a closed room returns every beam
  double worst = 0.0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      const Eigen::Vector3d local = scan.xyz[i].cast<double>();
      const double t = frame.start_s + scan.time_offset_s[i];
      EXPECT_NEAR(t, frame.start_s + 0.1 * col / 256.0, 1e-6);
      worst = std::max(worst, test::distance_to_box(trajectory->pose(t) * local, setup.box));
      // Range from the lidar origin: beam origin offset plus the distance from the beam origin.
      const double expected_range =
          settings.sensor.beam_origin_offset_m + (local - beam_origin(settings.sensor, col)).norm();
      EXPECT_NEAR(scan.range_m[i], expected_range, 1e-4);
    }
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(SimBoxRoom, NoisyReturnsStayWithinTheNoiseBound) {
  BoxScene setup;
  const auto trajectory =
      make_spline_trajectory({Eigen::Vector3d(-2, -1, 1.4), Eigen::Vector3d(2, 1, 1.6)}, 1.0);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement.seed = 7;
  settings.measurement.mixed_pixels = false;  // points between surfaces: tested below
  const LidarSimulator sim(setup.mesh, setup.caster, *trajectory, settings);
  const SimulatedFrame frame = sim.simulate(1);
  double worst = 0.0;
  double sum_sq = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < frame.scan.size(); ++i) {
    if (!frame.scan.valid[i]) continue;
    const double t = frame.start_s + frame.scan.time_offset_s[i];
    const Eigen::Vector3d p = trajectory->pose(t) * frame.scan.xyz[i].cast<double>();
    const double d = test::distance_to_box(p, setup.box);
    worst = std::max(worst, d);
    sum_sq += d * d;
    ++n;
  }
  ASSERT_GT(n, frame.scan.size() / 2);
  // Truncated at 3 sigma, sigma at most 10/3 cm: Ouster's +-1.5 .. +-10 cm.
  EXPECT_LE(worst, settings.measurement.sigma_max_m * 3.0 + 1e-4);
  // The noise is there: distances (|error| projected on the wall normal) average a few mm.
  const double rms = std::sqrt(sum_sq / static_cast<double>(n));
  EXPECT_GT(rms, 0.5 * settings.measurement.sigma_min_m);
  EXPECT_LT(rms, settings.measurement.sigma_max_m);
}

TEST(SimBoxRoom, BeamElevationsRecoveredFromThePointsMatchTheSensorModel) {
  BoxScene setup;
  // Standing still (a very slow path) so that each column's pose is the same.
  const auto trajectory =
      make_spline_trajectory({Eigen::Vector3d(0, 0, 1.5), Eigen::Vector3d(1e-3, 0, 1.5)}, 1e-4);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement = MeasurementSettings::exact();
  const LidarSimulator sim(setup.mesh, setup.caster, *trajectory, settings);
  const Scan scan = sim.simulate(0).scan;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; col += 17) {
      const Eigen::Vector3d v =
          scan.xyz[scan.index(row, col)].cast<double>() - beam_origin(settings.sensor, col);
      const double elevation = std::atan2(v.z(), std::hypot(v.x(), v.y()));
      EXPECT_NEAR(elevation, settings.sensor.elevation_rad[static_cast<size_t>(row)], 2e-5);
      const double azimuth = std::atan2(v.y(), v.x());
      const double expected = -2.0 * M_PI * col / scan.cols +
                              settings.sensor.azimuth_offset_rad[static_cast<size_t>(row)];
      EXPECT_NEAR(std::remainder(azimuth - expected, 2.0 * M_PI), 0.0, 2e-5);
    }
  }
}

TEST(SimBoxRoom, MotionDistortsTheScanAndGroundTruthUndistortsIt) {
  BoxScene setup;
  // A fast, turning, tilting path: 3 m/s with roll and pitch.
  const auto trajectory = make_spline_trajectory(
      {Eigen::Vector3d(-3, -2, 1.0), Eigen::Vector3d(0, 1, 2.0), Eigen::Vector3d(3, -1, 1.2)}, 3.0,
      /*tilt=*/true);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement = MeasurementSettings::exact();
  const LidarSimulator sim(setup.mesh, setup.caster, *trajectory, settings);
  ASSERT_GE(sim.frames_available(), 3u);
  const SimulatedFrame frame = sim.simulate(2);
  double undistorted = 0.0;
  double with_frame_pose = 0.0;
  const Eigen::Isometry3d frame_pose = trajectory->pose(frame.start_s);
  for (size_t i = 0; i < frame.scan.size(); ++i) {
    if (!frame.scan.valid[i]) continue;
    const Eigen::Vector3d local = frame.scan.xyz[i].cast<double>();
    const double t = frame.start_s + frame.scan.time_offset_s[i];
    undistorted =
        std::max(undistorted, test::distance_to_box(trajectory->pose(t) * local, setup.box));
    with_frame_pose =
        std::max(with_frame_pose, test::distance_to_box(frame_pose * local, setup.box));
  }
  EXPECT_LT(undistorted, 1e-4);
  EXPECT_GT(with_frame_pose, 0.1);  // 0.3 m of travel and a turn within the revolution
}

/// Distance from a point outside an axis-aligned box to the box (0 inside).
double distance_outside(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                        const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
}

TEST(SimBoxRoom, MixedPixelsLieBetweenAnEdgeAndTheSurfaceBehindIt) {
  // The room with a pillar: its vertical edges are depth discontinuities, nothing else is.
  const Box box;
  mesh::TriangleMesh mesh = test::box_mesh(box);
  const Eigen::Vector3d pillar_lo(2.0, -0.5, 0.0);
  const Eigen::Vector3d pillar_hi(2.6, 0.1, 3.0);
  mesh.add_box(pillar_lo.cast<float>(), pillar_hi.cast<float>(), 0);
  const RayCaster caster(mesh);
  const auto trajectory =
      make_spline_trajectory({Eigen::Vector3d(-1, 0, 1.5), Eigen::Vector3d(-1, 1e-3, 1.5)}, 1e-4);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement = MeasurementSettings::exact();
  settings.measurement.mixed_pixels = true;
  settings.measurement.mixed_probability = 1.0;
  const LidarSimulator sim(mesh, caster, *trajectory, settings);
  const SimulatedFrame frame = sim.simulate(0);
  const Scan& scan = frame.scan;
  const Eigen::Isometry3d pose = trajectory->pose(0.0);
  size_t mixed = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      ASSERT_TRUE(scan.valid[i]);
      const Eigen::Vector3d p = pose * scan.xyz[i].cast<double>();
      const double off_surface =
          std::min(test::distance_to_box(p, box), distance_outside(p, pillar_lo, pillar_hi));
      if (off_surface < 1e-4) continue;
      ++mixed;
      // Beside the pillar's silhouette: a neighbouring column sees the wall behind.
      double neighbour = 0.0;
      for (int n : {col - 1, col + 1}) {
        neighbour =
            std::max<double>(neighbour, scan.range_m[scan.index(row, (n + scan.cols) % scan.cols)]);
      }
      EXPECT_GT(neighbour, scan.range_m[i]) << row << " " << col;
    }
  }
  EXPECT_GT(mixed, 0u);
  EXPECT_LT(mixed, 4u * static_cast<size_t>(scan.rows));  // two edges, one cell each side
}

TEST(SimBoxRoom, NothingBeyondMaxRangeOrInsideMinRange) {
  BoxScene setup;
  const auto trajectory =
      make_spline_trajectory({Eigen::Vector3d(-4.5, 0, 1.5), Eigen::Vector3d(-4, 0, 1.5)}, 1.0);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.sensor.min_range_m = 0.6;
  settings.sensor.max_range_m = 5.0;
  settings.measurement = MeasurementSettings::exact();
  const LidarSimulator sim(setup.mesh, setup.caster, *trajectory, settings);
  const Scan scan = sim.simulate(0).scan;
  size_t valid = 0;
  for (size_t i = 0; i < scan.size(); ++i) {
    if (!scan.valid[i]) continue;
    ++valid;
    EXPECT_GE(scan.range_m[i], 0.6f);
    EXPECT_LE(scan.range_m[i], 5.0f);
  }
  EXPECT_GT(valid, 0u);
  EXPECT_LT(valid, scan.size());  // the far wall (10 m away) is out of range
}

}  // namespace
}  // namespace featsense::slam
