// Live input: datagrams sent over the loopback interface to a live source must give exactly
// the scans its pcap reader gives for the same packets, and the receiver's limits (a full
// buffer, silence, a stop, a port in use) must each end or warn as documented.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/test_data.hpp"
#include "featsense/slam/io/live_source.hpp"
#include "featsense/slam/io/pcap_replay.hpp"
#include "featsense/slam/io/readers.hpp"
#include "net/udp_receiver.hpp"
#include "ouster/pcap_udp_reader.hpp"
#include "slam/udp_test_util.hpp"

namespace featsense::slam {
namespace {

constexpr const char* kOs1Pcap = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";
constexpr const char* kOs1Json = "ouster/OS-1-128_v2.3.0_1024x10.json";

std::vector<Scan> all_scans(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

detail::UdpListenSettings loopback(std::vector<int> ports) {
  detail::UdpListenSettings s;
  s.host = "127.0.0.1";
  s.ports = std::move(ports);
  s.idle_timeout_s = 0.5;
  return s;
}

/// An Ouster live source's options: two free ports of 127.0.0.1, the input ending after
/// `idle_s` seconds without a datagram.
LiveOptions loopback_ouster(double idle_s) {
  LiveOptions live;
  live.host = "127.0.0.1";
  live.lidar_port = test::free_udp_port();
  live.imu_port = test::free_udp_port();
  live.idle_timeout_s = idle_s;
  return live;
}

/// The capture's datagrams, each to `live`'s port for its kind (IMU packets were on 7503).
std::vector<test::Outgoing> addressed_to(const std::filesystem::path& pcap,
                                         const LiveOptions& live) {
  std::vector<test::Outgoing> out;
  std::ifstream stream(pcap, std::ios::binary);
  detail::PcapUdpReader reader(stream, pcap.string());
  while (const std::optional<detail::UdpDatagram> d = reader.next()) {
    out.push_back({d->destination_port == 7503 ? *live.imu_port : *live.lidar_port,
                   std::vector<uint8_t>(d->payload, d->payload + d->size)});
  }
  return out;
}

TEST(UdpReceiver, HandsOutDatagramsInOrderWithTheirPort) {
  const int a = test::free_udp_port();
  const int b = test::free_udp_port();
  detail::UdpReceiver receiver(loopback({a, b}));
  std::vector<test::Outgoing> out;
  for (uint8_t i = 0; i < 20; ++i)
    out.push_back({i % 2 == 0 ? a : b, std::vector<uint8_t>(100 + i, i)});
  test::send_all(out, std::chrono::microseconds(200));
  // In order per port (the receive thread empties one socket, then the other).
  std::vector<uint8_t> on_a, on_b;
  for (int i = 0; i < 20; ++i) {
    const std::optional<detail::UdpDatagram> d = receiver.next();
    ASSERT_TRUE(d);
    EXPECT_EQ(d->size, 100u + d->payload[0]);
    EXPECT_GT(d->timestamp_ns, 0);
    (d->destination_port == a ? on_a : on_b).push_back(d->payload[0]);
  }
  EXPECT_EQ(on_a, std::vector<uint8_t>({0, 2, 4, 6, 8, 10, 12, 14, 16, 18}));
  EXPECT_EQ(on_b, std::vector<uint8_t>({1, 3, 5, 7, 9, 11, 13, 15, 17, 19}));
  // Then silence: the idle timeout ends the input, and says so.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(receiver.next());
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(450));
  ASSERT_TRUE(receiver.problem());
  EXPECT_NE(receiver.problem()->find("no datagram for"), std::string::npos);
  EXPECT_TRUE(receiver.end_warnings().empty());
}

TEST(UdpReceiver, AFullBufferDropsAndCountsInsteadOfGrowing) {
  const int port = test::free_udp_port();
  detail::UdpListenSettings settings = loopback({port});
  settings.buffer_datagrams = 10;
  detail::UdpReceiver receiver(settings);
  std::vector<test::Outgoing> out(50, test::Outgoing{port, std::vector<uint8_t>(64, 7)});
  test::send_all(out, std::chrono::microseconds(100));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // all received, none read
  size_t read = 0;
  while (receiver.next()) ++read;
  EXPECT_EQ(read, 10u);
  EXPECT_EQ(receiver.stats().received, 50u);
  EXPECT_EQ(receiver.stats().dropped_full, 40u);
  ASSERT_EQ(receiver.end_warnings().size(), 1u);
  EXPECT_NE(receiver.end_warnings()[0].find("40 of 50 datagrams dropped"), std::string::npos)
      << receiver.end_warnings()[0];
}

TEST(UdpReceiver, AStopEndsTheWaitWithoutADatagram) {
  detail::UdpListenSettings settings = loopback({test::free_udp_port()});
  settings.idle_timeout_s = 0.0;  // only the stop ends it
  const auto start = std::chrono::steady_clock::now();
  settings.stop_requested = [start] {
    return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(300);
  };
  detail::UdpReceiver receiver(settings);
  EXPECT_FALSE(receiver.next());
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_EQ(receiver.problem(), std::optional<std::string>("stopped"));
}

TEST(UdpReceiver, APortInUseIsOneClearError) {
  const int port = test::free_udp_port();
  detail::UdpReceiver first(loopback({port}));
  try {
    detail::UdpReceiver second(loopback({port}));
    FAIL() << "a second receiver bound the same port";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot listen on 127.0.0.1:" + std::to_string(port)), std::string::npos)
        << what;
    EXPECT_NE(what.find("another program receives there"), std::string::npos) << what;
  }
  EXPECT_THROW(detail::UdpReceiver(loopback({70000})), InputError);
  detail::UdpListenSettings bad_host = loopback({port});
  bad_host.host = "not-an-address";
  EXPECT_THROW(detail::UdpReceiver{bad_host}, InputError);
}

TEST(LiveSource, OusterWithoutMetadataIsAnError) {
  LiveOptions live;
  live.host = "127.0.0.1";
  live.lidar_port = test::free_udp_port();
  try {
    open_live_source(live, {});
    FAIL() << "opened without metadata";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--meta FILE"), std::string::npos) << e.what();
  }
}

TEST(LiveSource, OusterPacketsOverTheNetworkGiveThePcapsScans) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  SourceOptions options;
  options.meta_path = json.string();
  const std::vector<Scan> expected = all_scans(*open_scan_source(pcap.string(), options));
  ASSERT_EQ(expected.size(), 3u);

