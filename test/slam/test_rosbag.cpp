// The ROS bag source with PointCloud2 topics: bags written by the test writer read back
// through the source, topic choice and its errors, damaged bags, and reading speed.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rosbag/bag_imu_topic.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "rosbag/imu_message.hpp"
#include "rosbag/rosbag_source.hpp"
#include "slam/ros2_test_writers.hpp"
#include "slam/rosbag_test_clouds.hpp"
#include "slam/rosbag_test_source.hpp"
#include "slam/rosbag_test_writer.hpp"

namespace featsense::slam {
namespace {

using test::CloudSpec;
using test::TestBagWriter;
using test::TestCompression;

constexpr int64_t kFirstStamp = 1700000000123456789;
constexpr int64_t kFramePeriodNs = 100000000;

CloudSpec frame_spec(CloudSpec spec, int frame) {
  spec.stamp_ns = kFirstStamp + frame * kFramePeriodNs;
  return spec;
}

/// A bag of `frames` reference clouds on /points, with some other traffic beside them.
std::vector<uint8_t> cloud_bag(TestCompression compression, const CloudSpec& spec, int frames,
                               bool with_index = true, size_t chunk_bytes = 30000) {
  TestBagWriter writer(compression, chunk_bytes);
  const uint32_t points = writer.add_connection("/points", "sensor_msgs/PointCloud2");
  const uint32_t note = writer.add_connection("/note", "std_msgs/String");
  for (int frame = 0; frame < frames; ++frame) {
    const CloudSpec s = frame_spec(spec, frame);
    writer.add_message(points, s.stamp_ns + 5000000, test::make_reference_cloud(s).serialize());
    writer.add_message(note, s.stamp_ns + 6000000, test::serialize_string_message("frame"));
  }
  return writer.finish(with_index);
}

std::unique_ptr<ScanSource> open_bag(const std::string& path, const SourceOptions& options = {}) {
  static test::StandInLog log;
  return open_rosbag_source(path, options, test::stand_in_dependencies(log));
}

std::string error_of(const std::string& path, const SourceOptions& options = {}) {
  try {
    open_bag(path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Rosbag, ReadsOrganizedCloudsOfEveryCompression) {
  const auto dir = test::scratch_dir("rosbag_every_compression");
  for (const TestCompression compression :
       {TestCompression::kNone, TestCompression::kBz2, TestCompression::kLz4}) {
    for (const uint8_t xyz_type : {test::kFloat32, test::kFloat64}) {
      for (const bool with_index : {true, false}) {
        const std::string name = std::string(test::compression_name(compression)) + "_" +
                                 std::to_string(xyz_type) + (with_index ? "" : "_unindexed");
        SCOPED_TRACE(name);
        CloudSpec spec;
        spec.xyz_type = xyz_type;
        spec.intensity_type = test::kUint16;
        spec.ring_type = test::kUint16;
        const int frames = 5;
        const std::string path = test::write_bag_file(
            dir, name + ".bag", cloud_bag(compression, spec, frames, with_index));
        const std::unique_ptr<ScanSource> source = open_bag(path);
        const SourceInfo& info = source->info();
        EXPECT_EQ(info.format, "rosbag");
        EXPECT_EQ(info.path, path);
        EXPECT_EQ(info.frames, static_cast<size_t>(frames));
        EXPECT_EQ(info.fields, (std::vector<std::string>{"x", "y", "z", "intensity", "ring", "t"}));
        // 16 rows: the 16-beam preset, with the cloud's columns.
        EXPECT_EQ(info.sensor.name, "vlp16");
        EXPECT_EQ(info.sensor.columns, test::kRefCols);
        EXPECT_FALSE(info.sensor_from_metadata);
        EXPECT_TRUE(contains(info.detail, "topic /points (sensor_msgs/PointCloud2)"))
            << info.detail;
        EXPECT_TRUE(contains(info.detail, test::compression_name(compression))) << info.detail;
        EXPECT_EQ(contains(info.detail, "no usable index"), !with_index) << info.detail;

        const std::vector<Scan> scans = test::read_scans(*source);
        ASSERT_EQ(scans.size(), static_cast<size_t>(frames));
        for (int frame = 0; frame < frames; ++frame) {
          SCOPED_TRACE("frame " + std::to_string(frame));
          test::expect_reference_scan(scans[static_cast<size_t>(frame)], frame_spec(spec, frame),
                                      1e-9);
          EXPECT_EQ(scans[static_cast<size_t>(frame)].sequence, static_cast<uint64_t>(frame));
        }
        EXPECT_EQ(source->stats().frames_read, static_cast<size_t>(frames));
        EXPECT_EQ(source->stats().warning_count, 0u);
        EXPECT_FALSE(source->next().has_value());  // stays at the end
      }
    }
  }
}

TEST(Rosbag, VelodyneStyleCloudsComeOutHighestRowFirst) {
  const auto dir = test::scratch_dir("rosbag_velodyne_style");
  CloudSpec spec;
  spec.lowest_first = true;
  spec.time_field = "time";
  spec.intensity_type = test::kUint8;
  const std::string path =
      test::write_bag_file(dir, "v.bag", cloud_bag(TestCompression::kLz4, spec, 3));
  const std::unique_ptr<ScanSource> source = open_bag(path);
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 3u);
  CloudSpec expected = spec;
  expected.lowest_first = false;
  for (int frame = 0; frame < 3; ++frame) {
    test::expect_reference_scan(scans[static_cast<size_t>(frame)], frame_spec(expected, frame),
                                1e-6);
  }
}

TEST(Rosbag, UnusualRowCountGetsAnEstimatedSensor) {
  const auto dir = test::scratch_dir("rosbag_estimated_sensor");
  CloudSpec spec;
  spec.rows = 40;
  const std::string path =
      test::write_bag_file(dir, "40.bag", cloud_bag(TestCompression::kNone, spec, 2));
  const std::unique_ptr<ScanSource> source = open_bag(path);
  EXPECT_EQ(source->info().sensor.beams, 40);
  EXPECT_EQ(source->info().sensor.columns, test::kRefCols);
  EXPECT_TRUE(contains(source->info().sensor.name, "estimated")) << source->info().sensor.name;
  EXPECT_NEAR(source->info().sensor.vertical_fov_rad(), 30.0 * M_PI / 180.0, 1e-6);
  EXPECT_EQ(test::read_scans(*source).size(), 2u);

  // An explicit preset wins.
  SourceOptions options;
  options.sensor_preset = "os1-64";
  EXPECT_EQ(open_bag(path, options)->info().sensor.name, "os1-64");
}

/// The reference cloud of `spec` flattened into one row: an unorganized cloud with rings.
test::TestCloud flattened_reference_cloud(const CloudSpec& spec) {
  test::TestCloud cloud = test::make_reference_cloud(spec);
  cloud.width *= cloud.height;
  cloud.height = 1;
  cloud.row_step = cloud.width * cloud.point_step;
  return cloud;
}

/// A bag file of `messages` copies of `cloud` on `topic`, one frame period apart.
std::string one_cloud_bag(const std::filesystem::path& dir, const std::string& name,
                          const test::TestCloud& cloud, int messages,
                          const std::string& topic = "/points",
                          TestCompression compression = TestCompression::kNone) {
  TestBagWriter writer(compression);
  const uint32_t points = writer.add_connection(topic, "sensor_msgs/PointCloud2");
  for (int k = 0; k < messages; ++k) {
    writer.add_message(points, kFirstStamp + k * kFramePeriodNs, cloud.serialize());
  }
  return test::write_bag_file(dir, name, writer.finish());
}

/// One ring-less unorganized cloud of 64 beams from -24.8 to +2 deg (an HDL-64E's span), 360
/// columns, 10 m away: a bag of two such messages on /points.
std::string ringless_bag(const std::filesystem::path& dir) {
  test::TestCloud cloud;
  cloud.stamp_ns = kFirstStamp;
  cloud.add_field("x", test::kFloat32);
  cloud.add_field("y", test::kFloat32);
  cloud.add_field("z", test::kFloat32);
  cloud.allocate(1, 64 * 360);
  for (int beam = 0; beam < 64; ++beam) {
    const double elevation = (-24.8 + 26.8 * beam / 63.0) * M_PI / 180.0;
    for (int col = 0; col < 360; ++col) {
      const double azimuth = col * M_PI / 180.0;
      const size_t i = static_cast<size_t>(beam * 360 + col);
      cloud.set(i, "x", 10.0 * std::cos(elevation) * std::cos(azimuth));
      cloud.set(i, "y", 10.0 * std::cos(elevation) * std::sin(azimuth));
      cloud.set(i, "z", 10.0 * std::sin(elevation));
    }
  }
  return one_cloud_bag(dir, "ringless.bag", cloud, 2);
}

TEST(Rosbag, APresetThePointsDoNotFitIsAnError) {
  // A VLP-16 spans +-15 deg: the 36 % of the points below that would be lost from every scan.
  const auto dir = test::scratch_dir("rosbag_preset_misfit");
  const std::string path = ringless_bag(dir);
  SourceOptions options;
  options.sensor_preset = "vlp16";
  const std::string what = error_of(path, options);
  EXPECT_TRUE(contains(what, "outside the beams of sensor vlp16")) << what;
  EXPECT_TRUE(contains(what, "/points")) << what;
  EXPECT_TRUE(contains(what, "%")) << what;
  // Without a preset the model comes from the points themselves and fits.
  EXPECT_EQ(error_of(path), "");
}

TEST(Rosbag, RingsBeyondThePresetsBeamsAreAnError) {
  // Reference clouds of 32 rings flattened into one row, read as a VLP-16: rings 16-31 have
  // no beam, half of every scan. By their rings alone they are an HDL-32E, which fits.
  const auto dir = test::scratch_dir("rosbag_rings_misfit");
  CloudSpec spec;
  spec.rows = 32;
  const std::string path = one_cloud_bag(dir, "rings.bag", flattened_reference_cloud(spec), 1);
  SourceOptions options;
  options.sensor_preset = "vlp16";
  const std::string what = error_of(path, options);
  EXPECT_TRUE(contains(what, "outside the beams of sensor vlp16")) << what;
  EXPECT_EQ(error_of(path), "");
}

TEST(Rosbag, UnorganizedCloudsGoToTheOrganizer) {
  const auto dir = test::scratch_dir("rosbag_unorganized");
  // The reference scene flattened into one row, rings numbered from the lowest beam up.
  CloudSpec spec;
  spec.lowest_first = true;
  const test::TestCloud cloud = flattened_reference_cloud(spec);
  const std::string path =
      one_cloud_bag(dir, "u.bag", cloud, 2, "/velodyne_points", TestCompression::kBz2);

  test::StandInLog log;
  const std::unique_ptr<ScanSource> source =
      open_rosbag_source(path, {}, test::stand_in_dependencies(log));
  EXPECT_EQ(source->info().sensor.name, "vlp16");  // by its 16 rings
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[1].sequence, 1u);
  ASSERT_EQ(log.organized_clouds.size(), 2u);
  const PointCloud& handed = log.organized_clouds[0];
  EXPECT_EQ(log.organized_for[0].name, "vlp16");
  ASSERT_EQ(handed.size(), cloud.width);
  EXPECT_TRUE(handed.ring_counts_up);
  EXPECT_EQ(handed.stamp_ns, spec.stamp_ns);
  for (int stored_row = 0; stored_row < test::kRefRows; ++stored_row) {
    for (int col = 0; col < test::kRefCols; ++col) {
      const size_t i = static_cast<size_t>(stored_row * test::kRefCols + col);
      const test::ReferencePoint p = test::reference_point(test::kRefRows - 1 - stored_row, col);
      EXPECT_EQ(handed.ring[i], stored_row);
      if (p.valid) {
        EXPECT_EQ(handed.xyz[i], p.xyz.cast<float>());
      }
    }
  }

  // Without a ring field the elevations tell the beams (the reference scene's are a
  // VLP-16's); sensor.preset still wins.
  test::TestCloud no_ring = cloud;
  no_ring.fields[4].name = "unused";
  TestBagWriter no_ring_writer(TestCompression::kNone);
  const uint32_t c = no_ring_writer.add_connection("/cloud", "sensor_msgs/PointCloud2");
  no_ring_writer.add_message(c, kFirstStamp, no_ring.serialize());
  const std::string no_ring_path = test::write_bag_file(dir, "n.bag", no_ring_writer.finish());
  EXPECT_EQ(open_bag(no_ring_path, {})->info().sensor.name, "vlp16");
  SourceOptions options;
  options.sensor_preset = "hdl32";
  EXPECT_EQ(open_bag(no_ring_path, options)->info().sensor.name, "hdl32");

  // Points on no beams at all (elevations spread evenly): the user must name the sensor.
  test::TestCloud scattered = no_ring;
  for (size_t i = 0; i < scattered.width; ++i) {
    const double elevation =
        (-15.0 + 30.0 * static_cast<double>(i) / scattered.width) * M_PI / 180.0;
    const double azimuth = 2.0 * M_PI * static_cast<double>(i % 64) / 64.0;
    scattered.set(i, "x", 8.0 * std::cos(elevation) * std::cos(azimuth));
    scattered.set(i, "y", 8.0 * std::cos(elevation) * std::sin(azimuth));
    scattered.set(i, "z", 8.0 * std::sin(elevation));
  }
  TestBagWriter scattered_writer(TestCompression::kNone);
  const uint32_t d = scattered_writer.add_connection("/cloud", "sensor_msgs/PointCloud2");
  scattered_writer.add_message(d, kFirstStamp, scattered.serialize());
  const std::string scattered_path = test::write_bag_file(dir, "s.bag", scattered_writer.finish());
  EXPECT_TRUE(contains(error_of(scattered_path), "set sensor.preset")) << error_of(scattered_path);
}

TEST(Rosbag, CloudsWithoutTimesGetThemFromTheAzimuth) {
  // The reference scene turns clockwise from +x over its 64 columns, row after row: every
  // point's time is its column's share of the revolution after the header stamp.
  const auto dir = test::scratch_dir("rosbag_azimuth_times");
  CloudSpec spec;
  spec.time_field = "";
  test::TestCloud organized = test::make_reference_cloud(spec);
  test::TestCloud flat = organized;
  flat.width *= flat.height;
  flat.height = 1;
  flat.row_step = flat.width * flat.point_step;
  TestBagWriter writer(TestCompression::kNone);
  const uint32_t image = writer.add_connection("/image", "sensor_msgs/PointCloud2");
  const uint32_t points = writer.add_connection("/points", "sensor_msgs/PointCloud2");
  writer.add_message(image, kFirstStamp, organized.serialize());
  writer.add_message(points, kFirstStamp, flat.serialize());
  const std::string path = test::write_bag_file(dir, "t.bag", writer.finish());
  const double column_s = 1.0 / (test::kRefCols * 10.0);  // vlp16: 10 Hz

  SourceOptions options;
  options.topic = "/image";
  std::unique_ptr<ScanSource> source = open_bag(path, options);
  EXPECT_TRUE(contains(source->info().times, "from the azimuth (the sweep began 0.0 deg"))
      << source->info().times;
  std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(source->stats().warning_count, 0u);
  for (int row = 0; row < test::kRefRows; ++row) {
    for (int col = 0; col < test::kRefCols; ++col) {
      const size_t i = scans[0].index(row, col);
      if (scans[0].valid[i]) {
        EXPECT_NEAR(scans[0].time_offset_s[i], col * column_s, 1e-6);
      }
    }
  }

  options.topic = "/points";
  test::StandInLog log;
  source = open_rosbag_source(path, options, test::stand_in_dependencies(log));
  scans = test::read_scans(*source);
  ASSERT_EQ(log.organized_clouds.size(), 1u);
  const PointCloud& handed = log.organized_clouds[0];
  ASSERT_EQ(handed.time_offset_s.size(), handed.size());
  for (size_t i = 0; i < handed.size(); ++i) {
    if (!handed.xyz[i].isZero() && handed.xyz[i].allFinite()) {
      EXPECT_NEAR(handed.time_offset_s[i], static_cast<double>(i % test::kRefCols) * column_s,
                  1e-6);
    }
  }

  // sensor.times_from_azimuth: false.
  options.topic = "/image";
  options.times_from_azimuth = false;
  source = open_bag(path, options);
  EXPECT_EQ(source->info().times, "none: no time field, and sensor.times_from_azimuth is false");
  scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  for (const float t : scans[0].time_offset_s) EXPECT_EQ(t, 0.0f);
}

// ---------------------------------------------------------------------------------------
// Topic choice

TEST(Rosbag, TopicChoice) {
  const auto dir = test::scratch_dir("rosbag_topic_choice");
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t front = writer.add_connection("/front/points", "sensor_msgs/PointCloud2");
  const uint32_t rear = writer.add_connection("/rear/points", "sensor_msgs/PointCloud2");
  const uint32_t imu = writer.add_connection("/imu", "sensor_msgs/Imu");
  CloudSpec front_spec;
  CloudSpec rear_spec;
  rear_spec.stamp_ns = kFirstStamp + 777;
  writer.add_message(front, kFirstStamp, test::make_reference_cloud(front_spec).serialize());
  writer.add_message(rear, kFirstStamp, test::make_reference_cloud(rear_spec).serialize());
  writer.add_message(imu, kFirstStamp, std::vector<uint8_t>(300, 1));
  const std::string path = test::write_bag_file(dir, "two.bag", writer.finish());

  // Two cloud topics and no choice: the error lists both and says how to choose.
  const std::string both = error_of(path);
  EXPECT_TRUE(contains(both, "/front/points")) << both;
  EXPECT_TRUE(contains(both, "/rear/points")) << both;
  EXPECT_TRUE(contains(both, "--topic")) << both;
  EXPECT_FALSE(contains(both, "/imu")) << both;

  SourceOptions options;
  options.topic = "/rear/points";
  const std::unique_ptr<ScanSource> source = open_bag(path, options);
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  test::expect_reference_scan(scans[0], rear_spec, 1e-9);

  options.topic = "/rear/point";
  const std::string unknown = error_of(path, options);
  EXPECT_TRUE(contains(unknown, "no topic '/rear/point'")) << unknown;
  EXPECT_TRUE(contains(unknown, "did you mean '/rear/points'")) << unknown;

  options.topic = "/imu";
  const std::string wrong_type = error_of(path, options);
  EXPECT_TRUE(contains(wrong_type, "sensor_msgs/Imu, which is not a scan type")) << wrong_type;

  // A bag without any scan topic.
  TestBagWriter no_scans(TestCompression::kNone);
  const uint32_t only = no_scans.add_connection("/imu", "sensor_msgs/Imu");
  no_scans.add_message(only, kFirstStamp, std::vector<uint8_t>(10, 0));
  const std::string none = error_of(test::write_bag_file(dir, "none.bag", no_scans.finish()));
  EXPECT_TRUE(contains(none, "no topic holds scans")) << none;
}

TEST(Rosbag, RealOusterBagChoosesTheLidarPackets) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  test::StandInLog log;
  EXPECT_THROW(open_rosbag_source(path.string(), {}, test::stand_in_dependencies(log)), InputError);
  EXPECT_EQ(log.packet_topic, "/os_node0/lidar_packets");

