// The IMU's samples of Ouster recordings: the 48-byte packet decoded from bytes laid out
// here by the legacy IMU packet format, the samples' assignment to sweeps, and the real
// capture of ../shared/data/ouster, whose IMU packets arrive on UDP port 7503.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/slam/io/readers.hpp"
#include "imu_sweep_assigner.hpp"
#include "ouster/ouster_imu_packet.hpp"
#include "pcap_test_util.hpp"

namespace featsense::slam {
namespace {

constexpr const char* kOs1Pcap = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";
constexpr const char* kOs1Json = "ouster/OS-1-128_v2.3.0_1024x10.json";
constexpr double kG = 9.80665;
constexpr double kDeg = M_PI / 180.0;

template <typename T>
void append(std::vector<uint8_t>& bytes, T value) {
  uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));  // the test host is little-endian, as the packets are
  bytes.insert(bytes.end(), raw, raw + sizeof(T));
}

/// A legacy IMU packet: system, accelerometer and gyroscope times (ns), then the
/// accelerometer (g) and the gyroscope (deg/s), x y z each.
std::vector<uint8_t> imu_packet(uint64_t gyro_ns, const Eigen::Vector3f& accel_g,
                                const Eigen::Vector3f& gyro_dps) {
  std::vector<uint8_t> bytes;
  append<uint64_t>(bytes, gyro_ns - 500);
  append<uint64_t>(bytes, gyro_ns - 200);
  append<uint64_t>(bytes, gyro_ns);
  for (int i = 0; i < 3; ++i) append<float>(bytes, accel_g[i]);
  for (int i = 0; i < 3; ++i) append<float>(bytes, gyro_dps[i]);
  return bytes;
}

ImuSample sample_at(int64_t stamp_ns) {
  ImuSample sample;
  sample.stamp_ns = stamp_ns;
  return sample;
}

Scan scan_at(int64_t stamp_ns) {
  Scan scan;
  scan.stamp_ns = stamp_ns;
  return scan;
}

std::vector<int64_t> stamps(const Scan& scan) {
  std::vector<int64_t> out;
  for (const ImuSample& sample : scan.imu) out.push_back(sample.stamp_ns);
  return out;
}

TEST(OusterImuPacket, UnitsAndTimestampWithIdentity) {
  const std::vector<uint8_t> packet =
      imu_packet(123456789012345, Eigen::Vector3f(0.5f, -0.25f, 1.0f), Eigen::Vector3f(90, 0, -45));
  ASSERT_EQ(packet.size(), 48u);
  const std::optional<ImuSample> sample =
      detail::decode_ouster_imu_packet(packet.data(), packet.size(), Eigen::Matrix3d::Identity());
  ASSERT_TRUE(sample);
  EXPECT_EQ(sample->stamp_ns, 123456789012345);  // the gyroscope's time
  EXPECT_NEAR(sample->accel_mps2.x(), 0.5 * kG, 1e-6);
  EXPECT_NEAR(sample->accel_mps2.y(), -0.25 * kG, 1e-6);
  EXPECT_NEAR(sample->accel_mps2.z(), kG, 1e-6);
  EXPECT_NEAR(sample->gyro_radps.x(), M_PI / 2, 1e-6);
  EXPECT_NEAR(sample->gyro_radps.y(), 0.0, 1e-12);
  EXPECT_NEAR(sample->gyro_radps.z(), -M_PI / 4, 1e-6);
}

TEST(OusterImuPacket, TurnedByTheMetadatasImuToSensorRotation) {
  // imu_to_sensor: a quarter turn about z (x_imu -> y_sensor) with a lever arm, which only
  // the rotation may touch.
  OusterMetadata metadata;
  metadata.imu_to_sensor = {0, -1, 0, 6.253, 1, 0, 0, -11.775, 0, 0, 1, 7.645, 0, 0, 0, 1};
  const Eigen::Matrix3d rotation = detail::ouster_imu_to_sensor_rotation(metadata);
  EXPECT_TRUE(rotation.isApprox(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));

  const std::vector<uint8_t> packet =
      imu_packet(1000, Eigen::Vector3f(1.0f, 0.0f, 0.0f), Eigen::Vector3f(0, 10, 0));
  const std::optional<ImuSample> sample =
      detail::decode_ouster_imu_packet(packet.data(), packet.size(), rotation);
  ASSERT_TRUE(sample);
  EXPECT_TRUE(sample->accel_mps2.isApprox(Eigen::Vector3d(0, kG, 0), 1e-6))
      << sample->accel_mps2.transpose();
  EXPECT_TRUE(sample->gyro_radps.isApprox(Eigen::Vector3d(-10 * kDeg, 0, 0), 1e-6))
      << sample->gyro_radps.transpose();
}

