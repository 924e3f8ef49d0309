// Per-point times from the azimuth for clouds without a time field: firing order and ring
// by ring, the seam from the first points, the stamp's reference (sweep start or KITTI's
// forward-facing instant), clouds whose order tells no times, the readers that use them,
// and a round trip of simulated scans through KITTI .bin files.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "common/test_data.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/azimuth_times.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/io/scan_writers.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/scene_library.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

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

/// An unorganized cloud as a file without a time field would decode.
DecodedCloud decoded_of(std::vector<Eigen::Vector3f> xyz) {
  DecodedCloud decoded;
  decoded.format = "pcd";
  decoded.width = static_cast<int>(xyz.size());
  decoded.fields = {"x", "y", "z"};
  decoded.cloud.xyz = std::move(xyz);
  return decoded;
}

/// The largest |scan time - known| over the scan's valid cells, `known` per cell.
double largest_cell_error_s(const Scan& scan, const std::vector<double>& known_by_cell) {
  double largest = 0.0;
  for (size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i]) {
      largest = std::max(largest, std::abs(scan.time_offset_s[i] - known_by_cell[i]));
    }
  }
  return largest;
}

/// Per cell of `sensor`'s scan, the time of the point of `cloud` that organize() puts there:
/// a sweep()'s points lie on their beams, each in the column of its azimuth.
std::vector<double> times_by_cell(const TimedCloud& cloud, const config::SensorModel& sensor) {
  std::vector<double> by_cell(static_cast<size_t>(sensor.beams * sensor.columns), 0.0);
  for (size_t i = 0; i < cloud.xyz.size(); ++i) {
    const int col = column_of(cloud.xyz[i], sensor.columns);
    by_cell[static_cast<size_t>(cloud.beam[i] * sensor.columns + col)] = cloud.time_s[i];
  }
  return by_cell;
}

TEST(AzimuthTimes, CloudToScanDerivesKeepsOrReportsTimes) {
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  SweepSpec spec;
  spec.sensor = vlp16;
  spec.seam_rad = 30.0 * kDeg;
  const TimedCloud cloud = sweep(spec);
  const std::vector<double> known = times_by_cell(cloud, vlp16);

  // No time field: from the azimuth.
  std::vector<std::string> warnings;
  std::string times;
  Scan scan = cloud_to_scan(decoded_of(cloud.xyz), vlp16, "a.pcd", nullptr, &warnings, {}, &times);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(times.rfind("from the azimuth (the sweep began 30.0 deg", 0), 0u) << times;
  EXPECT_LE(largest_cell_error_s(scan, known), column_s(vlp16));

  // A time field of its own wins, even where it disagrees with the azimuth.
  DecodedCloud timed = decoded_of(cloud.xyz);
  timed.fields.push_back("time");
  for (const double t : cloud.time_s)
    timed.cloud.time_offset_s.push_back(static_cast<float>(t / 2));
  scan = cloud_to_scan(timed, vlp16, "b.pcd", nullptr, &warnings, {}, &times);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(times, "per-point field 'time'");
  std::vector<double> halved = known;
  for (double& t : halved) t /= 2;
  EXPECT_LE(largest_cell_error_s(scan, halved), 1e-7);

  // Shuffled: no times, a warning, and the report says why.
  std::vector<Eigen::Vector3f> shuffled = cloud.xyz;
  std::shuffle(shuffled.begin() + 16, shuffled.end(), std::mt19937(5));
  scan = cloud_to_scan(decoded_of(shuffled), vlp16, "c.pcd", nullptr, &warnings, {}, &times);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("c.pcd: no per-point times from the azimuth: the points are not in "
                              "the order they were measured",
                              0),
            0u)
      << warnings[0];
  EXPECT_EQ(times.rfind("none: the points are not in the order", 0), 0u) << times;
  EXPECT_EQ(std::count(scan.time_offset_s.begin(), scan.time_offset_s.end(), 0.0f),
            static_cast<std::ptrdiff_t>(scan.size()));

  // sensor.times_from_azimuth: false.
  warnings.clear();
  CloudTiming off;
  off.from_azimuth = false;
  scan = cloud_to_scan(decoded_of(cloud.xyz), vlp16, "d.pcd", nullptr, &warnings, off, &times);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(times, "none: no time field, and sensor.times_from_azimuth is false");
  EXPECT_EQ(std::count(scan.time_offset_s.begin(), scan.time_offset_s.end(), 0.0f),
            static_cast<std::ptrdiff_t>(scan.size()));
}

TEST(AzimuthTimes, OrganizedCloudWithoutTimesIsReadRowByRow) {
  // An organized range image stores its rows one after another: ring by ring from column 0.
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  DecodedCloud decoded;
  decoded.format = "pcd";
  decoded.height = vlp16.beams;
  decoded.width = vlp16.columns;
  decoded.fields = {"x", "y", "z"};
  for (int row = 0; row < vlp16.beams; ++row) {
    for (int col = 0; col < vlp16.columns; ++col) {
      const bool hole = (row * 31 + col) % 10 == 0;
      decoded.cloud.xyz.push_back(
          hole ? Eigen::Vector3f::Zero()
               : point_at(2.0 * M_PI * col / vlp16.columns, vlp16.elevation_rad[row], 8.0));
    }
  }
  std::string times;
  const Scan scan = cloud_to_scan(decoded, vlp16, "o.pcd", nullptr, nullptr, {}, &times);
  EXPECT_NE(times.find("16 rings one after another"), std::string::npos) << times;
  std::vector<double> known(scan.size());
  for (size_t i = 0; i < scan.size(); ++i) known[i] = column_s(vlp16) * (i % vlp16.columns);
  EXPECT_LE(largest_cell_error_s(scan, known), 1e-6);
}