  const LiveOptions live = loopback_ouster(1.0);
  const std::vector<test::Outgoing> out = addressed_to(pcap, live);
  std::unique_ptr<ScanSource> source = open_live_source(live, options);
  EXPECT_EQ(source->info().format, "ouster-live");
  EXPECT_EQ(source->info().sensor.beams, 128);
  std::thread sender(test::send_all, std::cref(out), std::chrono::microseconds(1350));
  const std::vector<Scan> got = all_scans(*source);
  sender.join();
  ASSERT_EQ(got.size(), expected.size());
  for (size_t k = 0; k < got.size(); ++k) {
    // The stamps are the sensor's, from the packets: the same as recorded.
    EXPECT_EQ(got[k].stamp_ns, expected[k].stamp_ns);
    EXPECT_EQ(got[k].valid, expected[k].valid);
    EXPECT_EQ(got[k].xyz, expected[k].xyz);
    EXPECT_EQ(got[k].time_offset_s, expected[k].time_offset_s);
  }
  EXPECT_EQ(source->stats().warning_count, 0u) << source->stats().warnings.front();
}

/// The OS1-128 metadata with `key` set to `value`, written into the test's folder.
std::filesystem::path os1_metadata_with(const std::filesystem::path& json, const std::string& key,
                                        const nlohmann::json& value, const std::string& name) {
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(json));
  doc[key] = value;
  const std::filesystem::path path = test::scratch_dir(name) / "meta.json";
  std::ofstream(path) << doc.dump();
  return path;
}

