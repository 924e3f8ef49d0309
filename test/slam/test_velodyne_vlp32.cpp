// The Velodyne decoder against a real recording: the VLP-32C packets of a ROS 2 bag, decoded
// as tier4/nebula did for its expected cloud (its rules are in the data's README), must give
// the same points; the bag and a pcap written from its packet bytes must give the same scans.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/slam/io/live_source.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "ros2/sqlite_bag_log.hpp"
#include "slam/pcap_test_util.hpp"
#include "slam/udp_test_util.hpp"
#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_packet.hpp"
#include "velodyne/velodyne_scan_message.hpp"

namespace featsense::slam {
namespace {

constexpr const char* kBag = "ros2/vlp32_packets/1713492677464078412";
constexpr const char* kDb3 = "ros2/vlp32_packets/1713492677464078412/1713492677464078412_0.db3";
constexpr const char* kExpected = "ros2/vlp32_packets/expected_points.pcd";
constexpr const char* kCalibration = "velodyne/calibration/VLP32.yaml";

/// Packets of every message, in order, copied out of the bag.
struct BagPackets {
  std::vector<std::vector<std::vector<uint8_t>>> messages;  ///< message -> packet -> bytes
  std::vector<std::vector<int64_t>> stamps;
};

BagPackets read_packets(const std::filesystem::path& db3) {
  std::unique_ptr<MessageLog> log = open_sqlite_bag_file(db3.string());
  const BagTopic& topic = log->catalog().topics.at(0);
  std::unique_ptr<MessageCursor> cursor = log->open(topic, [](const std::string&) {});
  BagPackets out;
  while (const std::optional<BagMessage> message = cursor->next()) {
    const VelodyneScanView scan = parse_velodyne_scan(message->data, topic.encoding);
    out.messages.emplace_back();
    out.stamps.emplace_back();
    for (const VelodynePacketView& p : scan.packets) {
      out.messages.back().emplace_back(p.data.data, p.data.data + p.data.size);
      out.stamps.back().push_back(p.stamp_ns);
    }
  }
  return out;
}

/// x y z of a binary PCD holding only those three float fields.
std::vector<Eigen::Vector3f> read_xyz_pcd(const std::filesystem::path& path) {
  const std::string bytes = test::read_file(path);
  const size_t data = bytes.find("DATA binary\n");
  if (data == std::string::npos) throw std::runtime_error("not a binary PCD");
  const size_t start = data + std::strlen("DATA binary\n");
  std::vector<Eigen::Vector3f> points((bytes.size() - start) / 12);
  for (size_t i = 0; i < points.size(); ++i) {
    float xyz[3];
    std::memcpy(xyz, bytes.data() + start + 12 * i, sizeof xyz);
    points[i] = Eigen::Vector3f(xyz[0], xyz[1], xyz[2]);
  }
  return points;
}

VelodyneCalibration calibration_file(const std::filesystem::path& path) {
  return parse_velodyne_calibration(test::read_file(path), path.string(), VelodyneModel::kVlp32c);
}

/// The reference's selection: kept azimuths 270 .. 90 deg (block azimuth, both inclusive),
/// distances in (0.4, 50) m.
bool reference_keeps(const VelodyneReturn& r) {
  const bool angle = r.block_azimuth >= 27000 || r.block_azimuth <= 9000;
  return angle && r.distance_m > 0.4f && r.distance_m < 50.0f;
}

/// Distance from each expected point to the nearest decoded one (a 5 cm hash grid).
std::vector<double> nearest_distances(const std::vector<Eigen::Vector3f>& expected,
                                      const std::vector<Eigen::Vector3f>& decoded) {
  constexpr double kCell = 0.05;
  auto key = [](const Eigen::Vector3f& p, int dx, int dy, int dz) {
    const auto c = [](float v) { return static_cast<int64_t>(std::floor(v / kCell)); };
    return ((c(p.x()) + dx) * 73856093) ^ ((c(p.y()) + dy) * 19349663) ^
           ((c(p.z()) + dz) * 83492791);
  };
  std::multimap<int64_t, size_t> grid;
  for (size_t i = 0; i < decoded.size(); ++i) grid.emplace(key(decoded[i], 0, 0, 0), i);
  std::vector<double> out;
  for (const Eigen::Vector3f& p : expected) {
    double best = 1e9;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto range = grid.equal_range(key(p, dx, dy, dz));
          for (auto it = range.first; it != range.second; ++it) {
            best = std::min(best, static_cast<double>((decoded[it->second] - p).norm()));
          }
        }
      }
    }
    out.push_back(best);
  }
  return out;
}