TEST(OusterImuPacket, WrongSizeIsRefused) {
  std::vector<uint8_t> packet = imu_packet(1000, Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero());
  EXPECT_FALSE(detail::decode_ouster_imu_packet(packet.data(), 47, Eigen::Matrix3d::Identity()));
  packet.push_back(0);
  EXPECT_FALSE(
      detail::decode_ouster_imu_packet(packet.data(), packet.size(), Eigen::Matrix3d::Identity()));
  EXPECT_FALSE(detail::decode_ouster_imu_packet(nullptr, 48, Eigen::Matrix3d::Identity()));
  const std::vector<uint8_t> nan =
      imu_packet(1000, Eigen::Vector3f(0.0f, std::nanf(""), 1.0f), Eigen::Vector3f::Zero());
  EXPECT_FALSE(
      detail::decode_ouster_imu_packet(nan.data(), nan.size(), Eigen::Matrix3d::Identity()));
}

TEST(ImuSweepAssigner, EachSampleGoesToTheSweepThatHoldsIt) {
  detail::ImuSweepAssigner imu(100);
  // Out of order, one before the first sweep, one exactly on the boundary of two sweeps.
  for (int64_t t : {1030, 990, 1100, 1000, 1050, 1199, 1150, 1250}) imu.add(sample_at(t));
  Scan first = scan_at(1000);
  EXPECT_FALSE(imu.covers(first));  // nothing a margin past 1100 yet
  imu.add(sample_at(1100 + 20'000'000));
  EXPECT_TRUE(imu.covers(first));
  imu.attach(first);
  EXPECT_EQ(stamps(first), (std::vector<int64_t>{1000, 1030, 1050}));
  EXPECT_EQ(imu.unassigned(), 1u);  // 990, before the first sweep

  imu.add(sample_at(1080));  // too late: its sweep has been handed out
  EXPECT_EQ(imu.late(), 1u);
  Scan second = scan_at(1100);
  imu.attach(second);
  EXPECT_EQ(stamps(second), (std::vector<int64_t>{1100, 1150, 1199}));
  EXPECT_EQ(imu.assigned(), 6u);
}

TEST(ImuSweepAssigner, OverlappingSweepsShareNothingAndGapsTakeNothing) {
  detail::ImuSweepAssigner imu(100);
  for (int64_t t : {0, 50, 95, 105, 150, 260, 330}) imu.add(sample_at(t));
  Scan a = scan_at(0);
  Scan b = scan_at(90);   // jitter: begins before a's sweep ends
  Scan c = scan_at(300);  // a sweep whose start was lost: 260 lies between sweeps
  imu.attach(a);
  imu.attach(b);
  imu.attach(c);
  EXPECT_EQ(stamps(a), (std::vector<int64_t>{0, 50, 95}));
  EXPECT_EQ(stamps(b), (std::vector<int64_t>{105, 150}));
  EXPECT_EQ(stamps(c), (std::vector<int64_t>{330}));
  EXPECT_EQ(imu.unassigned(), 1u);
}

TEST(ImuSweepAssigner, SamplesOfAnotherClockRaiseAWarning) {
  detail::ImuSweepAssigner imu(100);
  imu.add(sample_at(5));
  Scan scan = scan_at(1'000'000);
  imu.attach(scan);
  EXPECT_TRUE(scan.imu.empty());
  EXPECT_NE(detail::clock_mismatch_warning(imu, "x").find("clock"), std::string::npos);
}

std::vector<Scan> read_all(const std::string& path, const SourceOptions& options = {}) {
  std::unique_ptr<ScanSource> source = open_ouster_pcap(path, options);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  return scans;
}

