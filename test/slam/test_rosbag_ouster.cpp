// open_rosbag() with the whole library: raw Ouster packets decoded with their metadata
// (OusterFrameAssembler) and unorganized clouds placed by organize().

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/slam/io/readers.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "slam/rosbag_test_source.hpp"
#include "slam/rosbag_test_writer.hpp"

namespace featsense::slam {
namespace {

using test::TestBagWriter;
using test::TestCompression;

/// The messages of the real bag by topic, payloads copied.
struct BagContents {
  std::map<std::string, std::vector<std::vector<uint8_t>>> messages;
  std::map<std::string, std::vector<int64_t>> times;
  std::map<std::string, std::string> types;
};

BagContents read_contents(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  BagRecordReader reader(stream, path.string());
  BagContents contents;
  while (const std::optional<BagMessage> message = reader.next()) {
    const BagConnection& connection = reader.connections().at(message->connection);
    contents.types[connection.topic] = connection.type;
    contents.messages[connection.topic].emplace_back(message->data.data,
                                                     message->data.data + message->data.size);
    contents.times[connection.topic].push_back(message->time_ns);
  }
  return contents;
}

/// The std_msgs/String payload as text.
std::string string_message(const std::vector<uint8_t>& message) {
  uint32_t size = 0;
  std::memcpy(&size, message.data(), 4);
  return std::string(message.begin() + 4, message.begin() + 4 + size);
}

/// A bag holding only the lidar packets of the real bag (plus `extra` packets of another
/// size on the same topic).
std::string packets_only_bag(const std::filesystem::path& dir, const BagContents& contents,
                             int extra = 0) {
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t lidar = writer.add_connection("/os_node0/lidar_packets", "ouster_ros/PacketMsg");
  const auto& packets = contents.messages.at("/os_node0/lidar_packets");
  const auto& times = contents.times.at("/os_node0/lidar_packets");
  for (size_t i = 0; i < packets.size(); ++i) {
    writer.add_message(lidar, times[i], packets[i]);
    if (static_cast<int>(i) < extra) {
      writer.add_message(lidar, times[i],
                         test::RosBytes().byte_array(std::vector<uint8_t>(100, 7)).bytes());
    }
  }
  return test::write_bag_file(dir, "packets_only.bag", writer.finish());
}

/// Checks a decoded frame against the raw packets, decoded here by the PACKET_FORMAT.md rules for
/// the RNG15_RFL8_NIR8 profile: u16 range (low 15 bits, 8 mm units), u8 reflectivity, u8
/// NIR per pixel, the pixel of row i and measurement id m in image column
/// (m + pixel_shift_by_row[i]) mod W.
void expect_scan_matches_packets(const Scan& scan, const nlohmann::json& metadata,
                                 const std::vector<std::vector<uint8_t>>& packets) {
  const nlohmann::json& format = metadata["lidar_data_format"];
  ASSERT_EQ(format["udp_profile_lidar"], "RNG15_RFL8_NIR8");
  const int pixels = format["pixels_per_column"].get<int>();
  const int columns_per_packet = format["columns_per_packet"].get<int>();
  const int width = format["columns_per_frame"].get<int>();
  const std::vector<int> shift = format["pixel_shift_by_row"].get<std::vector<int>>();
  ASSERT_EQ(scan.rows, pixels);
  ASSERT_EQ(scan.cols, width);
  const ScanChannel* reflectivity = scan.channel("reflectivity");
  const ScanChannel* nir = scan.channel("nir");
  ASSERT_NE(reflectivity, nullptr);
  ASSERT_NE(nir, nullptr);
  size_t returns = 0;
  for (const std::vector<uint8_t>& message : packets) {
    const uint8_t* packet = message.data() + 4;  // after the u8[] length
    for (int c = 0; c < columns_per_packet; ++c) {
      const uint8_t* column = packet + 32 + c * (12 + pixels * 4);
      uint16_t measurement_id = 0;
      uint16_t status = 0;
      std::memcpy(&measurement_id, column + 8, 2);
      std::memcpy(&status, column + 10, 2);
      if ((status & 1) == 0) continue;
      for (int row = 0; row < pixels; ++row) {
        const uint8_t* pixel = column + 12 + row * 4;
        uint16_t raw_range = 0;
        std::memcpy(&raw_range, pixel, 2);
        const double range_m = (raw_range & 0x7FFF) * 8 * 1e-3;
        const int col = (measurement_id + shift[static_cast<size_t>(row)]) % width;
        const size_t i = scan.index(row, col);
        if (range_m == 0.0) {
          EXPECT_EQ(scan.valid[i], 0) << "row " << row << " col " << col;
          continue;
        }
        ++returns;
        ASSERT_EQ(scan.valid[i], 1) << "row " << row << " col " << col;
        EXPECT_NEAR(scan.range_m[i], range_m, 1e-4);
        EXPECT_EQ(reflectivity->values[i], static_cast<float>(pixel[2]));
        EXPECT_EQ(nir->values[i], static_cast<float>(pixel[3]));
      }
    }
  }
  EXPECT_EQ(scan.valid_count(), returns);
  EXPECT_GT(returns, scan.size() / 10);
}

TEST(RosbagOuster, RealBagDecodesIntoOneFrame) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  const BagContents contents = read_contents(path);
  const nlohmann::json metadata =
      nlohmann::json::parse(string_message(contents.messages.at("/os_node0/metadata").at(0)));

