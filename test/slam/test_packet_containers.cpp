// Sensor packets in every container: the real VLP-32C packets re-wrapped as a ROS 1 bag, an
// MCAP file and a ROS 2 bag of MCAP storage give the scans the original ROS 2 bag gives; the
// real Ouster packets of the ROS 1 bag, written as a ROS 2 bag in CDR with their metadata
// topic, give the frame the ROS 1 bag gives. Also synthetic Velodyne packets for what the
// real ones do not show: dual returns and the VLP-16's two firings per block.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "ros2/sqlite_bag_log.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "slam/pcap_test_util.hpp"
#include "slam/ros2_test_writers.hpp"
#include "slam/rosbag_test_writer.hpp"
#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_scan_assembler.hpp"

namespace featsense::slam {
namespace {

constexpr const char* kVelodyneBag = "ros2/vlp32_packets/1713492677464078412";
constexpr const char* kVelodyneTopic = "/sensing/lidar/front/velodyne_packets";

/// The raw CDR messages of the real VLP-32C bag with their receive times.
std::vector<test::TestMessage> velodyne_messages(const std::filesystem::path& folder) {
  std::unique_ptr<MessageLog> log =
      open_sqlite_bag_file((folder / "1713492677464078412_0.db3").string());
  std::unique_ptr<MessageCursor> cursor =
      log->open(log->catalog().topics.at(0), [](const std::string&) {});
  std::vector<test::TestMessage> out;
  while (const std::optional<BagMessage> m = cursor->next()) {
    out.push_back({kVelodyneTopic, m->time_ns,
                   std::vector<uint8_t>(m->data.data, m->data.data + m->data.size)});
  }
  return out;
}

/// A CDR VelodyneScan re-serialized the ROS 1 way: header with seq, u32 sec / nsec times.
std::vector<uint8_t> ros1_velodyne_scan(const std::vector<uint8_t>& cdr) {
  size_t at = 4;
  auto u32 = [&](size_t& p) {
    p = 4 + (p - 4 + 3) / 4 * 4;
    uint32_t v = 0;
    std::memcpy(&v, cdr.data() + p, 4);
    p += 4;
    return v;
  };
  test::RosBytes out;
  const uint32_t sec = u32(at);
  const uint32_t nsec = u32(at);
  const uint32_t frame_length = u32(at);
  const std::string frame(reinterpret_cast<const char*>(cdr.data() + at), frame_length - 1);
  at += frame_length;
  out.u32(0).u32(sec).u32(nsec).string(frame);
  const uint32_t packets = u32(at);
  out.u32(packets);
  for (uint32_t i = 0; i < packets; ++i) {
    const uint32_t s = u32(at);
    const uint32_t ns = u32(at);
    out.u32(s).u32(ns).raw(
        std::vector<uint8_t>(cdr.begin() + static_cast<std::ptrdiff_t>(at),
                             cdr.begin() + static_cast<std::ptrdiff_t>(at + 1206)));
    at += 1206;
  }
  return out.bytes();
}

std::vector<Scan> all_scans(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

void expect_same_scans(const std::vector<Scan>& a, const std::vector<Scan>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].stamp_ns, b[s].stamp_ns);
    ASSERT_EQ(a[s].valid, b[s].valid);
    EXPECT_EQ(a[s].xyz, b[s].xyz);
  }
}