TEST(OusterPcapImu, Os1SamplesComeWithTheirSweeps) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  const std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), {});
  EXPECT_NE(source->info().imu.find("7503"), std::string::npos) << source->info().imu;
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(source->stats().warning_count, 0u);

  // The capture's 30 IMU packets span 991.609 .. 991.899 s of the sensor's clock, the three
  // sweeps begin at 991.587, 991.687 and 991.787 s: 8, 10 and 10 samples, the last two
  // after the last sweep.
  std::vector<size_t> counts;
  std::vector<double> spacing_ms;
  for (const Scan& scan : scans) {
    counts.push_back(scan.imu.size());
    for (size_t i = 0; i < scan.imu.size(); ++i) {
      const ImuSample& sample = scan.imu[i];
      EXPECT_GE(sample.stamp_ns, scan.stamp_ns);
      EXPECT_LT(sample.stamp_ns, scan.stamp_ns + 100'000'000);
      // A hand-held sensor near rest: about 1 g (this unit reads 1.03 .. 1.15 g while being
      // carried), turning by a few deg/s.
      EXPECT_GT(sample.accel_mps2.norm(), 9.5);
      EXPECT_LT(sample.accel_mps2.norm(), 11.5);
      EXPECT_LT(sample.gyro_radps.norm(), 10.0 * kDeg);
      if (i > 0) {
        EXPECT_GT(sample.stamp_ns, scan.imu[i - 1].stamp_ns);
        spacing_ms.push_back(static_cast<double>(sample.stamp_ns - scan.imu[i - 1].stamp_ns) *
                             1e-6);
      }
    }
  }
  EXPECT_EQ(counts, (std::vector<size_t>{8, 10, 10}));
  ASSERT_FALSE(spacing_ms.empty());
  for (double ms : spacing_ms) EXPECT_NEAR(ms, 10.0, 0.1);  // 100 Hz

  // imu_to_sensor_transform is a pure translation for this unit: the sensor frame's z is the
  // IMU's, and the sensor stood upright, so gravity's reaction points up along +z.
  const ImuSample& first = scans[0].imu.front();
  EXPECT_GT(first.accel_mps2.z(), 0.9 * kG);
  EXPECT_LT(first.accel_mps2.z(), 1.1 * kG);
}

TEST(OusterPcapImu, Os1WithoutImuWhenTurnedOff) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  SourceOptions options;
  options.imu = false;
  const std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), options);
  EXPECT_TRUE(source->info().imu.empty());
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  ASSERT_EQ(scans.size(), 3u);
  for (const Scan& scan : scans) EXPECT_TRUE(scan.imu.empty());
}

TEST(OusterPcapImu, Os1MalformedImuPacketsAreCountedAndSkipped) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const auto dir = test::scratch_dir("ouster_imu_malformed");
  std::vector<test::CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  // Two cut-short IMU packets among the first frames.
  for (size_t at : {size_t{5}, size_t{40}}) {
    test::CapturedFrame bad = frames[at];
    bad.bytes = test::ethernet_ipv4_udp(std::vector<uint8_t>(20, 1), 7503, 999);
    frames.insert(frames.begin() + static_cast<std::ptrdiff_t>(at), bad);
  }
  const auto path = dir / "malformed_imu.pcap";
  test::write_file(path, test::write_pcap(frames));
  SourceOptions options;
  options.meta_path = json.string();
  const std::unique_ptr<ScanSource> source = open_ouster_pcap(path.string(), options);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[0].imu.size() + scans[1].imu.size() + scans[2].imu.size(), 28u);
  ASSERT_EQ(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings[0].find("2 packets on the IMU port"), std::string::npos)
      << source->stats().warnings[0];
}

TEST(OusterPcapImu, Os1ImuPacketsAfterTheirSweepStillReachIt) {
  // Every IMU packet moved behind the lidar packets of the next frame's start: the reader
  // must hold a completed frame until its sweep's samples have come.
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const auto dir = test::scratch_dir("ouster_imu_delayed");
  const std::vector<test::CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  std::vector<test::CapturedFrame> lidar;
  std::vector<test::CapturedFrame> imu;
  for (const test::CapturedFrame& frame : frames) {
    (frame.bytes.size() < 200 ? imu : lidar).push_back(frame);
  }
  ASSERT_EQ(imu.size(), 30u);
  std::vector<test::CapturedFrame> delayed;
  size_t next_imu = 0;
  for (size_t i = 0; i < lidar.size(); ++i) {
    delayed.push_back(lidar[i]);
    // After every 8 lidar packets (12.5 ms), the IMU packets up to about 40 ms ago.
    if (i % 8 == 7) {
      const size_t due = std::min(imu.size(), (i + 1) * 30 / lidar.size());
      const size_t late = due > 4 ? due - 4 : 0;
      while (next_imu < late) delayed.push_back(imu[next_imu++]);
    }
  }
  while (next_imu < imu.size()) delayed.push_back(imu[next_imu++]);
  const auto path = dir / "delayed_imu.pcap";
  test::write_file(path, test::write_pcap(delayed));
  SourceOptions options;
  options.meta_path = json.string();
  const std::vector<Scan> scans = read_all(path.string(), options);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[0].imu.size(), 8u);
  EXPECT_EQ(scans[1].imu.size(), 10u);
  EXPECT_EQ(scans[2].imu.size(), 10u);
}

}  // namespace
}  // namespace featsense::slam