  const std::unique_ptr<ScanSource> source = open_rosbag(path.string(), {});
  const SourceInfo& info = source->info();
  EXPECT_EQ(info.format, "rosbag");
  EXPECT_TRUE(info.sensor_from_metadata);
  EXPECT_EQ(info.sensor.beams, metadata["lidar_data_format"]["pixels_per_column"].get<int>());
  EXPECT_EQ(info.sensor.columns, metadata["lidar_data_format"]["columns_per_frame"].get<int>());
  EXPECT_NE(info.detail.find("/os_node0/lidar_packets"), std::string::npos) << info.detail;
  EXPECT_NE(info.detail.find("/os_node0/metadata"), std::string::npos) << info.detail;

  // 32 packets of 16 columns: exactly one 512-column frame, handed out at the end.
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  expect_scan_matches_packets(scans[0], metadata, contents.messages.at("/os_node0/lidar_packets"));
  EXPECT_EQ(source->stats().frames_read, 1u);
}

TEST(RosbagOuster, MetadataFromTheOptionWhenTheBagHasNone) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  const auto dir = test::scratch_dir("rosbag_ouster_meta_option");
  const BagContents contents = read_contents(path);
  const std::string json = string_message(contents.messages.at("/os_node0/metadata").at(0));
  const std::string meta_path = (dir / "sensor.json").string();
  std::ofstream(meta_path) << json;
  const std::string bag = packets_only_bag(dir, contents);

  try {
    open_rosbag(bag, {});
    FAIL() << "a packet bag without metadata opened";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("metadata JSON"), std::string::npos) << e.what();
  }

  SourceOptions options;
  options.meta_path = meta_path;
  const std::unique_ptr<ScanSource> source = open_rosbag(bag, options);
  EXPECT_NE(source->info().detail.find(meta_path), std::string::npos) << source->info().detail;
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  expect_scan_matches_packets(scans[0], nlohmann::json::parse(json),
                              contents.messages.at("/os_node0/lidar_packets"));

  // An explicit metadata file wins over the bag's own.
  const std::unique_ptr<ScanSource> real = open_rosbag(path.string(), options);
  EXPECT_NE(real->info().detail.find(meta_path), std::string::npos) << real->info().detail;
}