TEST(PacketContainers, VelodynePacketsReadTheSameFromEveryContainer) {
  FEATSENSE_SHARED_FILE(bag, kVelodyneBag);
  std::unique_ptr<ScanSource> original = open_scan_source(bag.string());
  const std::vector<Scan> expected = all_scans(*original);
  ASSERT_EQ(expected.size(), 6u);
  const std::vector<test::TestMessage> messages = velodyne_messages(bag);
  const auto dir = test::scratch_dir("velodyne_containers");

  test::TestBagWriter ros1(test::TestCompression::kLz4);
  const uint32_t connection = ros1.add_connection(kVelodyneTopic, "velodyne_msgs/VelodyneScan");
  for (const test::TestMessage& m : messages) {
    ros1.add_message(connection, m.time_ns, ros1_velodyne_scan(m.data));
  }
  test::write_bytes(dir / "velodyne.bag", ros1.finish());

  test::McapLayoutSpec spec;
  spec.compression = test::McapCompression::kZstd;
  test::McapTestWriter mcap(spec);
  const uint16_t channel = mcap.add_topic(kVelodyneTopic, "velodyne_msgs/msg/VelodyneScan");
  for (const test::TestMessage& m : messages) mcap.add_message(channel, m.time_ns, m.data);
  const std::vector<uint8_t> mcap_bytes = mcap.write();
  test::write_bytes(dir / "velodyne.mcap", mcap_bytes);
  std::filesystem::create_directories(dir / "mcap_bag");
  test::write_bytes(dir / "mcap_bag" / "part_0.mcap", mcap_bytes);
  test::write_bag_metadata(dir / "mcap_bag", {"part_0.mcap"}, "mcap");

  for (const std::filesystem::path& input :
       {dir / "velodyne.bag", dir / "velodyne.mcap", dir / "mcap_bag"}) {
    SCOPED_TRACE(input.string());
    std::unique_ptr<ScanSource> source = open_scan_source(input.string());
    expect_same_scans(all_scans(*source), expected);
    EXPECT_EQ(source->stats().warning_count, 0u);
  }
}

TEST(PacketContainers, OusterPacketsInARos2Bag) {
  FEATSENSE_SHARED_FILE(path, "ouster/512x10_raw.bag");
  std::ifstream stream(path, std::ios::binary);
  BagRecordReader reader(stream, path.string());
  std::vector<test::TestMessage> messages;
  while (const std::optional<BagMessage> message = reader.next()) {
    const BagConnection& connection = reader.connections().at(message->connection);
    if (connection.topic == "/os_node0/imu_packets") continue;
    // ROS 1 u8[] / string = u32 length + bytes; CDR adds the encapsulation header (and a
    // trailing NUL to a string).
    uint32_t size = 0;
    std::memcpy(&size, message->data.data, 4);
    const std::vector<uint8_t> payload(message->data.data + 4, message->data.data + 4 + size);
    test::CdrBytes cdr;
    if (connection.type == "std_msgs/String") {
      cdr.string(std::string(payload.begin(), payload.end()));
    } else {
      cdr.byte_sequence(payload);
    }
    messages.push_back({connection.topic, message->time_ns, cdr.data()});
  }
  const auto dir = test::scratch_dir("ouster_ros2");
  test::write_sqlite_bag(dir / "ouster_0.db3",
                         {{"/os_node0/lidar_packets", "ouster_sensor_msgs/msg/PacketMsg"},
                          {"/os_node0/metadata", "std_msgs/msg/String"}},
                         messages);
  test::write_bag_metadata(dir, {"ouster_0.db3"});

  std::unique_ptr<ScanSource> ros1 = open_scan_source(path.string());
  std::unique_ptr<ScanSource> ros2 = open_scan_source(dir.string());
  EXPECT_TRUE(ros2->info().sensor_from_metadata);
  EXPECT_NE(ros2->info().detail.find("/os_node0/metadata"), std::string::npos)
      << ros2->info().detail;
  const std::vector<Scan> a = all_scans(*ros1);
  const std::vector<Scan> b = all_scans(*ros2);
  ASSERT_EQ(a.size(), 1u);
  expect_same_scans(a, b);
}