  SourceOptions options;
  options.topic = "/os_node0/imu_packets";
  const std::string imu = error_of(path.string(), options);
  EXPECT_TRUE(contains(imu, "IMU packets")) << imu;
}

// ---------------------------------------------------------------------------------------
// Damaged input

TEST(Rosbag, BadMessagesAreSkippedWithCountedWarnings) {
  const auto dir = test::scratch_dir("rosbag_bad_messages");
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t points = writer.add_connection("/points", "sensor_msgs/PointCloud2");
  const test::TestCloud good = test::make_reference_cloud({});
  test::TestCloud big_endian = good;
  big_endian.is_bigendian = 1;
  test::TestCloud past_step = good;
  past_step.fields[5].offset = past_step.point_step;  // t starts where the point ends
  std::vector<uint8_t> cut = good.serialize();
  cut.resize(cut.size() / 2);
  writer.add_message(points, kFirstStamp, good.serialize());
  writer.add_message(points, kFirstStamp, big_endian.serialize());
  writer.add_message(points, kFirstStamp, past_step.serialize());
  writer.add_message(points, kFirstStamp, cut);
  writer.add_message(points, kFirstStamp, good.serialize());
  const std::string path = test::write_bag_file(dir, "bad.bag", writer.finish());

  const std::unique_ptr<ScanSource> source = open_bag(path);
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].sequence, 0u);
  EXPECT_EQ(scans[1].sequence, 4u);
  const ReadStats& stats = source->stats();
  EXPECT_EQ(stats.frames_read, 2u);
  EXPECT_EQ(stats.frames_skipped, 3u);
  ASSERT_EQ(stats.warning_count, 3u);
  EXPECT_TRUE(contains(stats.warnings[0], "big-endian")) << stats.warnings[0];
  EXPECT_TRUE(contains(stats.warnings[1], "past point_step")) << stats.warnings[1];
  EXPECT_TRUE(contains(stats.warnings[2], "remain")) << stats.warnings[2];

  // When no message of the topic is readable, opening fails and says why.
  TestBagWriter all_bad(TestCompression::kNone);
  const uint32_t c = all_bad.add_connection("/points", "sensor_msgs/PointCloud2");
  all_bad.add_message(c, kFirstStamp, big_endian.serialize());
  const std::string error = error_of(test::write_bag_file(dir, "all_bad.bag", all_bad.finish()));
  EXPECT_TRUE(contains(error, "no readable PointCloud2 message on /points")) << error;
  EXPECT_TRUE(contains(error, "big-endian")) << error;
}