TEST(RosbagOuster, PacketsOfAnotherSizeAreCountedAndIgnored) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  const auto dir = test::scratch_dir("rosbag_ouster_wrong_size");
  const BagContents contents = read_contents(path);
  const std::string json = string_message(contents.messages.at("/os_node0/metadata").at(0));
  const std::string meta_path = (dir / "sensor.json").string();
  std::ofstream(meta_path) << json;
  SourceOptions options;
  options.meta_path = meta_path;
  const std::unique_ptr<ScanSource> source =
      open_rosbag(packets_only_bag(dir, contents, 3), options);
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(source->stats().warning_count, 3u);
  expect_scan_matches_packets(scans[0], nlohmann::json::parse(json),
                              contents.messages.at("/os_node0/lidar_packets"));
}

TEST(RosbagOuster, RealBagImuPacketsComeWithTheFrame) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  const BagContents contents = read_contents(path);
  ASSERT_EQ(contents.messages.at("/os_node0/imu_packets").size(), 10u);

  const std::unique_ptr<ScanSource> source = open_rosbag(path.string(), {});
  EXPECT_NE(source->info().imu.find("/os_node0/imu_packets"), std::string::npos)
      << source->info().imu;
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0];
  EXPECT_EQ(source->stats().warning_count, 0u);
  ASSERT_FALSE(scan.imu.empty());
  for (size_t i = 0; i < scan.imu.size(); ++i) {
    const ImuSample& sample = scan.imu[i];
    EXPECT_GE(sample.stamp_ns, scan.stamp_ns);
    EXPECT_LT(sample.stamp_ns, scan.stamp_ns + 100'000'000);
    EXPECT_GT(sample.accel_mps2.norm(), 9.0);
    EXPECT_LT(sample.accel_mps2.norm(), 11.5);
    EXPECT_LT(sample.gyro_radps.norm(), 0.5);
    if (i > 0) {
      EXPECT_GT(sample.stamp_ns, scan.imu[i - 1].stamp_ns);
    }
  }
  std::cout << "IMU samples in the frame: " << scan.imu.size() << ", first |a| "
            << scan.imu.front().accel_mps2.norm() << " m/s^2, stamps "
            << scan.imu.front().stamp_ns - scan.stamp_ns << " .. "
            << scan.imu.back().stamp_ns - scan.stamp_ns << " ns after the frame's stamp\n";

  SourceOptions off;
  off.imu = false;
  const std::unique_ptr<ScanSource> without = open_rosbag(path.string(), off);
  EXPECT_TRUE(without->info().imu.empty());
  const std::vector<Scan> plain = test::read_scans(*without);
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_TRUE(plain[0].imu.empty());
}

TEST(RosbagOuster, DamagedImuPacketsAreCountedAndSkipped) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  const auto dir = test::scratch_dir("rosbag_ouster_imu_damaged");
  const BagContents contents = read_contents(path);
  TestBagWriter writer(TestCompression::kLz4);
  const uint32_t metadata = writer.add_connection("/os_node0/metadata", "std_msgs/String");
  const uint32_t lidar = writer.add_connection("/os_node0/lidar_packets", "ouster_ros/PacketMsg");
  const uint32_t imu = writer.add_connection("/os_node0/imu_packets", "ouster_ros/PacketMsg");
  writer.add_message(metadata, contents.times.at("/os_node0/metadata")[0],
                     contents.messages.at("/os_node0/metadata")[0]);
  for (size_t i = 0; i < contents.messages.at("/os_node0/lidar_packets").size(); ++i) {
    writer.add_message(lidar, contents.times.at("/os_node0/lidar_packets")[i],
                       contents.messages.at("/os_node0/lidar_packets")[i]);
  }
  const auto& imu_packets = contents.messages.at("/os_node0/imu_packets");
  for (size_t i = 0; i < imu_packets.size(); ++i) {
    const int64_t time = contents.times.at("/os_node0/imu_packets")[i];
    writer.add_message(imu, time, imu_packets[i]);
    if (i == 2) writer.add_message(imu, time, test::RosBytes().byte_array({1, 2, 3}).bytes());
    if (i == 4) writer.add_message(imu, time, {1, 2});  // not even a whole u8[] length
  }
  const std::string bag = test::write_bag_file(dir, "damaged_imu.bag", writer.finish());

  const std::unique_ptr<ScanSource> whole = open_rosbag(path.string(), {});
  const std::vector<Scan> expected = test::read_scans(*whole);
  const std::unique_ptr<ScanSource> source = open_rosbag(bag, {});
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  ASSERT_EQ(expected.size(), 1u);
  EXPECT_EQ(scans[0].imu.size(), expected[0].imu.size());
  EXPECT_EQ(source->stats().warning_count, 2u);
}