/// A synthetic packet: every block at `azimuth0 + step * block` (0.01 deg), every return at
/// `raw` distance units, return mode and product id as given.
std::vector<uint8_t> synthetic_packet(uint16_t azimuth0, uint16_t step, uint16_t raw, uint8_t mode,
                                      uint8_t product, bool dual_pairs) {
  std::vector<uint8_t> packet(kVelodynePacketBytes, 0);
  for (size_t block = 0; block < kVelodyneBlocks; ++block) {
    uint8_t* b = packet.data() + block * kVelodyneBlockBytes;
    b[0] = 0xFF;
    b[1] = 0xEE;
    const size_t firing = dual_pairs ? block / 2 : block;
    const uint16_t azimuth = static_cast<uint16_t>((azimuth0 + step * firing) % 36000);
    std::memcpy(b + 2, &azimuth, 2);
    // In the dual pairs, the second block holds the farther return.
    const uint16_t distance = static_cast<uint16_t>(raw + (dual_pairs && block % 2 ? 500 : 0));
    for (size_t slot = 0; slot < kVelodyneSlots; ++slot) {
      std::memcpy(b + 4 + slot * 3, &distance, 2);
      b[4 + slot * 3 + 2] = static_cast<uint8_t>(slot);
    }
  }
  packet[kVelodyneReturnModeByte] = mode;
  packet[kVelodyneProductIdByte] = product;
  return packet;
}

TEST(PacketContainers, DualReturnsKeepTheLastInEachCell) {
  const VelodyneCalibration calibration = builtin_velodyne_calibration(VelodyneModel::kVlp32c);
  VelodyneScanSettings settings;
  settings.columns = 1900;  // the vlp32c preset's: more columns than firings in a turn
  VelodyneScanAssembler assembler(VelodynePacketDecoder(VelodyneModel::kVlp32c, calibration),
                                  calibration, settings);
  const std::vector<uint8_t> packet = synthetic_packet(1000, 20, 2500, 0x39, 0x28, true);
  std::vector<VelodyneReturn> returns;
  VelodynePacketDecoder(VelodyneModel::kVlp32c, calibration).decode(packet.data(), returns);
  ASSERT_EQ(returns.size(), 12u * 32u);  // both returns of 6 firings
  // The two blocks of a firing share its time.
  EXPECT_EQ(returns[0].time_offset_s, returns[32].time_offset_s);
  assembler.add_packet(packet.data(), 1000000000);
  assembler.flush();
  const std::optional<Scan> scan = assembler.take();
  ASSERT_TRUE(scan.has_value());
  EXPECT_EQ(scan->valid_count(), 6u * 32u);
  for (size_t i = 0; i < scan->size(); ++i) {
    if (scan->valid[i]) {
      EXPECT_NEAR(scan->range_m[i], 3000 * 0.004, 1e-4);
    }
  }
  EXPECT_EQ(assembler.dual_return_packets(), 1u);
}

TEST(PacketContainers, Vlp16FiresTwiceABlock) {
  const VelodyneCalibration calibration = builtin_velodyne_calibration(VelodyneModel::kVlp16);
  VelodyneScanAssembler assembler(VelodynePacketDecoder(VelodyneModel::kVlp16, calibration),
                                  calibration, VelodyneScanSettings{});
  // 0.4 deg a block: two firings of 0.2 deg, as at 10 Hz.
  const std::vector<uint8_t> packet = synthetic_packet(9000, 40, 5000, 0x37, 0x22, false);
  std::vector<VelodyneReturn> returns;
  VelodynePacketDecoder(VelodyneModel::kVlp16, calibration).decode(packet.data(), returns);
  ASSERT_EQ(returns.size(), 12u * 32u);
  // Slot 16 is the first laser of the second firing: 55.296 us after slot 0.
  EXPECT_NEAR(returns[16].time_offset_s - returns[0].time_offset_s, 55.296e-6, 1e-9);
  EXPECT_NEAR(returns[32].time_offset_s - returns[0].time_offset_s, 110.592e-6, 1e-9);
  assembler.add_packet(packet.data(), 1000000000);
  assembler.flush();
  const std::optional<Scan> scan = assembler.take();
  ASSERT_TRUE(scan.has_value());
  EXPECT_EQ(scan->rows, 16);
  // Every firing in a column of its own: no two share a cell.
  EXPECT_EQ(scan->valid_count(), 12u * 32u);
  // Row 0 is the highest laser (+15 deg).
  for (int col = 0; col < scan->cols; ++col) {
    if (!scan->valid[scan->index(0, col)]) continue;
    const Eigen::Vector3f& p = scan->xyz[scan->index(0, col)];
    EXPECT_NEAR(std::atan2(p.z(), p.head<2>().norm()), 15.0 * M_PI / 180.0, 1e-4);
  }
}

