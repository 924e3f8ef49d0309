// sensor_msgs/PointCloud2 decoding: message layout checks, field conversion from every
// datatype, the per-point time rules, row orientation, and the sensor model of clouds.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "rosbag/cloud_sensor_model.hpp"
#include "rosbag/pointcloud2.hpp"
#include "rosbag/pointcloud2_convert.hpp"
#include "slam/rosbag_test_clouds.hpp"

namespace featsense::slam {
namespace {

using test::CloudSpec;
using test::make_reference_cloud;
using test::TestCloud;

/// Parses a serialized test cloud; `bytes` must outlive the view.
PointCloud2View parse(const std::vector<uint8_t>& bytes) {
  return parse_pointcloud2(ByteView{bytes.data(), bytes.size()});
}

Scan to_scan(const TestCloud& cloud, int64_t fallback_stamp_ns = 0) {
  const std::vector<uint8_t> bytes = cloud.serialize();
  const PointCloud2View view = parse(bytes);
  EXPECT_EQ(layout_problem(view), "");
  return organized_cloud_to_scan(view, fallback_stamp_ns);
}

TEST(PointCloud2, ParsesEveryMember) {
  TestCloud cloud = make_reference_cloud({});
  cloud.seq = 77;
  cloud.frame_id = "os_sensor";
  cloud.is_dense = 1;
  const std::vector<uint8_t> bytes = cloud.serialize();
  const PointCloud2View view = parse(bytes);
  EXPECT_EQ(view.seq, 77u);
  EXPECT_EQ(view.stamp_ns, cloud.stamp_ns);
  EXPECT_EQ(view.frame_id, "os_sensor");
  EXPECT_EQ(view.height, cloud.height);
  EXPECT_EQ(view.width, cloud.width);
  ASSERT_EQ(view.fields.size(), cloud.fields.size());
  for (size_t i = 0; i < cloud.fields.size(); ++i) {
    EXPECT_EQ(view.fields[i].name, cloud.fields[i].name);
    EXPECT_EQ(view.fields[i].offset, cloud.fields[i].offset);
    EXPECT_EQ(view.fields[i].datatype, cloud.fields[i].datatype);
    EXPECT_EQ(view.fields[i].count, cloud.fields[i].count);
  }
  EXPECT_FALSE(view.is_bigendian);
  EXPECT_EQ(view.point_step, cloud.point_step);
  EXPECT_EQ(view.row_step, cloud.row_step);
  ASSERT_EQ(view.data.size, cloud.data.size());
  EXPECT_EQ(std::vector<uint8_t>(view.data.data, view.data.data + view.data.size), cloud.data);
  EXPECT_TRUE(view.is_dense);
  EXPECT_EQ(layout_problem(view), "");
}

TEST(PointCloud2, CutShortMessagesThrow) {
  const std::vector<uint8_t> bytes = make_reference_cloud({}).serialize();
  for (size_t size = 0; size < bytes.size(); size += (size < 200 ? 1 : 997)) {
    EXPECT_THROW(parse_pointcloud2(ByteView{bytes.data(), size}), SerializationError) << size;
  }
}

TEST(PointCloud2, LayoutProblemsAreNamed) {
  auto problem_of = [](TestCloud cloud) {
    const std::vector<uint8_t> bytes = cloud.serialize();
    return layout_problem(parse(bytes));
  };
  auto expect_problem = [&](const TestCloud& cloud, const std::string& words) {
    const std::string problem = problem_of(cloud);
    EXPECT_NE(problem.find(words), std::string::npos) << "'" << problem << "' lacks " << words;
  };
  const TestCloud good = make_reference_cloud({});
  EXPECT_EQ(problem_of(good), "");

  TestCloud big_endian = good;
  big_endian.is_bigendian = 1;
  expect_problem(big_endian, "big-endian");

  TestCloud past_step = good;
  past_step.fields[3].offset = past_step.point_step - 1;  // a float32 over the end
  expect_problem(past_step, "field 'intensity' ends at byte");

  TestCloud short_data = good;
  short_data.data.resize(short_data.data.size() - 1);
  expect_problem(short_data, "data holds");

  TestCloud short_rows = good;
  short_rows.row_step -= 1;
  expect_problem(short_rows, "row_step");

  TestCloud no_z = good;
  no_z.fields[2].name = "w";
  expect_problem(no_z, "no 'z' field");

  TestCloud odd_type = good;
  odd_type.fields[4].datatype = 9;
  expect_problem(odd_type, "unknown datatype 9");

  TestCloud empty = good;
  empty.height = 0;
  expect_problem(empty, "empty cloud");

  TestCloud huge = good;
  huge.height = 1u << 20;
  huge.width = 1u << 20;
  expect_problem(huge, "more than the limit");

  // Rows with padding after the points (row_step > width x point_step) are fine.
  TestCloud padded = good;
  const uint32_t old_row_step = padded.row_step;
  padded.row_step += 12;
  std::vector<uint8_t> data(static_cast<size_t>(padded.row_step) * padded.height, 0xEE);
  for (uint32_t row = 0; row < padded.height; ++row) {
    std::copy(good.data.begin() + row * old_row_step, good.data.begin() + (row + 1) * old_row_step,
              data.begin() + row * padded.row_step);
  }
  padded.data = data;
  EXPECT_EQ(problem_of(padded), "");
  test::expect_reference_scan(to_scan(padded), CloudSpec{}, 1e-9);
}

TEST(PointCloud2, OrganizedCloudBecomesTheScan) {
  for (const uint8_t xyz_type : {test::kFloat32, test::kFloat64}) {
    CloudSpec spec;
    spec.xyz_type = xyz_type;
    SCOPED_TRACE("xyz datatype " + std::to_string(xyz_type));
    const Scan scan = to_scan(make_reference_cloud(spec));
    test::expect_reference_scan(scan, spec, 1e-9);
    // Row 0 is stored first and is the highest beam: no flip needed.
    EXPECT_EQ(rows_lowest_first(scan), false);
  }
}

TEST(PointCloud2, EveryDatatypeConvertsToFloat) {
  for (uint8_t type = 1; type <= 8; ++type) {
    SCOPED_TRACE("datatype " + std::to_string(type));
    CloudSpec spec;
    spec.intensity_type = type;
    spec.ring_type = type;
    test::expect_reference_scan(to_scan(make_reference_cloud(spec)), spec, 1e-9);
  }
  // Negative values of the signed types, and wide values of the 32-bit ones.
  TestCloud cloud;
  for (const char* axis : {"x", "y", "z"}) cloud.add_field(axis, test::kFloat32);
  cloud.add_field("reflectivity", test::kInt8);
  cloud.add_field("signal", test::kInt16);
  cloud.add_field("ambient", test::kInt32);
  cloud.add_field("nir", test::kUint32);
  cloud.allocate(4, 8);
  for (size_t i = 0; i < 32; ++i) {
    const double k = static_cast<double>(i);
    cloud.set(i, "x", 1.0 + k);
    cloud.set(i, "reflectivity", -100.0 + k);
    cloud.set(i, "signal", -1000.0 + k);
    cloud.set(i, "ambient", -100000.0 - k);
    cloud.set(i, "nir", 4000000000.0 + k);
  }
  const Scan scan = to_scan(cloud);
  for (size_t i = 0; i < 32; ++i) {
    const auto k = static_cast<float>(i);
    EXPECT_EQ(scan.channel("reflectivity")->values[i], -100.0f + k);
    EXPECT_EQ(scan.channel("signal")->values[i], -1000.0f + k);
    EXPECT_EQ(scan.channel("ambient")->values[i], -100000.0f - k);
    // Beyond 2^24 a float rounds, as any conversion of that integer to float does.
    EXPECT_EQ(scan.channel("nir")->values[i], static_cast<float>(4000000000u + i));
  }
}

TEST(PointCloud2, TimeRules) {
  // Ouster: u32 ns since the stamp.
  CloudSpec ouster;
  ouster.time_field = "t";
  test::expect_reference_scan(to_scan(make_reference_cloud(ouster)), ouster, 1e-9);
  // Velodyne: float32 s relative to the stamp, starting before it: the scan starts at the
  // earliest point, the offsets count from there.
  CloudSpec velodyne;
  velodyne.time_field = "time";
  test::expect_reference_scan(to_scan(make_reference_cloud(velodyne)), velodyne, 1e-6);
  // float64 absolute seconds: double precision of an epoch time is about 0.2 us.
  CloudSpec absolute;
  absolute.time_field = "timestamp";
  test::expect_reference_scan(to_scan(make_reference_cloud(absolute)), absolute, 1e-6);
  // No time field: every offset 0.
  CloudSpec none;
  none.time_field = "";
  test::expect_reference_scan(to_scan(make_reference_cloud(none)), none, 0.0);
}

TEST(PointCloud2, ZeroStampFallsBackToTheReceiveTime) {
  CloudSpec spec;
  spec.stamp_ns = 0;
  const Scan scan = to_scan(make_reference_cloud(spec), 1234567890);
  EXPECT_EQ(scan.stamp_ns, 1234567890);
}

TEST(PointCloud2, RangeFieldIsUsedInItsUnit) {
  for (const uint8_t type : {test::kUint32, test::kFloat32}) {
    SCOPED_TRACE("range datatype " + std::to_string(type));
    TestCloud cloud;
    cloud.add_field("x", test::kFloat32);
    cloud.add_field("y", test::kFloat32);
    cloud.add_field("z", test::kFloat32);
    cloud.add_field("range", type);
    cloud.allocate(2, 2);
    for (size_t i = 0; i < 4; ++i) {
      cloud.set(i, "x", 3.0 + static_cast<double>(i));
      // Ouster's range runs from the lidar origin, not the beam origin: not |xyz|.
      const double range_m = 3.1 + static_cast<double>(i);
      cloud.set(i, "range", type == test::kUint32 ? range_m * 1000.0 : range_m);
    }
    const Scan scan = to_scan(cloud);
    for (size_t i = 0; i < 4; ++i) {
      EXPECT_NEAR(scan.range_m[i], 3.1 + static_cast<double>(i), 1e-6);
    }
  }
}

TEST(PointCloud2, LowestFirstRowsAreDetectedAndFlipped) {
  CloudSpec spec;
  spec.lowest_first = true;
  Scan scan = to_scan(make_reference_cloud(spec));
  ASSERT_EQ(rows_lowest_first(scan), true);
  flip_rows(scan);
  spec.lowest_first = false;  // now the reference layout
  test::expect_reference_scan(scan, spec, 1e-9);

  // One row with points cannot tell.
  Scan single = Scan::allocate(3, 2);
  single.valid[0] = 1;
  single.xyz[0] = {1.0f, 0.0f, 0.5f};
  EXPECT_FALSE(rows_lowest_first(single).has_value());
}

TEST(PointCloud2, UnorganizedCloudBecomesPoints) {
  // The reference scene flattened into one row, rings numbered Velodyne style (0 lowest).
  CloudSpec spec;
  spec.lowest_first = true;
  TestCloud cloud = make_reference_cloud(spec);
  cloud.width *= cloud.height;
  cloud.height = 1;
  cloud.row_step = cloud.width * cloud.point_step;
  const std::vector<uint8_t> bytes = cloud.serialize();
  const PointCloud2View view = parse(bytes);
  ASSERT_EQ(layout_problem(view), "");
  EXPECT_EQ(ring_count(view), test::kRefRows);
  const PointCloud points = cloud_to_points(view, 0);
  ASSERT_EQ(points.size(), static_cast<size_t>(test::kRefRows * test::kRefCols));
  EXPECT_TRUE(points.ring_counts_up);
  EXPECT_EQ(points.stamp_ns, spec.stamp_ns);
  ASSERT_EQ(points.ring.size(), points.size());
  ASSERT_EQ(points.time_offset_s.size(), points.size());
  ASSERT_EQ(points.channels.size(), 1u);
  EXPECT_EQ(points.channels[0].name, "intensity");
  for (int stored_row = 0; stored_row < test::kRefRows; ++stored_row) {
    const int row = test::kRefRows - 1 - stored_row;
    for (int col = 0; col < test::kRefCols; ++col) {
      const size_t i = static_cast<size_t>(stored_row * test::kRefCols + col);
      const test::ReferencePoint p = test::reference_point(row, col);
      EXPECT_EQ(points.ring[i], test::kRefRows - 1 - row);
      EXPECT_EQ(points.channels[0].values[i], static_cast<float>(p.intensity));
      EXPECT_NEAR(points.time_offset_s[i], p.time_s, 1e-9);
      if (p.valid) {
        EXPECT_EQ(points.xyz[i], p.xyz.cast<float>());
      }
    }
  }

  // The same with Ouster-style rings (0 highest).
  TestCloud ouster = make_reference_cloud({});
  ouster.width *= ouster.height;
  ouster.height = 1;
  const std::vector<uint8_t> ouster_bytes = ouster.serialize();
  EXPECT_FALSE(cloud_to_points(parse(ouster_bytes), 0).ring_counts_up);
}

TEST(PointCloud2, HugeAndNonFiniteValuesAreNoPoints) {
  TestCloud cloud;
  cloud.add_field("x", test::kFloat64);
  cloud.add_field("y", test::kFloat64);
  cloud.add_field("z", test::kFloat64);
  cloud.add_field("t", test::kFloat64);
  cloud.allocate(2, 2);
  const double values[] = {1e300, -1e300, std::numeric_limits<double>::infinity(), 2.0};
  for (size_t i = 0; i < 4; ++i) {
    cloud.set(i, "x", values[i]);
    cloud.set(i, "t", values[3 - i] * 1e-9);
  }
  const Scan scan = to_scan(cloud);
  EXPECT_EQ(scan.valid, (std::vector<uint8_t>{0, 0, 0, 1}));
  for (float t : scan.time_offset_s) EXPECT_TRUE(std::isfinite(t));
}

TEST(CloudSensorModel, PresetByRings) {
  EXPECT_EQ(preset_for_rings(16, false), "vlp16");
  EXPECT_EQ(preset_for_rings(32, false), "hdl32");
  EXPECT_EQ(preset_for_rings(64, false), "os1-64");
  EXPECT_EQ(preset_for_rings(128, false), "os1-128");
  EXPECT_EQ(preset_for_rings(40, false), std::nullopt);
  EXPECT_EQ(preset_for_rings(40, true), "os1-64");
  EXPECT_EQ(preset_for_rings(15, true), "vlp16");
  EXPECT_EQ(preset_for_rings(129, true), std::nullopt);
  EXPECT_EQ(preset_for_rings(0, true), std::nullopt);
}

TEST(CloudSensorModel, EstimatedFromTheRows) {
  // Elevations of the reference scene: +15 .. -15 deg in 2 deg steps. Row 5 is left empty
  // and must be interpolated.
  Scan scan = to_scan(make_reference_cloud({}));
  for (int col = 0; col < scan.cols; ++col) scan.invalidate(scan.index(5, col));
  const std::optional<config::SensorModel> model = sensor_model_from_scan(scan);
  ASSERT_TRUE(model.has_value());
  EXPECT_EQ(model->beams, test::kRefRows);
  EXPECT_EQ(model->columns, test::kRefCols);
  ASSERT_EQ(model->elevation_rad.size(), static_cast<size_t>(test::kRefRows));
  for (int row = 0; row < test::kRefRows; ++row) {
    EXPECT_NEAR(model->elevation_rad[static_cast<size_t>(row)], (15.0 - 2.0 * row) * M_PI / 180.0,
                1e-6);
  }
  EXPECT_NO_THROW(model->validate());

  Scan empty = Scan::allocate(4, 4);
  EXPECT_FALSE(sensor_model_from_scan(empty).has_value());
}

}  // namespace
}  // namespace featsense::slam