TEST(LiveSource, AnotherSensorsPacketsOnThePortAreSkippedAndCounted) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  SourceOptions options;
  options.meta_path = json.string();
  const std::vector<Scan> expected = all_scans(*open_scan_source(pcap.string(), options));
  const LiveOptions live = loopback_ouster(1.0);
  // Every lidar packet twice: as recorded, and as a second unit (serial + 1) would send it.
  std::vector<test::Outgoing> out;
  for (test::Outgoing& recorded : addressed_to(pcap, live)) {
    out.push_back(recorded);
    if (recorded.bytes.size() == 8448) {
      ++recorded.bytes[7];  // the serial's lowest byte (PACKET_FORMAT.md)
      out.push_back(std::move(recorded));
    }
  }
  std::unique_ptr<ScanSource> source = open_live_source(live, options);
  std::thread sender(test::send_all, std::cref(out), std::chrono::microseconds(700));
  const std::vector<Scan> got = all_scans(*source);
  sender.join();
  ASSERT_EQ(got.size(), expected.size());
  for (size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].xyz, expected[k].xyz);
  ASSERT_EQ(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings[0].find("192 lidar packets from another sensor (serial "
                                             "122201000999) than the metadata's (serial "
                                             "122201000998"),
            std::string::npos)
      << source->stats().warnings[0];
}

TEST(LiveSource, MetadataOfAnotherUnitIsOneClearError) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  SourceOptions options;
  options.meta_path = os1_metadata_with(json, "prod_sn", "122201000123", "meta_other_unit");
  try {
    all_scans(*open_scan_source(pcap.string(), options));
    FAIL() << "read another unit's packets";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("all 192 lidar packets from another sensor (serial 122201000998)"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("is the metadata this sensor's?"), std::string::npos) << what;
  }
  // The same unit initialized again since its metadata was written: read, warned once.
  options.meta_path = os1_metadata_with(json, "initialization_id", 7109751, "meta_reinitialized");
  std::unique_ptr<ScanSource> source = open_scan_source(pcap.string(), options);
  EXPECT_EQ(all_scans(*source).size(), 3u);
  ASSERT_EQ(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings[0].find("initialization id 7109750 is not the metadata's"),
            std::string::npos)
      << source->stats().warnings[0];
}

TEST(LiveSource, ASilentOusterEndsWithTheNoPacketsError) {
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  SourceOptions options;
  options.meta_path = json.string();
  std::unique_ptr<ScanSource> source = open_live_source(loopback_ouster(0.3), options);
  try {
    source->next();
    FAIL() << "a scan from silence";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no lidar packets"), std::string::npos) << what;
    EXPECT_NE(what.find("no datagram for"), std::string::npos) << what;
  }
}

TEST(LiveSource, ASilentVelodyneIsOneClearError) {
  LiveOptions live;
  live.sensor = LiveSensor::kVelodyne;
  live.host = "127.0.0.1";
  live.lidar_port = test::free_udp_port();
  live.idle_timeout_s = 0.3;
  try {
    open_live_source(live, {});
    FAIL() << "opened from silence";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no Velodyne data packet"), std::string::npos) << e.what();
  }
}

/// Replays the OS1-128 capture into a live source on free ports and returns its scans.
struct ReplayedOs1 {
  std::vector<Scan> scans;
  ReadStats stats;
  ReplayResult replay;
};

