// ROS 2 bags (sqlite3 files with their metadata.yaml) and MCAP files of PointCloud2 messages,
// written here and read through open_scan_source(): the clouds must come out as the ROS 1
// reader gives them, split bags in order, and damage as a clear error or a counted warning.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "slam/pcap_test_util.hpp"
#include "slam/ros2_test_writers.hpp"
#include "slam/rosbag_test_clouds.hpp"

namespace featsense::slam {
namespace {

using test::CloudSpec;
using test::McapCompression;
using test::McapLayoutSpec;
using test::McapTestWriter;
using test::TestMessage;
using test::TestTopic;

constexpr const char* kTopic = "/lidar/points";
constexpr const char* kCloudType = "sensor_msgs/msg/PointCloud2";
constexpr int64_t kPeriodNs = 100000000;

CloudSpec spec_of(int index) {
  CloudSpec spec;
  spec.stamp_ns += index * kPeriodNs;
  return spec;
}

std::vector<TestMessage> cloud_messages(int first, int count) {
  std::vector<TestMessage> messages;
  for (int i = first; i < first + count; ++i) {
    const CloudSpec spec = spec_of(i);
    messages.push_back(
        {kTopic, spec.stamp_ns + 5000000, test::cdr_pointcloud2(test::make_reference_cloud(spec))});
  }
  return messages;
}

/// Reads every scan, checking each against the reference cloud of its index.
size_t expect_reference_scans(ScanSource& source, int count) {
  size_t read = 0;
  while (std::optional<Scan> scan = source.next()) {
    if (read < static_cast<size_t>(count)) {
      test::expect_reference_scan(*scan, spec_of(static_cast<int>(read)), 1e-6);
    }
    ++read;
  }
  return read;
}

TEST(Ros2Bag, FolderAndSingleFileGiveTheClouds) {
  const auto dir = test::scratch_dir("ros2_folder");
  test::write_sqlite_bag(dir / "bag_0.db3",
                         {{kTopic, kCloudType}, {"/chatter", "std_msgs/msg/String"}},
                         cloud_messages(0, 3));
  test::write_bag_metadata(dir, {"bag_0.db3"});
  for (const std::string& input :
       {dir.string(), (dir / "bag_0.db3").string(), (dir / "metadata.yaml").string()}) {
    SCOPED_TRACE(input);
    std::unique_ptr<ScanSource> source = open_scan_source(input);
    EXPECT_EQ(source->info().format, "ros2-bag");
    ASSERT_EQ(source->info().topics.size(), 2u);
    EXPECT_EQ(source->info().topics[1], "/lidar/points (sensor_msgs/PointCloud2, cdr, 3 messages)");
    EXPECT_EQ(expect_reference_scans(*source, 3), 3u);
    EXPECT_EQ(source->stats().warning_count, 0u);
  }
}

// Older rosbag2 versions left serialization_format empty; the messages are CDR all the same.
TEST(Ros2Bag, AnEmptySerializationFormatMeansCdr) {
  const auto dir = test::scratch_dir("ros2_empty_format");
  test::write_sqlite_bag(dir / "empty.db3", {{kTopic, kCloudType, ""}}, cloud_messages(0, 3));
  test::write_sqlite_bag(dir / "cdr.db3", {{kTopic, kCloudType, "cdr"}}, cloud_messages(0, 3));
  std::unique_ptr<ScanSource> empty = open_scan_source((dir / "empty.db3").string());
  std::unique_ptr<ScanSource> cdr = open_scan_source((dir / "cdr.db3").string());
  EXPECT_EQ(empty->info().topics, cdr->info().topics);
  for (int i = 0; i < 3; ++i) {
    const std::optional<Scan> a = empty->next();
    const std::optional<Scan> b = cdr->next();
    ASSERT_TRUE(a && b) << "scan " << i;
    test::expect_reference_scan(*a, spec_of(i), 1e-6);
    EXPECT_EQ(a->stamp_ns, b->stamp_ns);
    EXPECT_EQ(a->xyz, b->xyz);
    EXPECT_EQ(a->valid, b->valid);
  }
  EXPECT_FALSE(empty->next());
  EXPECT_EQ(empty->stats().warning_count, 0u);
}

// A bag converted from ROS 1 says "ros1": its messages are read as ROS 1 serializes them.
TEST(Ros2Bag, ARos1SerializedTopicIsReadAsRos1) {
  const auto dir = test::scratch_dir("ros2_ros1_format");
  std::vector<TestMessage> messages;
  for (int i = 0; i < 2; ++i) {
    const CloudSpec spec = spec_of(i);
    messages.push_back(
        {kTopic, spec.stamp_ns + 5000000, test::make_reference_cloud(spec).serialize()});
  }
  test::write_sqlite_bag(dir / "bag.db3", {{kTopic, kCloudType, "ros1"}}, messages);
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "bag.db3").string());
  EXPECT_EQ(expect_reference_scans(*source, 2), 2u);
  EXPECT_EQ(source->stats().warning_count, 0u);
}