TEST(VelodyneVlp32, DecodesTheFirstMessageLikeTheReference) {
  FEATSENSE_SHARED_FILE(db3, kDb3);
  FEATSENSE_SHARED_FILE(expected_path, kExpected);
  FEATSENSE_SHARED_FILE(calibration_path, kCalibration);
  const BagPackets bag = read_packets(db3);
  ASSERT_EQ(bag.messages.size(), 5u);
  ASSERT_EQ(bag.messages[0].size(), 76u);
  const std::vector<Eigen::Vector3f> expected = read_xyz_pcd(expected_path);
  ASSERT_EQ(expected.size(), 26216u);

  for (const bool builtin : {false, true}) {
    SCOPED_TRACE(builtin ? "built-in table" : "VLP32.yaml");
    const VelodyneCalibration calibration =
        builtin ? builtin_velodyne_calibration(VelodyneModel::kVlp32c)
                : calibration_file(calibration_path);
    VelodynePacketDecoder decoder(VelodyneModel::kVlp32c, calibration);
    std::vector<VelodyneReturn> returns;
    for (const std::vector<uint8_t>& packet : bag.messages[0]) {
      ASSERT_EQ(packet[kVelodyneProductIdByte], 0x28);
      decoder.decode(packet.data(), returns);
    }
    EXPECT_EQ(returns.size(), 26330u);  // the README's non-zero returns
    std::vector<Eigen::Vector3f> kept;
    for (const VelodyneReturn& r : returns) {
      if (reference_keeps(r)) kept.push_back(r.xyz);
    }
    EXPECT_EQ(kept.size(), expected.size());
    std::vector<double> distances = nearest_distances(expected, kept);
    std::sort(distances.begin(), distances.end());
    const double median = distances[distances.size() / 2];
    const double p99 = distances[distances.size() * 99 / 100];
    const double worst = distances.back();
    size_t same_order_within_1mm = 0;
    for (size_t i = 0; i < std::min(kept.size(), expected.size()); ++i) {
      if ((kept[i] - expected[i]).norm() <= 1e-3) ++same_order_within_1mm;
    }
    std::printf(
        "decoded %zu kept %zu expected %zu; nearest: median %.3g m, p99 %.3g m, max %.3g "
        "m; same index within 1 mm: %zu\n",
        returns.size(), kept.size(), expected.size(), median, p99, worst, same_order_within_1mm);
    EXPECT_LE(median, 1e-3);
    EXPECT_LE(worst, 1e-2);
  }
}