ReplayedOs1 replay_os1(const std::filesystem::path& pcap, const std::filesystem::path& json,
                       ReplaySettings settings) {
  SourceOptions options;
  options.meta_path = json.string();
  const LiveOptions live = loopback_ouster(1.0);
  std::unique_ptr<ScanSource> source = open_live_source(live, options);
  settings.ports = {{7502, *live.lidar_port}, {7503, *live.imu_port}};
  ReplayedOs1 out;
  std::thread sender([&] { out.replay = replay_pcap(pcap.string(), settings); });
  out.scans = all_scans(*source);
  sender.join();
  out.stats = source->stats();
  return out;
}

TEST(PcapReplay, ReplayedToALiveSourceGivesThePcapsScans) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  SourceOptions options;
  options.meta_path = json.string();
  const std::vector<Scan> expected = all_scans(*open_scan_source(pcap.string(), options));
  // At the sensor's pace: a receive buffer of the kernel's default size (208 KB, 28 of these
  // packets) must not overflow on a busy machine.
  const ReplayedOs1 got = replay_os1(pcap, json, {});
  EXPECT_EQ(got.replay.sent, 222u);  // every UDP datagram of the capture
  EXPECT_EQ(got.replay.passes, 1u);
  EXPECT_NEAR(got.replay.recording_seconds, 0.2985, 0.001);
  EXPECT_GT(got.replay.seconds, 0.29);  // the recorded timing, not faster
  EXPECT_LT(got.replay.seconds, 2.0);
  ASSERT_EQ(got.scans.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(got.scans[k].stamp_ns, expected[k].stamp_ns);
    EXPECT_EQ(got.scans[k].xyz, expected[k].xyz);
  }
}

TEST(PcapReplay, DroppedDatagramsLeaveIncompleteFramesWithWarnings) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  ReplaySettings settings;
  settings.drop_fraction = 0.2;
  settings.seed = 7;
  const ReplayedOs1 got = replay_os1(pcap, json, settings);
  EXPECT_EQ(got.replay.sent + got.replay.dropped, 222u);
  EXPECT_GT(got.replay.dropped, 20u);
  EXPECT_LT(got.replay.dropped, 70u);
  // The frames come, short of the dropped packets' columns, each with a warning.
  ASSERT_GE(got.scans.size(), 2u);
  EXPECT_GT(got.stats.warning_count, 0u);
  for (const Scan& scan : got.scans) EXPECT_LT(scan.valid_count(), 107000u);
  // The same seed drops the same datagrams.
  const ReplayedOs1 again = replay_os1(pcap, json, settings);
  EXPECT_EQ(again.replay.dropped, got.replay.dropped);
}

TEST(PcapReplay, SettingsOutOfRangeAndEmptyCapturesAreErrors) {
  const auto dir = test::scratch_dir("pcap_replay");
  const std::filesystem::path empty = dir / "empty.pcap";
  {
    // A pcap global header (little-endian, microseconds, Ethernet) and no record.
    const uint8_t header[24] = {0xd4, 0xc3, 0xb2, 0xa1, 2, 0, 4, 0, 0, 0, 0, 0,
                                0,    0,    0,    0,    0, 0, 4, 0, 1, 0, 0, 0};
    std::ofstream(empty, std::ios::binary).write(reinterpret_cast<const char*>(header), 24);
  }
  try {
    replay_pcap(empty.string(), {});
    FAIL() << "replayed an empty capture";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no UDP datagram to replay"), std::string::npos)
        << e.what();
  }
  ReplaySettings bad;
  bad.rate = 0.0;
  EXPECT_THROW(replay_pcap(empty.string(), bad), InputError);
  bad = {};
  bad.drop_fraction = 1.0;
  EXPECT_THROW(replay_pcap(empty.string(), bad), InputError);
  bad = {};
  bad.host = "localhost";  // an address, not a name
  EXPECT_THROW(replay_pcap(empty.string(), bad), InputError);
  bad = {};
  bad.ports = {{7502, 0}};
  EXPECT_THROW(replay_pcap(empty.string(), bad), InputError);
}

}  // namespace
}  // namespace featsense::slam
