#pragma once
// The reference scene of the PointCloud2 tests: an organized cloud whose every value is a
// known function of its row and column, so a test can tell what the reader must return.

#include <gtest/gtest.h>
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "featsense/slam/scan.hpp"
#include "slam/rosbag_test_writer.hpp"

namespace featsense::test {

/// A point of the reference scene: beams from +15 deg (row 0) down to -15 deg in 2 deg
/// steps, 64 columns turning clockwise from +x, range growing with row and column. Cell
/// (3, 5) is NaN and cell (7, 9) is all zero: no returns.
struct ReferencePoint {
  Eigen::Vector3d xyz;
  bool valid = true;
  double intensity = 0.0;  ///< small integers, exact in every datatype
  int ring = 0;            ///< Ouster style: ring 0 is the highest beam
  double time_s = 0.0;     ///< after the first column
};

constexpr int kRefRows = 16;
constexpr int kRefCols = 64;

inline ReferencePoint reference_point(int row, int col, int rows = kRefRows, int cols = kRefCols) {
  ReferencePoint p;
  const double elevation = (15.0 - 30.0 * row / (rows - 1)) * M_PI / 180.0;
  const double azimuth = -2.0 * M_PI * col / cols;
  const double range = 5.0 + 0.25 * row + 0.01 * col;
  p.xyz = range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                  std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  if (row == 3 && col == 5) {
    p.xyz.setConstant(std::numeric_limits<double>::quiet_NaN());
    p.valid = false;
  }
  if (row == 7 && col == 9) {
    p.xyz.setZero();
    p.valid = false;
  }
  p.intensity = (row * 7 + col) % 100;
  p.ring = row;
  p.time_s = col * 1e-4;
  return p;
}

/// How a reference cloud is laid out and typed.
struct CloudSpec {
  uint8_t xyz_type = kFloat32;
  uint8_t intensity_type = kFloat32;
  uint8_t ring_type = kUint16;
  /// "t" (u32 ns), "time" (float32 s, starting 10 ms before the stamp, as Velodyne's may)
  /// or "timestamp" (float64 absolute seconds); "" for none.
  std::string time_field = "t";
  bool lowest_first = false;  ///< rows stored from the lowest beam up
  int64_t stamp_ns = 1700000000123456789;
  int rows = kRefRows;
  int cols = kRefCols;
};

/// Where `time` starts relative to the stamp in the Velodyne-style layout, seconds.
constexpr double kVelodyneTimeStartS = -0.01;

inline TestCloud make_reference_cloud(const CloudSpec& spec) {
  TestCloud cloud;
  cloud.stamp_ns = spec.stamp_ns;
  cloud.add_field("x", spec.xyz_type);
  cloud.add_field("y", spec.xyz_type);
  cloud.add_field("z", spec.xyz_type);
  cloud.add_field("intensity", spec.intensity_type);
  cloud.add_field("ring", spec.ring_type);
  if (spec.time_field == "t") cloud.add_field("t", kUint32);
  if (spec.time_field == "time") cloud.add_field("time", kFloat32);
  if (spec.time_field == "timestamp") cloud.add_field("timestamp", kFloat64);
  cloud.allocate(static_cast<uint32_t>(spec.rows), static_cast<uint32_t>(spec.cols));
  const double stamp_s = static_cast<double>(spec.stamp_ns) * 1e-9;
  for (int stored_row = 0; stored_row < spec.rows; ++stored_row) {
    const int row = spec.lowest_first ? spec.rows - 1 - stored_row : stored_row;
    for (int col = 0; col < spec.cols; ++col) {
      const ReferencePoint p = reference_point(row, col, spec.rows, spec.cols);
      const size_t i = static_cast<size_t>(stored_row) * spec.cols + col;
      cloud.set(i, "x", p.xyz.x());
      cloud.set(i, "y", p.xyz.y());
      cloud.set(i, "z", p.xyz.z());
      cloud.set(i, "intensity", p.intensity);
      cloud.set(i, "ring", spec.lowest_first ? spec.rows - 1 - p.ring : p.ring);
      if (spec.time_field == "t") cloud.set(i, "t", std::round(p.time_s * 1e9));
      if (spec.time_field == "time") cloud.set(i, "time", kVelodyneTimeStartS + p.time_s);
      if (spec.time_field == "timestamp") cloud.set(i, "timestamp", stamp_s + p.time_s);
    }
  }
  return cloud;
}

/// The stamp a reader must give a reference cloud: Velodyne-style times start before the
/// header stamp, so the scan starts at the earliest point.
inline int64_t expected_stamp_ns(const CloudSpec& spec) {
  return spec.time_field == "time"
             ? spec.stamp_ns + static_cast<int64_t>(std::llround(kVelodyneTimeStartS * 1e9))
             : spec.stamp_ns;
}

/// Checks a scan against the reference scene: geometry to the precision of the xyz
/// datatype, validity, intensity exactly, time offsets to `time_tolerance_s`.
inline void expect_reference_scan(const slam::Scan& scan, const CloudSpec& spec,
                                  double time_tolerance_s) {
  ASSERT_EQ(scan.rows, spec.rows);
  ASSERT_EQ(scan.cols, spec.cols);
  EXPECT_EQ(scan.stamp_ns, expected_stamp_ns(spec));
  const slam::ScanChannel* intensity = scan.channel("intensity");
  ASSERT_NE(intensity, nullptr);
  for (int row = 0; row < spec.rows; ++row) {
    for (int col = 0; col < spec.cols; ++col) {
      const ReferencePoint p = reference_point(row, col, spec.rows, spec.cols);
      const size_t i = scan.index(row, col);
      ASSERT_EQ(scan.valid[i], p.valid ? 1 : 0) << "row " << row << " col " << col;
      EXPECT_EQ(intensity->values[i], static_cast<float>(p.intensity));
      if (spec.time_field.empty()) {
        EXPECT_EQ(scan.time_offset_s[i], 0.0f);
      } else {
        EXPECT_NEAR(scan.time_offset_s[i], p.time_s, time_tolerance_s);
      }
      if (!p.valid) {
        EXPECT_EQ(scan.xyz[i], Eigen::Vector3f::Zero());
        EXPECT_EQ(scan.range_m[i], 0.0f);
        continue;
      }
      // float32 storage rounds to half an ulp; float64 storage is converted once to float.
      const Eigen::Vector3f expected = p.xyz.cast<float>();
      EXPECT_EQ(scan.xyz[i], expected) << "row " << row << " col " << col;
      EXPECT_NEAR(scan.range_m[i], p.xyz.norm(), 1e-5);
    }
  }
}

}  // namespace featsense::test