/// Every scan of a source, in order.
std::vector<Scan> all_scans(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

SourceOptions reference_options(const std::filesystem::path& calibration) {
  SourceOptions options;
  options.velodyne_calibration = calibration.string();
  options.scan_cut_deg = 180.0;
  options.min_range_m = 0.4;
  options.max_range_m = 50.0;
  return options;
}

TEST(VelodyneVlp32, BagGivesOrganizedTimedScans) {
  FEATSENSE_SHARED_FILE(bag, kBag);
  FEATSENSE_SHARED_FILE(calibration_path, kCalibration);
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<ScanSource> source =
      open_scan_source(bag.string(), reference_options(calibration_path));
  EXPECT_EQ(source->info().format, "ros2-bag");
  EXPECT_NE(source->info().detail.find("VLP-32C (product id 0x28)"), std::string::npos)
      << source->info().detail;
  ASSERT_EQ(source->info().topics.size(), 1u);
  const std::vector<Scan> scans = all_scans(*source);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Five sweeps of the front half, each cut where the azimuth jumps back from 90 to 270 deg,
  // and the start of a sixth: the last blocks of the last packet.
  ASSERT_EQ(scans.size(), 6u);
  EXPECT_LT(scans[5].valid_count(), 12u * 32u);
  EXPECT_EQ(source->stats().warning_count, 0u);
  size_t points = 0;
  for (size_t s = 0; s < 5; ++s) {
    const Scan& scan = scans[s];
    EXPECT_EQ(scan.rows, 32);
    EXPECT_EQ(scan.cols, 1900);
    points += scan.valid_count();
    float max_time = 0.0f;
    for (size_t i = 0; i < scan.size(); ++i) {
      if (scan.valid[i]) max_time = std::max(max_time, scan.time_offset_s[i]);
    }
    // Half a turn at 10 Hz: about 50 ms of firings.
    EXPECT_GT(max_time, 0.03f);
    EXPECT_LT(max_time, 0.08f);
  }
  // The first scan holds message 1's sweep: the reference's 26,216 points less the four
  // blocks of the last packet that already belong to the next sweep (cut here at the
  // block, there at the packet); 1900 columns a turn leave no two firings one cell.
  const size_t first = scans[0].valid_count();
  std::printf(
      "first scan %zu valid points (reference 26216); 5 sweeps %zu points, read in %.3f s\n", first,
      points, seconds);
  EXPECT_GE(first, 26216u - 4 * 32);
  EXPECT_LE(first, 26216u);
  EXPECT_LT(scans[0].stamp_ns, scans[1].stamp_ns);
}

TEST(VelodyneVlp32, PcapOfTheSamePacketsGivesTheSameScans) {
  FEATSENSE_SHARED_FILE(bag, kBag);
  FEATSENSE_SHARED_FILE(db3, kDb3);
  FEATSENSE_SHARED_FILE(calibration_path, kCalibration);
  const BagPackets packets = read_packets(db3);
  std::vector<test::CapturedFrame> frames;
  uint16_t id = 0;
  for (size_t m = 0; m < packets.messages.size(); ++m) {
    for (size_t p = 0; p < packets.messages[m].size(); ++p) {
      test::CapturedFrame frame;
      const int64_t ns = packets.stamps[m][p];
      frame.seconds = static_cast<uint32_t>(ns / 1000000000);
      frame.fraction = static_cast<uint32_t>(ns % 1000000000);
      frame.bytes = test::ethernet_ipv4_udp(packets.messages[m][p], 2368, id++);
      frames.push_back(std::move(frame));
      // A position packet (512 bytes, port 8308) now and then, which the reader passes over.
      if (p % 20 == 0) {
        test::CapturedFrame position = frames.back();
        position.bytes = test::ethernet_ipv4_udp(std::vector<uint8_t>(512, 0), 8308, id++);
        frames.push_back(std::move(position));
      }
    }
  }
  test::PcapWriteOptions pcap_options;
  pcap_options.nanoseconds = true;
  const auto dir = test::scratch_dir("velodyne_pcap");
  test::write_file(dir / "vlp32.pcap", test::write_pcap(frames, pcap_options));

  std::unique_ptr<ScanSource> from_pcap =
      open_scan_source((dir / "vlp32.pcap").string(), reference_options(calibration_path));
  EXPECT_EQ(from_pcap->info().format, "velodyne-pcap");
  std::unique_ptr<ScanSource> from_bag =
      open_scan_source(bag.string(), reference_options(calibration_path));
  const std::vector<Scan> a = all_scans(*from_pcap);
  const std::vector<Scan> b = all_scans(*from_bag);
  ASSERT_EQ(a.size(), b.size());
  for (size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].stamp_ns, b[s].stamp_ns);
    ASSERT_EQ(a[s].valid, b[s].valid);
    EXPECT_EQ(a[s].xyz, b[s].xyz);
    EXPECT_EQ(a[s].time_offset_s, b[s].time_offset_s);
  }
}