TEST(Rosbag, NotABag) {
  const auto dir = test::scratch_dir("rosbag_not_a_bag");
  EXPECT_TRUE(contains(error_of(test::write_bag_file(dir, "empty.bag", {})), "empty file"));
  const std::string text = "hello\n";
  EXPECT_TRUE(contains(error_of(test::write_bag_file(
                           dir, "text.bag", std::vector<uint8_t>(text.begin(), text.end()))),
                       "not a ROS bag"));
  EXPECT_TRUE(contains(error_of((dir / "missing.bag").string()), "cannot open"));
}

TEST(Rosbag, TruncatedBagsGiveFewerFramesOrAnError) {
  const auto dir = test::scratch_dir("rosbag_truncated");
  for (const TestCompression compression : {TestCompression::kNone, TestCompression::kLz4}) {
    SCOPED_TRACE(test::compression_name(compression));
    const int frames = 6;
    const std::vector<uint8_t> whole = cloud_bag(compression, CloudSpec{}, frames, true, 30000);
    size_t errors = 0;
    size_t partial = 0;
    for (size_t cut = 0; cut < whole.size(); cut += 1 + whole.size() / 97) {
      SCOPED_TRACE("cut at " + std::to_string(cut));
      const std::string path = test::write_bag_file(
          dir, "cut.bag", std::vector<uint8_t>(whole.begin(), whole.begin() + cut));
      std::unique_ptr<ScanSource> source;
      try {
        source = open_bag(path);
      } catch (const InputError&) {
        ++errors;
        continue;
      }
      const std::vector<Scan> scans = test::read_scans(*source);
      ASSERT_LE(scans.size(), static_cast<size_t>(frames));
      for (size_t i = 0; i < scans.size(); ++i) {
        test::expect_reference_scan(scans[i], frame_spec(CloudSpec{}, static_cast<int>(i)), 1e-9);
      }
      EXPECT_GT(source->stats().warning_count, 0u);  // a cut bag always says so
      if (scans.size() < static_cast<size_t>(frames)) ++partial;
    }
    EXPECT_GT(errors, 0u);
    EXPECT_GT(partial, 50u);
  }
}

