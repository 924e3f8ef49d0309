// The Ouster pcap reader on the real recordings of ../shared/data/ouster, checked against the
// sensor's own metadata and the maker's pose estimates, never against the decoder's formulas.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iostream>
#include <unordered_map>

#include "common/test_data.hpp"
#include "featsense/slam/io/readers.hpp"
#include "pcap_test_util.hpp"

namespace featsense::slam {
namespace {

constexpr const char* kOs1Pcap = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";
constexpr const char* kOs1Json = "ouster/OS-1-128_v2.3.0_1024x10.json";
constexpr const char* kOs1Poses = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt";
constexpr const char* kOs0Pcap = "ouster/OS-0-128-U1_v2.3.0_1024x10.pcap";

std::vector<Scan> read_all(const std::string& path, SourceOptions options = {}) {
  std::unique_ptr<ScanSource> source = open_ouster_pcap(path, options);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  return scans;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

/// What the tests need of the metadata, read straight from the JSON (flat layout).
struct Calibration {
  std::vector<double> altitude_deg;
  std::vector<int> shift;
  double n_m = 0.0;
  Eigen::Isometry3d lidar_to_sensor = Eigen::Isometry3d::Identity();
  int columns = 0;
};

Calibration calibration(const std::filesystem::path& json_path) {
  const nlohmann::json doc = nlohmann::json::parse(test::read_file(json_path));
  Calibration c;
  c.altitude_deg = doc["beam_altitude_angles"].get<std::vector<double>>();
  c.shift = doc["data_format"]["pixel_shift_by_row"].get<std::vector<int>>();
  c.columns = doc["data_format"]["columns_per_frame"].get<int>();
  c.n_m = doc["lidar_origin_to_beam_origin_mm"].get<double>() / 1000.0;
  const auto m = doc["lidar_to_sensor_transform"].get<std::vector<double>>();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k)
      c.lidar_to_sensor.linear()(r, k) = m[static_cast<size_t>(4 * r + k)];
    c.lidar_to_sensor.translation()[r] = m[static_cast<size_t>(4 * r + 3)] / 1000.0;
  }
  return c;
}

/// The vector from the beam origin to the point (lidar frame) of a scan cell: the sensor
/// frame undone, then the beam origin (n along the encoder angle of the cell's measurement)
/// subtracted. Its length is r - n, its direction the beam's.
Eigen::Vector3d beam_vector(const Calibration& c, const Scan& scan, int row, int col) {
  const Eigen::Vector3d p_sensor = scan.xyz[scan.index(row, col)].cast<double>();
  const Eigen::Vector3d p_lidar = c.lidar_to_sensor.inverse() * p_sensor;
  const int m = ((col - c.shift[static_cast<size_t>(row)]) % c.columns + c.columns) % c.columns;
  const double encoder = 2.0 * M_PI * (1.0 - static_cast<double>(m) / c.columns);
  return p_lidar - c.n_m * Eigen::Vector3d(std::cos(encoder), std::sin(encoder), 0.0);
}

TEST(OusterPcap, Os1GivesThreeFullFrames) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), {});
  EXPECT_EQ(source->info().format, "ouster-pcap");
  EXPECT_TRUE(source->info().sensor_from_metadata);
  EXPECT_EQ(source->info().sensor.beams, 128);
  EXPECT_EQ(source->info().detail, "OS-1-128 1024x10 RNG15_RFL8_NIR8");
  const std::vector<std::string> fields = {"x", "y", "z", "range", "t", "reflectivity", "nir"};
  EXPECT_EQ(source->info().fields, fields);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(source->stats().frames_read, 3u);
  EXPECT_EQ(source->stats().warning_count, 0u) << source->stats().warnings.front();
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& scan = scans[k];
    EXPECT_EQ(scan.rows, 128);
    EXPECT_EQ(scan.cols, 1024);
    EXPECT_EQ(scan.sequence, k);
    // data/README.md: "about 107k valid returns per frame"; measured 107,647, 107,357 and
    // 107,532 (of 131,072 cells).
    EXPECT_GT(scan.valid_count(), 107200u);
    EXPECT_LT(scan.valid_count(), 107800u);
    std::cout << "frame " << k << ": " << scan.valid_count() << " valid, stamp " << scan.stamp_ns
              << "\n";
    ASSERT_NE(scan.channel("reflectivity"), nullptr);
    ASSERT_NE(scan.channel("nir"), nullptr);
    EXPECT_EQ(scan.channel("signal"), nullptr);  // RNG15_RFL8_NIR8 has none
    if (k > 0) {
      // One revolution at 10 Hz apart.
      EXPECT_NEAR(static_cast<double>(scan.stamp_ns - scans[k - 1].stamp_ns) * 1e-9, 0.1, 0.002);
    }
  }
}