// A serialization that is neither CDR nor ROS 1 is never decoded as a scan, and named.
TEST(Ros2Bag, AnUnknownSerializationIsNamedNotDecoded) {
  const auto dir = test::scratch_dir("ros2_unknown_format");
  test::write_sqlite_bag(dir / "bag.db3", {{kTopic, kCloudType, "json"}}, cloud_messages(0, 1));
  try {
    open_scan_source((dir / "bag.db3").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("json serialization"), std::string::npos) << e.what();
  }
}

// PointCloud2 clouds with neither rows nor a ring field are told by the elevations their
// points lie on: a VLP-16's beams at 10 m, stored as one unorganized row.
TEST(Ros2Bag, AnUnorganizedCloudWithoutRingsIsToldByItsBeams) {
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  std::vector<TestMessage> messages;
  for (int k = 0; k < 2; ++k) {
    test::TestCloud cloud;
    cloud.stamp_ns = spec_of(k).stamp_ns;
    cloud.add_field("x", test::kFloat32);
    cloud.add_field("y", test::kFloat32);
    cloud.add_field("z", test::kFloat32);
    cloud.allocate(1, static_cast<uint32_t>(vlp16.beams * 900));
    size_t i = 0;
    for (int c = 0; c < 900; ++c) {
      const double azimuth = -2.0 * M_PI * c / 900;
      for (const double elevation : vlp16.elevation_rad) {
        const double range = 10.0 + 0.5 * std::sin(0.1 * c);
        cloud.set(i, "x", range * std::cos(elevation) * std::cos(azimuth));
        cloud.set(i, "y", range * std::cos(elevation) * std::sin(azimuth));
        cloud.set(i, "z", range * std::sin(elevation));
        ++i;
      }
    }
    messages.push_back({kTopic, cloud.stamp_ns, test::cdr_pointcloud2(cloud)});
  }
  const auto dir = test::scratch_dir("ros2_unorganized_no_rings");
  test::write_sqlite_bag(dir / "bag.db3", {{kTopic, kCloudType}}, messages);
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "bag.db3").string());
  EXPECT_EQ(source->info().sensor.name, "vlp16") << source->info().detail;
  const std::optional<Scan> scan = source->next();
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->rows, 16);
  EXPECT_EQ(scan->valid_count(), static_cast<size_t>(16 * 900));
}

TEST(Ros2Bag, SplitBagIsReadFileByFile) {
  const auto dir = test::scratch_dir("ros2_split");
  test::write_sqlite_bag(dir / "bag_0.db3", {{kTopic, kCloudType}}, cloud_messages(0, 2));
  test::write_sqlite_bag(dir / "bag_1.db3", {{kTopic, kCloudType}}, cloud_messages(2, 2));
  test::write_bag_metadata(dir, {"bag_0.db3", "bag_1.db3"});
  std::unique_ptr<ScanSource> source = open_scan_source(dir.string());
  EXPECT_EQ(source->info().frames, 4u);
  EXPECT_EQ(expect_reference_scans(*source, 4), 4u);
}