// ---------------------------------------------------------------------------------------
// Speed

TEST(Rosbag, ReadingSpeedOfLargeOrganizedClouds) {
  // 50 clouds of 128 x 1024 points in the Ouster driver's layout: 48-byte points holding
  // x y z intensity t reflectivity ring ambient range (6.3 MB a message), lz4 chunks.
  const auto dir = test::scratch_dir("rosbag_speed");
  CloudSpec spec;
  spec.rows = 128;
  spec.cols = 1024;
  test::TestCloud cloud = test::make_reference_cloud(spec);
  test::TestCloud ouster;
  for (const char* axis : {"x", "y", "z"}) ouster.add_field(axis, test::kFloat32);
  ouster.point_step += 4;
  ouster.add_field("intensity", test::kFloat32);
  ouster.add_field("t", test::kUint32);
  ouster.add_field("reflectivity", test::kUint16);
  ouster.add_field("ring", test::kUint16);
  ouster.add_field("ambient", test::kUint16);
  ouster.point_step += 2;
  ouster.add_field("range", test::kUint32);
  ouster.point_step = 48;
  ouster.allocate(128, 1024);
  ouster.stamp_ns = kFirstStamp;
  for (size_t i = 0; i < static_cast<size_t>(128 * 1024); ++i) {
    const uint8_t* from = cloud.data.data() + i * cloud.point_step;
    uint8_t* to = ouster.data.data() + i * ouster.point_step;
    std::memcpy(to, from, 12);           // x y z
    std::memcpy(to + 16, from + 12, 4);  // intensity
    std::memcpy(to + 20, from + 18, 4);  // t
    std::memcpy(to + 26, from + 16, 2);  // ring
  }
  const int messages = 50;
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t points = writer.add_connection("/os_cloud_node/points", "sensor_msgs/PointCloud2");
  size_t message_bytes = 0;
  for (int m = 0; m < messages; ++m) {
    ouster.stamp_ns = kFirstStamp + m * kFramePeriodNs;
    const std::vector<uint8_t> message = ouster.serialize();
    message_bytes += message.size();
    writer.add_message(points, ouster.stamp_ns, message);
  }
  const std::vector<uint8_t> bag = writer.finish();
  const std::string path = test::write_bag_file(dir, "speed.bag", bag);

  const auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<ScanSource> source = open_bag(path);
  size_t valid = 0;
  size_t scans = 0;
  while (std::optional<Scan> scan = source->next()) {
    valid += scan->valid_count();
    ++scans;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(scans, static_cast<size_t>(messages));
  EXPECT_EQ(valid, static_cast<size_t>(messages) * (128 * 1024 - 2));
  std::printf(
      "[ speed    ] %d messages of 128 x 1024 points, %.1f MB of messages in %.1f MB of "
      "lz4 bag: %.2f s, %.1f messages/s, %.0f MB/s of messages, %.0f MB/s of file\n",
      messages, static_cast<double>(message_bytes) / 1e6, static_cast<double>(bag.size()) / 1e6,
      seconds, messages / seconds, static_cast<double>(message_bytes) / 1e6 / seconds,
      static_cast<double>(bag.size()) / 1e6 / seconds);

  // The record reader alone (decompressing the chunks, no message decoding), for the share
  // of the reading that conversion to scans takes.
  const auto walk_start = std::chrono::steady_clock::now();
  std::ifstream stream(path, std::ios::binary);
  BagRecordReader reader(stream, path);
  size_t walked_bytes = 0;
  while (const std::optional<BagMessage> message = reader.next())
    walked_bytes += message->data.size;
  const double walk_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - walk_start).count();
  EXPECT_EQ(walked_bytes, message_bytes);
  std::printf("[ speed    ] record reader alone: %.2f s, %.0f MB/s of messages\n", walk_seconds,
              static_cast<double>(walked_bytes) / 1e6 / walk_seconds);
  std::filesystem::remove_all(dir);
}

