// The scan writers of `featsense convert`: PCD and PLY read back by this project's readers
// as the same scan, KITTI .bin checked byte by byte.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "common/file_bytes.hpp"
#include "common/test_data.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/io/scan_writers.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

/// A VLP-16-shaped scan: every third cell a return at the cell's beam and column centre,
/// with time, range and two channels that tell the cell.
Scan test_scan() {
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  Scan scan = Scan::allocate(vlp16.beams, vlp16.columns);
  scan.stamp_ns = 1673400472138016708;
  // Looked up by name below: a second add_channel() may move the first.
  scan.add_channel("intensity");
  scan.add_channel("reflectivity");
  std::mt19937 random(2);
  std::uniform_real_distribution<double> range(1.0, 60.0);
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      const size_t i = scan.index(r, c);
      scan.time_offset_s[i] = static_cast<float>(c) * 5.5e-5f;
      scan.channel("intensity")->values[i] = static_cast<float>((r * 7 + c) % 256);
      if ((r + c) % 3 != 0) continue;
      const double e = vlp16.elevation_rad[static_cast<size_t>(r)], a = -2 * M_PI * c / scan.cols,
                   d = range(random);
      scan.xyz[i] = Eigen::Vector3d(d * std::cos(e) * std::cos(a), d * std::cos(e) * std::sin(a),
                                    d * std::sin(e))
                        .cast<float>();
      scan.range_m[i] = static_cast<float>(d + 0.01);  // the sensor's own range, not |xyz|
      scan.valid[i] = 1;
      scan.channel("reflectivity")->values[i] = static_cast<float>(c % 100);
    }
  }
  return scan;
}

TEST(ScanWriters, PcdRoundTripGivesTheSameScan) {
  const Scan scan = test_scan();
  const fs::path file = test::scratch_dir("scan_writers_pcd") / "scan.pcd";
  write_scan_pcd(scan, file.string());

  const std::string bytes = test::file_bytes(file);
  EXPECT_NE(bytes.find("FIELDS x y z range t ring intensity reflectivity\n"), std::string::npos);
  EXPECT_NE(bytes.find("WIDTH 1800\nHEIGHT 16\n"), std::string::npos);
  EXPECT_NE(bytes.find("DATA binary\n"), std::string::npos);

  const auto source = open_pcd_file(file.string(), {});
  EXPECT_EQ(source->info().sensor.name, "vlp16");  // 16 rows
  const std::optional<Scan> back = source->next();
  ASSERT_TRUE(back);
  EXPECT_EQ(back->rows, scan.rows);
  EXPECT_EQ(back->cols, scan.cols);
  EXPECT_EQ(back->stamp_ns, scan.stamp_ns);
  EXPECT_EQ(back->valid, scan.valid);
  EXPECT_EQ(back->xyz, scan.xyz);
  EXPECT_EQ(back->range_m, scan.range_m);
  EXPECT_EQ(back->time_offset_s, scan.time_offset_s);
  ASSERT_EQ(back->channels.size(), 2u);
  for (const ScanChannel& c : scan.channels) {
    ASSERT_NE(back->channel(c.name), nullptr) << c.name;
    EXPECT_EQ(back->channel(c.name)->values, c.values) << c.name;
  }
}

TEST(ScanWriters, PlyRoundTripGivesTheValidPoints) {
  const Scan scan = test_scan();
  const fs::path file = test::scratch_dir("scan_writers_ply") / "scan.ply";
  write_scan_ply(scan, file.string());
  const DecodedCloud decoded = decode_ply(test::file_bytes(file), file.string());
  EXPECT_EQ(decoded.cloud.size(), scan.valid_count());
  EXPECT_FALSE(decoded.cloud.ring_counts_up);  // ring = row, row 0 highest

  const auto source = open_ply_file(file.string(), {});
  EXPECT_EQ(source->info().sensor.name, "vlp16");  // rings up to 15
  const std::optional<Scan> back = source->next();
  ASSERT_TRUE(back);
  EXPECT_EQ(back->stamp_ns, scan.stamp_ns);
  // Points lie on column centres, so organize() puts each back into its cell.
  EXPECT_EQ(back->valid, scan.valid);
  for (size_t i = 0; i < scan.size(); ++i) {
    if (!scan.valid[i]) continue;
    EXPECT_EQ(back->xyz[i], scan.xyz[i]);
    EXPECT_EQ(back->range_m[i], scan.range_m[i]);
    EXPECT_EQ(back->time_offset_s[i], scan.time_offset_s[i]);
    for (const ScanChannel& c : scan.channels)
      EXPECT_EQ(back->channel(c.name)->values[i], c.values[i]);
  }
}

TEST(ScanWriters, KittiBinHoldsValidPointsWithNormalisedIntensity) {
  Scan scan = test_scan();
  const fs::path file = test::scratch_dir("scan_writers_bin") / "000000.bin";
  write_scan_kitti_bin(scan, file.string());
  const std::string bytes = test::file_bytes(file);
  ASSERT_EQ(bytes.size(), scan.valid_count() * 16);
  // Scan::intensity() prefers reflectivity; its largest value among valid cells is 99.
  const ScanChannel& reflectivity = *scan.channel("reflectivity");
  float largest = 0;
  for (size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i]) largest = std::max(largest, reflectivity.values[i]);
  }
  ASSERT_EQ(largest, 99.0f);
  // In firing order: column by column from the first measured (0 here), each from the
  // highest beam down.
  size_t k = 0;
  for (int c = 0; c < scan.cols; ++c) {
    for (int r = 0; r < scan.rows; ++r) {
      const size_t i = scan.index(r, c);
      if (!scan.valid[i]) continue;
      float point[4];
      std::memcpy(point, bytes.data() + 16 * k++, 16);
      EXPECT_EQ(Eigen::Vector3f(point[0], point[1], point[2]), scan.xyz[i]);
      EXPECT_FLOAT_EQ(point[3], reflectivity.values[i] / largest);
    }
  }
  // A sweep that began mid-scan (KITTI's, behind the sensor) starts the file there.
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      scan.time_offset_s[scan.index(r, c)] = static_cast<float>((c + 900) % scan.cols) * 5.5e-5f;
    }
  }
  write_scan_kitti_bin(scan, file.string());
  const std::string from_behind = test::file_bytes(file);
  const size_t first = scan.index(0, 900);  // (0 + 900) % 3 == 0: a return
  ASSERT_TRUE(scan.valid[first]);
  float point[4];
  std::memcpy(point, from_behind.data(), 16);
  EXPECT_EQ(Eigen::Vector3f(point[0], point[1], point[2]), scan.xyz[first]);
  // No intensity channel at all: zeros.
  scan.channels.clear();
  write_scan_kitti_bin(scan, file.string());
  const std::string plain = test::file_bytes(file);
  float intensity = 1;
  std::memcpy(&intensity, plain.data() + 12, 4);
  EXPECT_EQ(intensity, 0.0f);
}

TEST(ScanWriters, UnwritablePathThrowsWriteErrorNamingIt) {
  const Scan scan = test_scan();
  const std::string path =
      (test::scratch_dir("scan_writers_error") / "no" / "such" / "folder" / "scan").string();
  for (auto write : {write_scan_pcd, write_scan_ply, write_scan_kitti_bin}) {
    try {
      write(scan, path);
      FAIL() << "wrote into a missing folder";
    } catch (const WriteError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace featsense::slam