TEST(OusterPcap, Os1PacketsCarryIncreasingFrameIds) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  // The frame id is bytes 2..3 of the 32-byte packet header (PACKET_FORMAT.md); data/README.md says
  // the capture holds frames 1795 to 1797.
  std::vector<int> ids;
  for (const test::CapturedFrame& frame : test::read_pcap_frames(test::read_file(pcap))) {
    if (frame.bytes.size() != 14 + 20 + 8 + 8448) continue;
    const int id = frame.bytes[42 + 2] | (frame.bytes[42 + 3] << 8);
    if (ids.empty() || ids.back() != id) ids.push_back(id);
  }
  EXPECT_EQ(ids, (std::vector<int>{1795, 1796, 1797}));
}

TEST(OusterPcap, Os1TimeOffsetsSpanOneRevolution) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const Calibration c = calibration(json);
  const std::vector<Scan> scans = read_all(pcap.string());
  ASSERT_FALSE(scans.empty());
  const Scan& scan = scans[0];
  // Every offset lies within one revolution (0.1 s at 10 Hz), and follows the measurement
  // order: the column measured m-th of 1024 fires about m / 1024 of a revolution after the
  // first (destaggering moves it to another image column, so undo the shift to find m).
  std::vector<double> lateness;
  float earliest = 1.0f;
  float latest = 0.0f;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const float t = scan.time_offset_s[scan.index(row, col)];
      ASSERT_GE(t, 0.0f);
      ASSERT_LE(t, 0.1f);
      earliest = std::min(earliest, t);
      latest = std::max(latest, t);
      const int m = ((col - c.shift[static_cast<size_t>(row)]) % c.columns + c.columns) % c.columns;
      lateness.push_back(std::abs(static_cast<double>(t) - 0.1 * m / c.columns));
    }
  }
  EXPECT_EQ(earliest, 0.0f);
  EXPECT_GT(latest, 0.099f);
  EXPECT_LT(median(lateness), 0.5e-3);
  // On average over the rows, later image columns are later in time (ignoring the first
  // columns, where the destaggering shift wraps rows around from the end of the revolution).
  const auto column_mean = [&](int col) {
    double sum = 0.0;
    for (int row = 0; row < scan.rows; ++row) {
      sum += static_cast<double>(scan.time_offset_s[scan.index(row, col)]);
    }
    return sum / scan.rows;
  };
  int increasing = 0;
  for (int col = 65; col < scan.cols; ++col) increasing += column_mean(col) > column_mean(col - 1);
  EXPECT_GT(increasing, (scan.cols - 65) * 9 / 10);
}

TEST(OusterPcap, Os1RangeRecomputedFromXyzMatchesRangeChannel) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const Calibration c = calibration(json);
  const std::vector<Scan> scans = read_all(pcap.string());
  ASSERT_FALSE(scans.empty());
  const Scan& scan = scans[0];
  double worst_mm = 0.0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      const double range = beam_vector(c, scan, row, col).norm() + c.n_m;
      worst_mm =
          std::max(worst_mm, std::abs(range - static_cast<double>(scan.range_m[i])) * 1000.0);
    }
  }
  std::cout << "largest range disagreement " << worst_mm << " mm\n";
  EXPECT_LT(worst_mm, 1.0);
}