TEST(Ros2Bag, MissingFileIsNamed) {
  const auto dir = test::scratch_dir("ros2_missing");
  test::write_sqlite_bag(dir / "bag_0.db3", {{kTopic, kCloudType}}, cloud_messages(0, 1));
  test::write_bag_metadata(dir, {"bag_0.db3", "bag_1.db3"});
  try {
    open_scan_source(dir.string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bag_1.db3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

TEST(Ros2Bag, UnknownTypeIsNotAScanTopic) {
  const auto dir = test::scratch_dir("ros2_unknown");
  test::write_sqlite_bag(dir / "bag.db3", {{"/imu", "sensor_msgs/msg/Imu"}},
                         {{"/imu", 1, {0, 1, 0, 0, 1, 2}}});
  SourceOptions options;
  options.topic = "/imu";
  try {
    open_scan_source((dir / "bag.db3").string(), options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a scan type"), std::string::npos) << e.what();
  }
  EXPECT_THROW(open_scan_source((dir / "bag.db3").string()), InputError);
}

TEST(Ros2Bag, TruncatedFileGivesAnErrorOrFewerFrames) {
  const auto dir = test::scratch_dir("ros2_truncated");
  const auto full = dir / "full.db3";
  test::write_sqlite_bag(full, {{kTopic, kCloudType}}, cloud_messages(0, 6));
  const std::string bytes = test::read_file(full);
  for (const double fraction : {0.1, 0.5, 0.9}) {
    const auto cut = dir / ("cut" + std::to_string(static_cast<int>(fraction * 10)) + ".db3");
    test::write_file(cut, bytes.substr(0, static_cast<size_t>(bytes.size() * fraction)));
    SCOPED_TRACE(cut.string());
    try {
      std::unique_ptr<ScanSource> source = open_scan_source(cut.string());
      size_t frames = 0;
      while (source->next()) ++frames;
      EXPECT_LT(frames, 6u);
      EXPECT_GT(source->stats().warning_count + source->stats().frames_skipped, 0u);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(cut.filename().string()), std::string::npos) << e.what();
    }
  }
}

/// An MCAP file of the reference clouds on one topic.
std::vector<uint8_t> mcap_of_clouds(const McapLayoutSpec& spec, int count, bool ros1 = false) {
  McapTestWriter writer(spec);
  const uint16_t channel = writer.add_topic(kTopic, ros1 ? "sensor_msgs/PointCloud2" : kCloudType);
  for (int i = 0; i < count; ++i) {
    const test::TestCloud cloud = test::make_reference_cloud(spec_of(i));
    writer.add_message(channel, cloud.stamp_ns,
                       ros1 ? cloud.serialize() : test::cdr_pointcloud2(cloud));
  }
  return writer.write();
}

TEST(Mcap, EveryLayoutAndCompressionGivesTheClouds) {
  const auto dir = test::scratch_dir("mcap_layouts");
  for (const bool chunked : {false, true}) {
    for (const McapCompression compression :
         {McapCompression::kNone, McapCompression::kZstd, McapCompression::kLz4}) {
      if (!chunked && compression != McapCompression::kNone) continue;
      for (const bool summary : {true, false}) {
        McapLayoutSpec spec;
        spec.chunked = chunked;
        spec.compression = compression;
        spec.summary = summary;
        const auto path = dir / ("clouds_" + std::to_string(chunked) +
                                 std::to_string(static_cast<int>(compression)) +
                                 std::to_string(summary) + ".mcap");
        test::write_bytes(path, mcap_of_clouds(spec, 5));
        SCOPED_TRACE(path.filename().string());
        std::unique_ptr<ScanSource> source = open_scan_source(path.string());
        EXPECT_EQ(source->info().format, "mcap");
        EXPECT_EQ(source->info().frames, 5u);
        EXPECT_NE(source->info().detail.find(summary ? "from the summary" : "file scanned"),
                  std::string::npos)
            << source->info().detail;
        EXPECT_EQ(expect_reference_scans(*source, 5), 5u);
        EXPECT_EQ(source->stats().warning_count, 0u) << source->stats().warnings.front();
      }
    }
  }
}

TEST(Mcap, Ros1EncodedCloudsAreReadToo) {
  const auto dir = test::scratch_dir("mcap_ros1");
  McapLayoutSpec spec;
  spec.compression = McapCompression::kZstd;
  spec.message_encoding = "ros1";
  spec.schema_encoding = "ros1msg";
  test::write_bytes(dir / "ros1.mcap", mcap_of_clouds(spec, 3, /*ros1=*/true));
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "ros1.mcap").string());
  EXPECT_EQ(expect_reference_scans(*source, 3), 3u);
}

TEST(Mcap, CutOffRecordingIsReadUpToTheCut) {
  const auto dir = test::scratch_dir("mcap_cut");
  McapLayoutSpec spec;
  spec.compression = McapCompression::kLz4;
  spec.messages_per_chunk = 1;
  const std::vector<uint8_t> whole = mcap_of_clouds(spec, 6);
  const std::vector<uint8_t> cut(whole.begin(), whole.begin() + whole.size() * 6 / 10);
  test::write_bytes(dir / "cut.mcap", cut);
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "cut.mcap").string());
  EXPECT_NE(source->info().detail.find("file scanned"), std::string::npos);
  size_t frames = expect_reference_scans(*source, 6);
  EXPECT_GE(frames, 2u);
  EXPECT_LT(frames, 6u);
  EXPECT_GE(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings.front().find("cut off"), std::string::npos)
      << source->stats().warnings.front();
}

TEST(Mcap, WrongChunkCrcSkipsTheChunkWithAWarning) {
  const auto dir = test::scratch_dir("mcap_crc");
  McapLayoutSpec spec;
  spec.messages_per_chunk = 1;
  std::vector<uint8_t> bytes = mcap_of_clouds(spec, 3);
  // A byte in the middle of the second cloud's points: still parseable, but its CRC is wrong.
  const size_t second_chunk = bytes.size() / 2;
  bytes[second_chunk] ^= 0x40;
  test::write_bytes(dir / "crc.mcap", bytes);
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "crc.mcap").string());
  size_t frames = 0;
  while (source->next()) ++frames;
  EXPECT_EQ(frames, 2u);
  ASSERT_GE(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings.front().find("CRC"), std::string::npos)
      << source->stats().warnings.front();
}

