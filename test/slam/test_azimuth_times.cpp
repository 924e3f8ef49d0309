// Per-point times from the azimuth for clouds without a time field: firing order and ring
// by ring, the seam from the first points, the stamp's reference (sweep start or KITTI's
// forward-facing instant), and clouds whose order tells no times.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/azimuth_times.hpp"

namespace featsense::slam {
namespace {

constexpr double kRateHz = 10.0;
constexpr double kDeg = M_PI / 180.0;

/// A cloud of known point times.
struct TimedCloud {
  std::vector<Eigen::Vector3f> xyz;
  std::vector<double> time_s;  ///< when the sensor fired at each point, after the sweep began
  std::vector<int> beam;       ///< each point's beam: its row in a scan
};

/// A point `cw` radians clockwise from +x seen from above, at elevation `e`, `d` metres away.
Eigen::Vector3f point_at(double cw, double e, double d) {
  return Eigen::Vector3d(d * std::cos(e) * std::cos(-cw), d * std::cos(e) * std::sin(-cw),
                         d * std::sin(e))
      .cast<float>();
}

/// How a synthetic sweep is laid out.
struct SweepSpec {
  config::SensorModel sensor;
  double seam_rad = 0.0;           ///< where the sweep begins, clockwise from +x
  bool ring_by_ring = false;       ///< else firing order: every beam of a column, column by column
  std::vector<double> offset_rad;  ///< per beam, added to its azimuth (none: all 0)
  double dropout = 0.1;            ///< share of points without a return
};

/// One revolution of spec.sensor, columns from the seam on, at random ranges; a share of the
/// points have no return and are left out, as KITTI files leave them out.
TimedCloud sweep(const SweepSpec& spec) {
  const config::SensorModel& s = spec.sensor;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  TimedCloud cloud;
  auto add = [&](int beam, int step) {
    const double offset = spec.offset_rad.empty() ? 0.0 : spec.offset_rad[beam];
    const double encoder = spec.seam_rad + 2.0 * M_PI * step / s.columns;
    if (uniform(random) < spec.dropout) return;
    const double d = 4.0 + 20.0 * uniform(random);
    cloud.xyz.push_back(point_at(encoder + offset, s.elevation_rad[beam], d));
    cloud.time_s.push_back(step / (s.columns * s.rate_hz));
    cloud.beam.push_back(beam);
  };
  if (spec.ring_by_ring) {
    for (int beam = 0; beam < s.beams; ++beam) {
      for (int step = 0; step < s.columns; ++step) add(beam, step);
    }
  } else {
    for (int step = 0; step < s.columns; ++step) {
      for (int beam = 0; beam < s.beams; ++beam) add(beam, step);
    }
  }
  return cloud;
}

/// The time of a point `shift_s` later (the forward-facing instant as zero: minus its time).
std::vector<double> shifted(const std::vector<double>& times, double shift_s) {
  std::vector<double> out = times;
  for (double& t : out) t -= shift_s;
  return out;
}

/// The largest |derived - known| over the cloud's points.
double largest_error_s(const AzimuthTimes& derived, const std::vector<double>& known) {
  double largest = 0.0;
  for (size_t i = 0; i < known.size(); ++i) {
    largest = std::max(largest, std::abs(derived.offset_s[i] - known[i]));
  }
  return largest;
}

double column_s(const config::SensorModel& sensor) {
  return 1.0 / (sensor.columns * sensor.rate_hz);
}

TEST(AzimuthTimes, FiringOrderFromBehindTheSensor) {
  SweepSpec spec;
  spec.sensor = config::sensor_preset("vlp16");
  spec.seam_rad = 200.0 * kDeg;
  const TimedCloud cloud = sweep(spec);
  const AzimuthTimes times = azimuth_times(cloud.xyz, kRateHz, SweepReference::kSweepStart);
  ASSERT_TRUE(times.found()) << times.problem;
  EXPECT_EQ(times.sweeps, 1);
  EXPECT_NEAR(times.seam_rad, spec.seam_rad, 1e-4);
  EXPECT_LE(largest_error_s(times, cloud.time_s), column_s(spec.sensor));
  EXPECT_NE(describe(times).find("from the azimuth (the sweep began 200.0 deg clockwise of +x, "
                                 "points in firing order; 0 s where it began)"),
            std::string::npos)
      << describe(times);

  // The instant the sensor faced +x, 160 deg into the sweep, as zero.
  const AzimuthTimes forward = azimuth_times(cloud.xyz, kRateHz, SweepReference::kFacingForward);
  ASSERT_TRUE(forward.found());
  const double facing_s = 160.0 / 360.0 / kRateHz;
  EXPECT_LE(largest_error_s(forward, shifted(cloud.time_s, facing_s)), column_s(spec.sensor));
}

TEST(AzimuthTimes, BeamAzimuthOffsetsShiftTimesByTheirAngleOnly) {
  // HDL-64-like offsets (-9 .. +9 deg): a firing's points spread over 18 deg, and those of the
  // last firings run past the seam. The sweep begins at the first firing's earliest point,
  // so each point is late by its beam's offset above the smallest, never a revolution off.
  SweepSpec spec;
  spec.sensor = config::sensor_preset("hdl64");
  spec.seam_rad = 90.0 * kDeg;
  for (int b = 0; b < spec.sensor.beams; ++b) spec.offset_rad.push_back(((b * 7) % 19 - 9) * kDeg);
  const TimedCloud cloud = sweep(spec);
  const AzimuthTimes times = azimuth_times(cloud.xyz, kRateHz, SweepReference::kSweepStart);
  ASSERT_TRUE(times.found()) << times.problem;
  EXPECT_EQ(times.sweeps, 1);
  EXPECT_NEAR(times.seam_rad, 81.0 * kDeg, 0.2 * kDeg);
  const double offsets_s = 18.0 / 360.0 / kRateHz;
  EXPECT_LE(largest_error_s(times, cloud.time_s), offsets_s + column_s(spec.sensor));
}

TEST(AzimuthTimes, RingByRingEveryRingRestartsAtTheSeam) {
  // KITTI-like: ring after ring, each from the seam behind the sensor; times around the
  // instant the sensor faced +x, half a revolution in.
  SweepSpec spec;
  spec.sensor = config::sensor_preset("hdl64");
  spec.seam_rad = M_PI;
  spec.ring_by_ring = true;
  const TimedCloud cloud = sweep(spec);
  const AzimuthTimes times = azimuth_times(cloud.xyz, kRateHz, SweepReference::kFacingForward);
  ASSERT_TRUE(times.found()) << times.problem;
  EXPECT_EQ(times.sweeps, spec.sensor.beams);
  EXPECT_NEAR(times.seam_rad, M_PI, 1e-4);
  const double half_s = 0.5 / kRateHz;
  EXPECT_LE(largest_error_s(times, shifted(cloud.time_s, half_s)), column_s(spec.sensor));
  for (const float t : times.offset_s) {
    EXPECT_GE(t, -half_s - 1e-6);
    EXPECT_LE(t, half_s);
  }
  EXPECT_NE(describe(times).find("64 rings one after another; 0 s where the sensor faced +x"),
            std::string::npos)
      << describe(times);

  // Beams with azimuth offsets of -9 .. +9 deg: rings begin before the seam or run past it,
  // before or after the previous ring ended. Each point belongs to its own ring's turn
  // (early or late by its offset), never to the neighbouring ring's (a revolution off).
  std::mt19937 random(11);
  std::uniform_real_distribution<double> offset(-9.0 * kDeg, 9.0 * kDeg);
  for (int b = 0; b < spec.sensor.beams; ++b)
    spec.offset_rad.push_back(b == 0 ? 0.0 : offset(random));
  const TimedCloud offset_cloud = sweep(spec);
  const AzimuthTimes offsets =
      azimuth_times(offset_cloud.xyz, kRateHz, SweepReference::kFacingForward);
  ASSERT_TRUE(offsets.found()) << offsets.problem;
  EXPECT_EQ(offsets.sweeps, spec.sensor.beams);
  EXPECT_LE(largest_error_s(offsets, shifted(offset_cloud.time_s, half_s)),
            9.0 / 360.0 / kRateHz + column_s(spec.sensor));

  // The first ring's first 20 deg of returns are missing, and it has few after them (sky):
  // the seam is where the other rings begin, not where the file's first point lies.
  spec.offset_rad.clear();
  const TimedCloud full = sweep(spec);
  TimedCloud late;
  for (size_t i = 0; i < full.xyz.size(); ++i) {
    const bool sparse = full.beam[i] == 0 && (full.time_s[i] < 20.0 / 360.0 / kRateHz || i % 25);
    if (sparse) continue;
    late.xyz.push_back(full.xyz[i]);
    late.time_s.push_back(full.time_s[i]);
    late.beam.push_back(full.beam[i]);
  }
  const AzimuthTimes from_start = azimuth_times(late.xyz, kRateHz, SweepReference::kSweepStart);
  ASSERT_TRUE(from_start.found()) << from_start.problem;
  EXPECT_NEAR(from_start.seam_rad, M_PI, 2 * M_PI / spec.sensor.columns);
  EXPECT_LE(largest_error_s(from_start, late.time_s), 2 * column_s(spec.sensor));
}

TEST(AzimuthTimes, PointsOutOfOrderTellNoTimes) {
  SweepSpec spec;
  spec.sensor = config::sensor_preset("vlp16");
  const TimedCloud cloud = sweep(spec);

  std::vector<Eigen::Vector3f> shuffled = cloud.xyz;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
  const AzimuthTimes random = azimuth_times(shuffled, kRateHz, SweepReference::kSweepStart);
  EXPECT_FALSE(random.found());
  EXPECT_NE(random.problem.find("not in the order they were measured"), std::string::npos)
      << random.problem;
  // Shuffled after the first firing: the seam is found, the steps give it away.
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
  std::copy(cloud.xyz.begin(), cloud.xyz.begin() + 16, shuffled.begin());
  const AzimuthTimes later = azimuth_times(shuffled, kRateHz, SweepReference::kSweepStart);
  EXPECT_FALSE(later.found());
  EXPECT_NE(later.problem.find("not in the order they were measured"), std::string::npos)
      << later.problem;

  // Sorted by height: rings, but in no order within them.
  std::vector<Eigen::Vector3f> by_z = cloud.xyz;
  std::stable_sort(by_z.begin(), by_z.end(),
                   [](const auto& a, const auto& b) { return a.z() < b.z(); });
  EXPECT_FALSE(azimuth_times(by_z, kRateHz, SweepReference::kSweepStart).found());

  // Counterclockwise: the sweep read backwards.
  const std::vector<Eigen::Vector3f> reversed(cloud.xyz.rbegin(), cloud.xyz.rend());
  const AzimuthTimes backwards = azimuth_times(reversed, kRateHz, SweepReference::kSweepStart);
  EXPECT_FALSE(backwards.found());
  EXPECT_NE(backwards.problem.find("counterclockwise"), std::string::npos) << backwards.problem;
  EXPECT_EQ(describe(backwards), "none: " + backwards.problem);

  const std::vector<Eigen::Vector3f> few(cloud.xyz.begin(), cloud.xyz.begin() + 20);
  EXPECT_NE(azimuth_times(few, kRateHz, SweepReference::kSweepStart).problem.find("too few"),
            std::string::npos);
}

}  // namespace
}  // namespace featsense::slam