TEST(PacketContainers, ModelFromThePresetWhereThePacketsNameNone) {
  FEATSENSE_SHARED_FILE(calibration, "velodyne/calibration/HDL64e_s3.yaml");
  // HDL-64E packets carry no product id; upper (FF EE) and lower (FF DD) blocks alternate.
  std::vector<test::CapturedFrame> frames;
  for (uint16_t p = 0; p < 40; ++p) {
    std::vector<uint8_t> packet =
        synthetic_packet(static_cast<uint16_t>(p * 120), 20, 5000, 0x37, 0x00, /*dual_pairs=*/true);
    for (size_t block = 1; block < kVelodyneBlocks; block += 2) {
      packet[block * kVelodyneBlockBytes + 1] = 0xDD;
    }
    test::CapturedFrame frame;
    frame.seconds = 1700000000;
    frame.fraction = p * 300u;
    frame.bytes = test::ethernet_ipv4_udp(packet, 2368, p);
    frames.push_back(std::move(frame));
  }
  const auto dir = test::scratch_dir("velodyne_preset");
  test::write_file(dir / "hdl64.pcap", test::write_pcap(frames));
  try {
    open_scan_source((dir / "hdl64.pcap").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("set sensor.preset"), std::string::npos) << e.what();
  }
  SourceOptions options;
  options.sensor_preset = "hdl64";
  try {
    open_scan_source((dir / "hdl64.pcap").string(), options);
    FAIL() << "no error";
  } catch (const InputError& e) {  // no built-in table for the HDL-64E
    EXPECT_NE(std::string(e.what()).find("sensor.calibration"), std::string::npos) << e.what();
  }
  options.velodyne_calibration = calibration.string();
  std::unique_ptr<ScanSource> source = open_scan_source((dir / "hdl64.pcap").string(), options);
  EXPECT_NE(source->info().detail.find("HDL-64E (sensor.preset hdl64)"), std::string::npos)
      << source->info().detail;
  const std::vector<Scan> scans = all_scans(*source);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].rows, 64);
  EXPECT_EQ(scans[0].valid_count(), 40u * 6u * 64u);
}

TEST(PacketContainers, ScansBeginAtTheCutAngle) {
  FEATSENSE_SHARED_FILE(bag, kVelodyneBag);
  // Cut at 0 deg, inside the fired sector (270 .. 90): a scan is a turn from the front to
  // the front, the right quarter (0 .. 90 deg) of one sweep, then the silent back half, then
  // the left quarter (270 .. 360) of the next.
  SourceOptions options;
  options.scan_cut_deg = 0.0;
  std::unique_ptr<ScanSource> source = open_scan_source(bag.string(), options);
  const std::vector<Scan> scans = all_scans(*source);
  ASSERT_EQ(scans.size(), 6u);  // the first sweep's left quarter, then five turns
  for (size_t s = 0; s < scans.size(); ++s) {
    float last = 0.0f;
    for (size_t i = 0; i < scans[s].size(); ++i) {
      if (!scans[s].valid[i]) continue;
      last = std::max(last, scans[s].time_offset_s[i]);
      // Right of the sensor (y < 0) first, left of it a half turn later.
      if (scans[s].xyz[i].y() < -1.0f) {
        EXPECT_LT(scans[s].time_offset_s[i], 0.03f);
      }
      if (s > 0 && scans[s].xyz[i].y() > 1.0f) {
        EXPECT_GT(scans[s].time_offset_s[i], 0.07f);
      }
    }
    EXPECT_LT(last, s == 0 ? 0.03f : 0.105f);
  }
}

}  // namespace
}  // namespace featsense::slam