TEST(Mcap, NotAnMcapAndGarbageAfterTheMagic) {
  const auto dir = test::scratch_dir("mcap_garbage");
  std::vector<uint8_t> bytes(std::begin(McapTestWriter::kMagic), std::end(McapTestWriter::kMagic));
  for (int i = 0; i < 100; ++i) bytes.push_back(static_cast<uint8_t>(i * 37));
  test::write_bytes(dir / "garbage.mcap", bytes);
  EXPECT_THROW(open_scan_source((dir / "garbage.mcap").string()), InputError);
}

/// A sensor_msgs/msg/Imu in CDR at `stamp_ns`: a level IMU at rest turning about z.
std::vector<uint8_t> cdr_imu(int64_t stamp_ns) {
  test::CdrBytes out;
  out.time(stamp_ns).string("imu_link");
  for (double q : {0.0, 0.0, 0.0, 1.0}) out.f64(q);
  for (int i = 0; i < 9; ++i) out.f64(0.0);
  for (double w : {0.0, 0.0, 0.25}) out.f64(w);
  for (int i = 0; i < 9; ++i) out.f64(0.0);
  for (double a : {0.0, 0.0, 9.81}) out.f64(a);
  for (int i = 0; i < 9; ++i) out.f64(0.0);
  return out.data();
}

/// 100 Hz IMU messages from a sweep before the first cloud to one after the last.
std::vector<TestMessage> imu_messages(const std::string& topic, int clouds) {
  std::vector<TestMessage> messages;
  const int64_t first = spec_of(0).stamp_ns;
  for (int64_t t = first - kPeriodNs; t < first + (clouds + 1) * kPeriodNs; t += 10'000'000) {
    messages.push_back({topic, t + 1'000'000, cdr_imu(t)});
  }
  return messages;
}

/// Each scan holds the 10 samples of its sweep, level and at rest.
void expect_imu_per_sweep(ScanSource& source, size_t scans) {
  size_t read = 0;
  while (std::optional<Scan> scan = source.next()) {
    ++read;
    ASSERT_EQ(scan->imu.size(), 10u) << "scan " << scan->sequence;
    for (const ImuSample& sample : scan->imu) {
      EXPECT_GE(sample.stamp_ns, scan->stamp_ns);
      EXPECT_LT(sample.stamp_ns, scan->stamp_ns + kPeriodNs);
      EXPECT_EQ(sample.accel_mps2, Eigen::Vector3d(0.0, 0.0, 9.81));
      EXPECT_EQ(sample.gyro_radps, Eigen::Vector3d(0.0, 0.0, 0.25));
    }
  }
  EXPECT_EQ(read, scans);
  EXPECT_EQ(source.stats().warning_count, 0u);
}

TEST(Ros2Bag, ImuMessagesGoWithTheirSweeps) {
  const auto dir = test::scratch_dir("ros2_bag_imu");
  std::vector<TestMessage> messages = cloud_messages(0, 3);
  for (TestMessage& m : imu_messages("/imu/data", 3)) messages.push_back(std::move(m));
  std::sort(messages.begin(), messages.end(),
            [](const TestMessage& a, const TestMessage& b) { return a.time_ns < b.time_ns; });
  test::write_sqlite_bag(dir / "bag.db3",
                         {{kTopic, kCloudType}, {"/imu/data", "sensor_msgs/msg/Imu"}}, messages);
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "bag.db3").string());
  EXPECT_NE(source->info().imu.find("/imu/data"), std::string::npos) << source->info().imu;
  expect_imu_per_sweep(*source, 3);
}

TEST(Mcap, ImuMessagesGoWithTheirSweeps) {
  const auto dir = test::scratch_dir("mcap_imu");
  McapLayoutSpec spec;
  spec.compression = McapCompression::kZstd;
  McapTestWriter writer(spec);
  const uint16_t clouds = writer.add_topic(kTopic, kCloudType);
  const uint16_t imu = writer.add_topic("/imu", "sensor_msgs/msg/Imu");
  std::vector<TestMessage> messages = cloud_messages(0, 4);
  for (TestMessage& m : imu_messages("/imu", 4)) messages.push_back(std::move(m));
  std::sort(messages.begin(), messages.end(),
            [](const TestMessage& a, const TestMessage& b) { return a.time_ns < b.time_ns; });
  for (const TestMessage& m : messages) {
    writer.add_message(m.topic == kTopic ? clouds : imu, m.time_ns, m.data);
  }
  const auto path = dir / "imu.mcap";
  test::write_bytes(path, writer.write());
  std::unique_ptr<ScanSource> source = open_scan_source(path.string());
  EXPECT_NE(source->info().imu.find("/imu"), std::string::npos) << source->info().imu;
  expect_imu_per_sweep(*source, 4);
}

}  // namespace
}  // namespace featsense::slam