TEST(RosbagOuster, UnorganizedCloudIsOrganizedByRing) {
  // A VLP-16-like cloud: rings numbered from the lowest beam (-15 deg) up in 2 deg steps,
  // one point per ring in every 7th of the preset's 1800 columns, at the column's centre
  // (azimuth measured clockwise from +x; column c is centred on c * 2 pi / columns, as
  // column_of() and Ouster's measurement ids have it).
  const auto dir = test::scratch_dir("rosbag_unorganized_organize");
  const int columns = 1800;
  test::TestCloud cloud;
  for (const char* axis : {"x", "y", "z"}) cloud.add_field(axis, test::kFloat32);
  cloud.add_field("intensity", test::kFloat32);
  cloud.add_field("ring", test::kUint16);
  cloud.add_field("time", test::kFloat32);
  struct Expected {
    int row;
    int col;
    Eigen::Vector3f xyz;
    float intensity;
  };
  std::vector<Expected> expected;
  for (int col = 0; col < columns; col += 7) {
    for (int ring = 0; ring < 16; ++ring) {
      const double elevation = (-15.0 + 2.0 * ring) * M_PI / 180.0;
      const double clockwise = col * 2.0 * M_PI / columns;
      const double range = 4.0 + 0.01 * ring;
      const Eigen::Vector3d p =
          range * Eigen::Vector3d(std::cos(elevation) * std::cos(-clockwise),
                                  std::cos(elevation) * std::sin(-clockwise), std::sin(elevation));
      expected.push_back({15 - ring, col, p.cast<float>(), static_cast<float>(ring + col % 50)});
    }
  }
  cloud.allocate(1, static_cast<uint32_t>(expected.size()));
  for (size_t i = 0; i < expected.size(); ++i) {
    cloud.set(i, "x", static_cast<double>(expected[i].xyz.x()));
    cloud.set(i, "y", static_cast<double>(expected[i].xyz.y()));
    cloud.set(i, "z", static_cast<double>(expected[i].xyz.z()));
    cloud.set(i, "intensity", static_cast<double>(expected[i].intensity));
    cloud.set(i, "ring", 15 - expected[i].row);
    cloud.set(i, "time", expected[i].col * 1e-4 / 1.8);
  }
  cloud.stamp_ns = 1700000000000000000;
  TestBagWriter writer(TestCompression::kBz2);
  const uint32_t points = writer.add_connection("/velodyne_points", "sensor_msgs/PointCloud2");
  writer.add_message(points, cloud.stamp_ns, cloud.serialize());
  const std::string bag = test::write_bag_file(dir, "vlp16.bag", writer.finish());

  const std::unique_ptr<ScanSource> source = open_rosbag(bag, {});
  EXPECT_EQ(source->info().sensor.name, "vlp16");
  const std::vector<Scan> scans = test::read_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0];
  ASSERT_EQ(scan.rows, 16);
  ASSERT_EQ(scan.cols, columns);
  EXPECT_EQ(scan.valid_count(), expected.size());
  const ScanChannel* intensity = scan.channel("intensity");
  ASSERT_NE(intensity, nullptr);
  for (const Expected& e : expected) {
    const size_t i = scan.index(e.row, e.col);
    ASSERT_EQ(scan.valid[i], 1) << "row " << e.row << " col " << e.col;
    EXPECT_EQ(scan.xyz[i], e.xyz);
    EXPECT_EQ(intensity->values[i], e.intensity);
  }
}

}  // namespace
}  // namespace featsense::slam