/// A sensor_msgs/Imu in ROS 1 serialization: header, orientation, angular velocity and
/// linear acceleration, each followed by its 3x3 covariance.
std::vector<uint8_t> ros1_imu(int64_t stamp_ns, const Eigen::Vector3d& gyro,
                              const Eigen::Vector3d& accel) {
  test::RosBytes out;
  out.u32(7).time(stamp_ns).string("imu_link");
  for (double q : {0.0, 0.0, 0.0, 1.0}) out.value(q);
  for (int i = 0; i < 9; ++i) out.value(-1.0);
  for (int i = 0; i < 3; ++i) out.value(gyro[i]);
  for (int i = 0; i < 9; ++i) out.value(0.0);
  for (int i = 0; i < 3; ++i) out.value(accel[i]);
  for (int i = 0; i < 9; ++i) out.value(0.0);
  return out.bytes();
}

/// The same in CDR (ROS 2: no seq; the doubles aligned to 8 bytes after the frame id).
std::vector<uint8_t> cdr_imu(int64_t stamp_ns, const Eigen::Vector3d& gyro,
                             const Eigen::Vector3d& accel) {
  test::CdrBytes out;
  out.time(stamp_ns).string("imu");  // 4 + 4 + 4 + 4 bytes: the doubles need padding
  for (double q : {0.0, 0.0, 0.0, 1.0}) out.f64(q);
  for (int i = 0; i < 9; ++i) out.f64(-1.0);
  for (int i = 0; i < 3; ++i) out.f64(gyro[i]);
  for (int i = 0; i < 9; ++i) out.f64(0.0);
  for (int i = 0; i < 3; ++i) out.f64(accel[i]);
  for (int i = 0; i < 9; ++i) out.f64(0.0);
  return out.data();
}