TEST(OusterPcap, Os1BeamElevationsMatchMetadata) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const Calibration c = calibration(json);
  const std::vector<Scan> scans = read_all(pcap.string());
  ASSERT_FALSE(scans.empty());
  const Scan& scan = scans[0];
  double worst_deg = 0.0;
  for (int row = 0; row < scan.rows; ++row) {
    std::vector<double> elevations;
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid[scan.index(row, col)]) continue;
      const Eigen::Vector3d v = beam_vector(c, scan, row, col);
      elevations.push_back(std::asin(v.z() / v.norm()) * 180.0 / M_PI);
    }
    ASSERT_GT(elevations.size(), 100u) << "row " << row;
    worst_deg = std::max(worst_deg,
                         std::abs(median(elevations) - c.altitude_deg[static_cast<size_t>(row)]));
  }
  std::cout << "largest elevation disagreement " << worst_deg << " deg\n";
  EXPECT_LT(worst_deg, 0.05);
}

TEST(OusterPcap, Os1DestaggeredColumnsLookOneWay) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  const std::vector<Scan> scans = read_all(pcap.string());
  ASSERT_FALSE(scans.empty());
  const Scan& scan = scans[0];
  // In a destaggered image every beam of a column looks the same way, whatever its azimuth
  // offset: the azimuths (atan2 of xyz) of one column agree to well within one column
  // (0.35 deg); left staggered they would spread over the 24 columns of pixel_shift_by_row.
  constexpr double kColumnDeg = 360.0 / 1024;
  std::vector<double> deviations_deg;
  for (int col = 0; col < scan.cols; ++col) {
    std::vector<double> azimuths;
    for (int row = 0; row < scan.rows; ++row) {
      const size_t i = scan.index(row, col);
      if (scan.valid[i] && scan.range_m[i] > 2.0f) {
        azimuths.push_back(static_cast<double>(std::atan2(scan.xyz[i].y(), scan.xyz[i].x())) *
                           180.0 / M_PI);
      }
    }
    if (azimuths.size() < 10) continue;
    const double center = median(azimuths);
    for (double a : azimuths) {
      deviations_deg.push_back(std::abs(std::remainder(a - center, 360.0)));
    }
  }
  ASSERT_GT(deviations_deg.size(), 50000u);
  const double typical = median(deviations_deg);
  std::cout << "median azimuth spread within a column " << typical << " deg\n";
  EXPECT_LT(typical, 0.25 * kColumnDeg);
}

/// KITTI pose lines: row-major 3x4.
std::vector<Eigen::Isometry3d> read_kitti_poses(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::vector<Eigen::Isometry3d> poses;
  std::string line;
  while (std::getline(file, line)) {
    std::istringstream in(line);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 4; ++k) in >> pose.matrix()(r, k);
    }
    if (in) poses.push_back(pose);
  }
  return poses;
}

/// Nearest-neighbour distances from (a subsample of) `moving` to `fixed` through a voxel hash;
/// distances beyond one cell are capped at the cell size (they only matter for the median).
double median_nearest_distance(const Scan& fixed, const Scan& moving,
                               const Eigen::Isometry3d& transform) {
  constexpr double kCell = 0.5;
  const auto key_of = [](const Eigen::Vector3d& p) {
    const auto q = [](double v) { return static_cast<int64_t>(std::floor(v / kCell)) & 0x1FFFFF; };
    return (q(p.x()) << 42) | (q(p.y()) << 21) | q(p.z());
  };
  std::unordered_map<int64_t, std::vector<Eigen::Vector3d>> grid;
  for (size_t i = 0; i < fixed.size(); ++i) {
    if (fixed.valid[i])
      grid[key_of(fixed.xyz[i].cast<double>())].push_back(fixed.xyz[i].cast<double>());
  }
  std::vector<double> distances;
  for (size_t i = 0; i < moving.size(); i += 7) {
    if (!moving.valid[i]) continue;
    const Eigen::Vector3d p = transform * moving.xyz[i].cast<double>();
    double best = kCell;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key_of(p + kCell * Eigen::Vector3d(dx, dy, dz)));
          if (it == grid.end()) continue;
          for (const Eigen::Vector3d& q : it->second) best = std::min(best, (q - p).norm());
        }
      }
    }
    distances.push_back(best);
  }
  return median(distances);
}