void write_bin(const fs::path& path, const std::vector<Eigen::Vector3f>& xyz) {
  std::ofstream out(path, std::ios::binary);
  for (const Eigen::Vector3f& p : xyz) {
    const float record[4] = {p.x(), p.y(), p.z(), 0.5f};
    out.write(reinterpret_cast<const char*>(record), sizeof record);
  }
}

std::vector<Scan> read_all(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

TEST(AzimuthTimes, KittiSequenceTimesCountFromFacingForward) {
  // KITTI's layout: sequences/00/times.txt beside sequences/00/velodyne/*.bin, points ring
  // by ring from behind the car.
  const fs::path sequence = test::scratch_dir("azimuth_times_kitti");
  const fs::path velodyne = sequence / "velodyne";
  fs::create_directories(velodyne);
  SweepSpec spec;
  spec.sensor = config::sensor_preset("hdl64");
  // Behind the sensor, on a column's centre: the scan's cells hold one point each.
  const int seam_col = (spec.sensor.columns + 1) / 2;
  spec.seam_rad = 2.0 * M_PI * seam_col / spec.sensor.columns;
  spec.ring_by_ring = true;
  const TimedCloud cloud = sweep(spec);
  const std::vector<double> known = times_by_cell(cloud, spec.sensor);
  const double half_s = column_s(spec.sensor) * (spec.sensor.columns - seam_col);
  for (int n = 0; n < 2; ++n)
    write_bin(velodyne / ("00000" + std::to_string(n) + ".bin"), cloud.xyz);
  std::ofstream(sequence / "times.txt") << "0.000000e+00\n1.036592e-01\n";

  const auto source = open_scan_folder(velodyne.string(), {});
  EXPECT_NE(source->info().times.find("0 s where the sensor faced +x"), std::string::npos)
      << source->info().times;
  std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[1].stamp_ns, 103659200);
  for (const Scan& scan : scans) {
    EXPECT_LE(largest_cell_error_s(scan, shifted(known, half_s)), column_s(spec.sensor));
  }
  EXPECT_EQ(source->stats().warning_count, 0u);

  // Without times.txt the stamps are the sweeps' starts.
  fs::remove(sequence / "times.txt");
  const auto unstamped = open_scan_folder(velodyne.string(), {});
  EXPECT_NE(unstamped->info().times.find("0 s where it began"), std::string::npos)
      << unstamped->info().times;
  scans = read_all(*unstamped);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_LE(largest_cell_error_s(scans[0], known), column_s(spec.sensor));

  // Points out of order: no times, counted per frame.
  std::vector<Eigen::Vector3f> shuffled = cloud.xyz;
  std::shuffle(shuffled.begin() + 16, shuffled.end(), std::mt19937(9));
  write_bin(velodyne / "000001.bin", shuffled);
  const auto mixed = open_scan_folder(velodyne.string(), {});
  scans = read_all(*mixed);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(mixed->stats().warning_count, 1u);
  ASSERT_EQ(mixed->stats().warnings.size(), 1u);
  EXPECT_NE(mixed->stats().warnings[0].find("000001.bin: no per-point times from the azimuth"),
            std::string::npos)
      << mixed->stats().warnings[0];
  EXPECT_EQ(std::count(scans[1].time_offset_s.begin(), scans[1].time_offset_s.end(), 0.0f),
            static_cast<std::ptrdiff_t>(scans[1].size()));
}

TEST(AzimuthTimes, SimulatedScanRoundTripsThroughKittiBin) {
  // A VLP-16 driving through the parking scene; its scans as KITTI .bin (x y z intensity, in
  // firing order) read back with times from the azimuth: each cell's time within a column
  // of the simulator's.
  const mesh::TriangleMesh mesh = build_scene("parking");
  const RayCaster caster(mesh);
  const NamedPath path = scene_path("parking", "drive");
  const auto trajectory = make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
  SimulationSettings settings;
  settings.sensor = config::sensor_preset("vlp16");
  const LidarSimulator simulator(mesh, caster, *trajectory, settings);
  const fs::path dir = test::scratch_dir("azimuth_times_simulated");
  std::vector<Scan> simulated;
  for (uint64_t i = 0; i < 2; ++i) {
    simulated.push_back(simulator.simulate(i).scan);
    write_scan_kitti_bin(simulated.back(), (dir / ("00000" + std::to_string(i) + ".bin")).string());
  }
  SourceOptions options;
  options.sensor_preset = "vlp16";
  const auto source = open_scan_folder(dir.string(), options);
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(source->stats().warning_count, 0u);
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& back = scans[k];
    const Scan& truth = simulated[k];
    ASSERT_EQ(back.valid, truth.valid);
    std::vector<double> known(truth.time_offset_s.begin(), truth.time_offset_s.end());
    EXPECT_LE(largest_cell_error_s(back, known), column_s(settings.sensor));
  }
}

}  // namespace
}  // namespace featsense::slam