TEST(ImuMessage, DecodesBothEncodings) {
  const Eigen::Vector3d gyro(0.1, -0.2, 0.3);
  const Eigen::Vector3d accel(0.5, 0.25, 9.8);
  const std::vector<uint8_t> ros1 = ros1_imu(kFirstStamp, gyro, accel);
  const ImuSample a = imu_message({ros1.data(), ros1.size()}, MessageEncoding::kRos1);
  EXPECT_EQ(a.stamp_ns, kFirstStamp);
  EXPECT_EQ(a.gyro_radps, gyro);
  EXPECT_EQ(a.accel_mps2, accel);

  const std::vector<uint8_t> cdr = cdr_imu(kFirstStamp, gyro, accel);
  const ImuSample b = imu_message({cdr.data(), cdr.size()}, MessageEncoding::kCdr);
  EXPECT_EQ(b.stamp_ns, kFirstStamp);
  EXPECT_EQ(b.gyro_radps, gyro);
  EXPECT_EQ(b.accel_mps2, accel);

  // Cut short: an error naming the field, never a read past the end.
  EXPECT_THROW(imu_message({ros1.data(), ros1.size() - 80}, MessageEncoding::kRos1),
               SerializationError);
  EXPECT_THROW(imu_message({cdr.data(), 30}, MessageEncoding::kCdr), SerializationError);
}