TEST(OusterPcap, Os1ReferencePosesAlignFrameOneOntoFrameZero) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(poses_path, kOs1Poses);
  const std::vector<Scan> scans = read_all(pcap.string());
  const std::vector<Eigen::Isometry3d> poses = read_kitti_poses(poses_path);
  ASSERT_EQ(scans.size(), 3u);
  ASSERT_EQ(poses.size(), 3u);
  const Eigen::Isometry3d T_0_1 = poses[0].inverse() * poses[1];
  const double identity =
      median_nearest_distance(scans[0], scans[1], Eigen::Isometry3d::Identity());
  const double forward = median_nearest_distance(scans[0], scans[1], T_0_1);
  const double inverse = median_nearest_distance(scans[0], scans[1], T_0_1.inverse());
  std::cout << "median NN distance frame 1 -> 0: identity " << identity << " m, pose " << forward
            << " m, inverse pose " << inverse << " m\n";
  // The pose maps frame 1 into frame 0's coordinates: it brings the clouds together, its
  // inverse pushes them further apart.
  EXPECT_LT(forward, 0.8 * identity);
  EXPECT_LT(forward, inverse);
}

TEST(OusterPcap, Os0GivesOneFrame) {
  FEATSENSE_SHARED_FILE(pcap, kOs0Pcap);
  std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), {});
  EXPECT_EQ(source->info().sensor.max_range_m, 100.0);
  // data/README.md says 90 degrees of vertical field of view (the data sheet's figure); this
  // unit's metadata spans 45.75 to -46.26 degrees, 92.01.
  EXPECT_NEAR(source->info().sensor.vertical_fov_rad() * 180.0 / M_PI, 90.0, 2.5);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  ASSERT_EQ(scans.size(), 1u);
  std::cout << "OS0 frame: " << scans[0].valid_count() << " valid\n";
  EXPECT_EQ(scans[0].rows, 128);
  EXPECT_EQ(scans[0].cols, 1024);
  // A full revolution of 131,072 cells: most return something, some see the sky.
  EXPECT_GT(scans[0].valid_count(), 60000u);
  EXPECT_LT(scans[0].valid_count(), 131072u);
}

TEST(OusterPcap, Os1ReadingSpeed) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  // Reported, not asserted: timings depend on the machine. Opening (metadata, per-pixel
  // tables) is timed apart from decoding, as a 3-frame file would otherwise be mostly opening.
  // CPU time is reported beside wall time because it does not count waiting for a busy CPU.
  constexpr int kRepeats = 10;
  using Clock = std::chrono::steady_clock;
  double open_s = 0.0;
  double decode_s = 0.0;
  double decode_cpu_s = 0.0;
  size_t frames = 0;
  for (int k = 0; k < kRepeats; ++k) {
    const Clock::time_point start = Clock::now();
    std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), {});
    const Clock::time_point opened = Clock::now();
    const std::clock_t cpu_start = std::clock();
    while (source->next()) ++frames;
    decode_cpu_s += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    decode_s += std::chrono::duration<double>(Clock::now() - opened).count();
    open_s += std::chrono::duration<double>(opened - start).count();
  }
  std::cout << "OS1-128 pcap: " << frames / decode_s << " frames/s decoding ("
            << frames / decode_cpu_s << " per CPU second), " << frames / (open_s + decode_s)
            << " frames/s with opening (open " << 1000.0 * open_s / kRepeats << " ms each)\n";
  EXPECT_EQ(frames, 3u * kRepeats);
}

}  // namespace
}  // namespace featsense::slam