TEST(VelodyneVlp32, PacketsOverTheNetworkGiveTheBagsScans) {
  FEATSENSE_SHARED_FILE(bag, kBag);
  FEATSENSE_SHARED_FILE(db3, kDb3);
  FEATSENSE_SHARED_FILE(calibration_path, kCalibration);
  const BagPackets packets = read_packets(db3);
  LiveOptions live;
  live.sensor = LiveSensor::kVelodyne;
  live.host = "127.0.0.1";
  live.lidar_port = test::free_udp_port();
  live.idle_timeout_s = 1.0;
  // Sent at the recorded pace: the reader clocks the sensor's time by the receive time.
  std::vector<test::Outgoing> out;
  std::vector<int64_t> times;
  for (size_t m = 0; m < packets.messages.size(); ++m) {
    for (size_t p = 0; p < packets.messages[m].size(); ++p) {
      out.push_back({*live.lidar_port, packets.messages[m][p]});
      times.push_back(packets.stamps[m][p]);
    }
  }
  // Sending starts once the socket is bound (the opener waits for the first packet).
  std::thread sender;
  live.on_listening = [&](const std::string&) {
    sender = std::thread(test::send_paced, std::cref(out), std::cref(times));
  };
  std::unique_ptr<ScanSource> from_network =
      open_live_source(live, reference_options(calibration_path));
  EXPECT_EQ(from_network->info().format, "velodyne-live");
  const std::vector<Scan> a = all_scans(*from_network);
  sender.join();
  std::unique_ptr<ScanSource> from_bag =
      open_scan_source(bag.string(), reference_options(calibration_path));
  const std::vector<Scan> b = all_scans(*from_bag);
  ASSERT_EQ(a.size(), b.size());
  // The same points. The times are the sensor's clock placed by the smallest delay of
  // reception seen so far (velodyne_scan_assembler.cpp): the same as recorded within the
  // sending's jitter once a packet came without delay, which a busy machine may put off for
  // the first scans. The stamps are the receiver's clock (now, not then): compared as intervals.
  constexpr double kJitterS = 2e-3;
  constexpr size_t kSettledScan = 2;
  ASSERT_GT(a.size(), kSettledScan + 2);
  for (size_t s = 0; s < a.size(); ++s) {
    ASSERT_EQ(a[s].valid, b[s].valid);
    EXPECT_EQ(a[s].xyz, b[s].xyz);
    if (s < kSettledScan) continue;
    if (s > kSettledScan) {
      EXPECT_NEAR(1e-9 * static_cast<double>(a[s].stamp_ns - a[s - 1].stamp_ns),
                  1e-9 * static_cast<double>(b[s].stamp_ns - b[s - 1].stamp_ns), kJitterS);
    }
    double worst = 0.0;
    for (size_t i = 0; i < a[s].size(); ++i) {
      if (a[s].valid[i]) {
        worst = std::max(
            worst, std::abs(static_cast<double>(a[s].time_offset_s[i]) - b[s].time_offset_s[i]));
      }
    }
    EXPECT_LT(worst, kJitterS) << "scan " << s;
  }
}

TEST(VelodyneVlp32, CalibrationProblemsAreNamed) {
  const auto dir = test::scratch_dir("velodyne_calibration");
  test::write_file(dir / "short.yaml",
                   "lasers:\n  - {laser_id: 0, rot_correction: 0, vert_correction: 0}\n");
  try {
    parse_velodyne_calibration(test::read_file(dir / "short.yaml"), "short.yaml",
                               VelodyneModel::kVlp32c);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lists 1 lasers"), std::string::npos) << e.what();
  }
  EXPECT_THROW(builtin_velodyne_calibration(VelodyneModel::kHdl64e), InputError);
}

}  // namespace
}  // namespace featsense::slam