TEST(ImuMessage, RollPitchYawTurnsTheImuIntoTheSensorFrame) {
  // Yaw 90 deg: the IMU's x is the sensor's y.
  const Eigen::Matrix3d yaw = rotation_from_roll_pitch_yaw_deg({0.0, 0.0, 90.0});
  EXPECT_TRUE((yaw * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  // Roll 180 deg: an IMU mounted upside down reads gravity's reaction along its -z.
  const Eigen::Matrix3d roll = rotation_from_roll_pitch_yaw_deg({180.0, 0.0, 0.0});
  EXPECT_TRUE((roll * Eigen::Vector3d(0, 0, -9.8)).isApprox(Eigen::Vector3d(0, 0, 9.8), 1e-12));
  // Roll first, then pitch, then yaw (R = Rz Ry Rx).
  const Eigen::Matrix3d all = rotation_from_roll_pitch_yaw_deg({10.0, 20.0, 30.0});
  const double d = M_PI / 180.0;
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(30 * d, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(20 * d, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(10 * d, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_TRUE(all.isApprox(expected, 1e-12));
}

/// Clouds on /points every 100 ms and a 200 Hz sensor_msgs/Imu on `imu_topics` (each the
/// same samples), starting 50 ms before the first cloud and ending 50 ms after the last
/// sweep.
std::string cloud_and_imu_bag(const std::filesystem::path& dir, const std::string& name,
                              const std::vector<std::string>& imu_topics, int frames) {
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t points = writer.add_connection("/points", "sensor_msgs/PointCloud2");
  std::vector<uint32_t> imus;
  for (const std::string& topic : imu_topics) {
    imus.push_back(writer.add_connection(topic, "sensor_msgs/Imu"));
  }
  int64_t imu_stamp = kFirstStamp - 50'000'000;
  const int64_t imu_end = kFirstStamp + frames * kFramePeriodNs + 50'000'000;
  for (int frame = 0; frame < frames; ++frame) {
    const CloudSpec s = frame_spec(CloudSpec(), frame);
    // The cloud is written once its sweep is over, as drivers publish it.
    while (imu_stamp < s.stamp_ns + kFramePeriodNs && imu_stamp < imu_end) {
      for (uint32_t imu : imus) {
        writer.add_message(
            imu, imu_stamp,
            ros1_imu(imu_stamp, Eigen::Vector3d(0.0, 0.0, 0.5), Eigen::Vector3d(1.0, 0.0, 9.8)));
      }
      imu_stamp += 5'000'000;
    }
    writer.add_message(points, s.stamp_ns + kFramePeriodNs,
                       test::make_reference_cloud(s).serialize());
  }
  while (imu_stamp < imu_end) {
    for (uint32_t imu : imus) {
      writer.add_message(
          imu, imu_stamp,
          ros1_imu(imu_stamp, Eigen::Vector3d(0.0, 0.0, 0.5), Eigen::Vector3d(1.0, 0.0, 9.8)));
    }
    imu_stamp += 5'000'000;
  }
  return test::write_bag_file(dir, name, writer.finish());
}

TEST(RosbagImu, TheOneImuTopicGoesWithTheClouds) {
  const auto dir = test::scratch_dir("rosbag_imu_one");
  const std::string path = cloud_and_imu_bag(dir, "imu.bag", {"/imu/data"}, 3);
  const std::unique_ptr<ScanSource> source = open_bag(path);
  EXPECT_TRUE(contains(source->info().imu, "/imu/data")) << source->info().imu;
  EXPECT_TRUE(contains(source->info().imu, "aligned with the LiDAR")) << source->info().imu;
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 3u);
  for (const Scan& scan : scans) {
    ASSERT_EQ(scan.imu.size(), 20u) << "scan " << scan.sequence;  // 200 Hz over 100 ms
    for (size_t i = 0; i < scan.imu.size(); ++i) {
      EXPECT_GE(scan.imu[i].stamp_ns, scan.stamp_ns);
      EXPECT_LT(scan.imu[i].stamp_ns, scan.stamp_ns + kFramePeriodNs);
      if (i > 0) {
        EXPECT_EQ(scan.imu[i].stamp_ns - scan.imu[i - 1].stamp_ns, 5'000'000);
      }
      EXPECT_EQ(scan.imu[i].accel_mps2, Eigen::Vector3d(1.0, 0.0, 9.8));
    }
  }
  EXPECT_EQ(source->stats().warning_count, 0u);

  // A configured rotation turns the samples: yaw 90 deg takes the IMU's x to the sensor's y.
  SourceOptions turned;
  turned.imu_rotation_deg = {0.0, 0.0, 90.0};
  const std::unique_ptr<ScanSource> rotated = open_bag(path, turned);
  EXPECT_TRUE(contains(rotated->info().imu, "sensor.imu_rotation")) << rotated->info().imu;
  const std::vector<Scan> rotated_scans = test::read_scans(*rotated);
  ASSERT_EQ(rotated_scans.size(), 3u);
  ASSERT_FALSE(rotated_scans[0].imu.empty());
  EXPECT_TRUE(rotated_scans[0].imu[0].accel_mps2.isApprox(Eigen::Vector3d(0.0, 1.0, 9.8), 1e-12));

  SourceOptions off;
  off.imu = false;
  const std::unique_ptr<ScanSource> plain = open_bag(path, off);
  EXPECT_TRUE(plain->info().imu.empty());
  for (const Scan& scan : test::read_scans(*plain)) EXPECT_TRUE(scan.imu.empty());
}

TEST(RosbagImu, SeveralImuTopicsNeedAName) {
  const auto dir = test::scratch_dir("rosbag_imu_several");
  const std::string path = cloud_and_imu_bag(dir, "imus.bag", {"/imu/a", "/imu/b"}, 2);
  const std::unique_ptr<ScanSource> source = open_bag(path);
  EXPECT_TRUE(contains(source->info().imu, "several")) << source->info().imu;
  for (const Scan& scan : test::read_scans(*source)) EXPECT_TRUE(scan.imu.empty());

  SourceOptions named;
  named.imu_topic = "/imu/b";
  const std::unique_ptr<ScanSource> chosen = open_bag(path, named);
  EXPECT_TRUE(contains(chosen->info().imu, "/imu/b")) << chosen->info().imu;
  const std::vector<Scan> scans = test::read_scans(*chosen);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].imu.size(), 20u);

  SourceOptions wrong;
  wrong.imu_topic = "/imu/c";
  EXPECT_TRUE(contains(error_of(path, wrong), "did you mean")) << error_of(path, wrong);
  wrong.imu_topic = "/points";
  EXPECT_TRUE(contains(error_of(path, wrong), "not sensor_msgs/Imu")) << error_of(path, wrong);
}

}  // namespace
}  // namespace featsense::slam
