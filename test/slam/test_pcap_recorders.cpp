// Simulated scans written as an Ouster's packets and read back by the pcap reader: the same
// scans within the packet format's resolution (1 mm ranges, whole-number reflectivity), the
// same column times and IMU samples, and metadata that says the simulator's geometry.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/io/pcap_recorders.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "scan_read_back.hpp"
#include "sim_test_util.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

struct Recorded {
  std::vector<SimulatedFrame> frames;
  std::vector<Scan> read_back;
  std::string metadata;
  uint64_t lidar_packets = 0;
};

/// `count` frames of a walk through the box room, recorded as packets and read back.
Recorded record_and_read(const config::SensorModel& sensor, const std::string& name,
                         int count = 3) {
  const test::BoxRoomWalk walk;
  SimulationSettings settings;
  settings.sensor = sensor;
  settings.measurement.seed = 3;
  const LidarSimulator simulator = walk.simulator(settings);

  const fs::path dir = fs::temp_directory_path() / ("featsense_pcap_recorder_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  Recorded out;
  {
    OusterPcapRecorder recorder((dir / "recording.pcap").string(), sensor);
    out.metadata = recorder.metadata_json();
    std::ofstream(dir / "recording.json") << out.metadata;
    for (int i = 0; i < count; ++i) {
      out.frames.push_back(simulator.simulate(static_cast<uint64_t>(i)));
      recorder.add(out.frames.back().scan);
    }
    recorder.finish();
    out.lidar_packets = recorder.lidar_packets();
  }
  test::ReadBack read = test::read_back(dir / "recording.pcap");
  out.read_back = std::move(read.scans);
  EXPECT_EQ(read.stats.warning_count, 0u)
      << (read.stats.warnings.empty() ? "" : read.stats.warnings.front());
  fs::remove_all(dir);
  return out;
}

TEST(OusterPcapRecorder, ScansReadBackAsTheSimulatorMadeThem) {
  const config::SensorModel sensor = test::small_sensor();
  const Recorded r = record_and_read(sensor, "exact");
  EXPECT_EQ(r.lidar_packets, 3u * 256u / 16u);
  ASSERT_EQ(r.read_back.size(), r.frames.size());
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const Scan& made = r.frames[f].scan;
    const Scan& read = r.read_back[f];
    ASSERT_EQ(read.rows, made.rows);
    ASSERT_EQ(read.cols, made.cols);
    EXPECT_EQ(read.stamp_ns, made.stamp_ns);
    EXPECT_GT(made.valid_count(), made.size() / 2);
    double worst_xyz = 0.0;
    double worst_range = 0.0;
    double worst_time = 0.0;
    double worst_reflectivity = 0.0;
    for (size_t i = 0; i < made.size(); ++i) {
      ASSERT_EQ(read.valid[i], made.valid[i]) << "cell " << i;
      if (!made.valid[i]) continue;
      worst_xyz = std::max(worst_xyz, static_cast<double>((read.xyz[i] - made.xyz[i]).norm()));
      worst_range = std::max(worst_range, std::abs(double{read.range_m[i]} - made.range_m[i]));
      worst_time =
          std::max(worst_time, std::abs(double{read.time_offset_s[i]} - made.time_offset_s[i]));
      worst_reflectivity =
          std::max(worst_reflectivity, std::abs(double{read.channel("reflectivity")->values[i]} -
                                                made.channel("reflectivity")->values[i]));
    }
    EXPECT_LT(worst_range, 0.5e-3 + 1e-6);      // millimetre ranges
    EXPECT_LT(worst_xyz, 0.5e-3 + 1e-5);        // along the beam only
    EXPECT_LT(worst_time, 1e-6);                // nanosecond column times
    EXPECT_LE(worst_reflectivity, 0.5 + 1e-4);  // whole-number reflectivity
  }
}

TEST(OusterPcapRecorder, ImuSamplesReadBackWithTheirTimes) {
  const Recorded r = record_and_read(test::small_sensor(), "imu");
  std::vector<ImuSample> made;
  for (const SimulatedFrame& frame : r.frames) {
    for (const ImuSample& s : frame.scan.imu) {
      if (made.empty() || s.stamp_ns > made.back().stamp_ns) made.push_back(s);
    }
  }
  std::vector<ImuSample> read;
  for (const Scan& scan : r.read_back) read.insert(read.end(), scan.imu.begin(), scan.imu.end());
  ASSERT_GE(made.size(), 25u);  // 100 Hz over 0.3 s
  // The reader keeps the samples within the scans' sweeps; every one it has is one made.
  ASSERT_GE(read.size(), made.size() - 2);
  size_t j = 0;
  for (const ImuSample& s : read) {
    while (j < made.size() && made[j].stamp_ns < s.stamp_ns) ++j;
    ASSERT_LT(j, made.size());
    EXPECT_EQ(made[j].stamp_ns, s.stamp_ns);
    EXPECT_LT((made[j].accel_mps2 - s.accel_mps2).norm(), 1e-5);  // float32 in g
    EXPECT_LT((made[j].gyro_radps - s.gyro_radps).norm(), 1e-6);  // float32 in deg/s
  }
}

TEST(OusterPcapRecorder, MetadataSaysTheSensorsGeometry) {
  const config::SensorModel sensor = test::small_sensor();
  const std::string path = (fs::temp_directory_path() / "featsense_recorder_meta.pcap").string();
  OusterPcapRecorder recorder(path, sensor);
  const OusterMetadata meta = parse_ouster_metadata(recorder.metadata_json(), "metadata");
  fs::remove(path);
  EXPECT_EQ(meta.profile, OusterProfile::kRng19Rfl8Sig16Nir16);
  EXPECT_EQ(meta.lidar_mode, "256x10");
  EXPECT_TRUE(meta.serial.has_value());
  const config::SensorModel read = meta.sensor_model();
  ASSERT_EQ(read.beams, sensor.beams);
  EXPECT_EQ(read.columns, sensor.columns);
  EXPECT_NEAR(read.beam_origin_offset_m, sensor.beam_origin_offset_m, 1e-12);
  for (size_t r = 0; r < sensor.elevation_rad.size(); ++r) {
    EXPECT_NEAR(read.elevation_rad[r], sensor.elevation_rad[r], 1e-12);
    EXPECT_NEAR(read.azimuth_offset_rad[r], sensor.azimuth_offset_rad[r], 1e-12);
  }
}

TEST(OusterPcapRecorder, ColumnsThatDoNotFillTheLastPacketAreMarkedInvalid) {
  config::SensorModel sensor = test::small_sensor();
  sensor.columns = 200;  // 12.5 packets of 16 columns
  const Recorded r = record_and_read(sensor, "partial", 2);
  EXPECT_EQ(r.lidar_packets, 2u * 13u);
  ASSERT_EQ(r.read_back.size(), 2u);
  EXPECT_EQ(r.read_back[1].valid, r.frames[1].scan.valid);
}

TEST(OusterPcapRecorder, WhatOustersFormatCannotSayIsRefused) {
  config::SensorModel sensor = test::small_sensor();
  const std::string path = (fs::temp_directory_path() / "featsense_recorder_bad.pcap").string();
  sensor.rate_hz = 12.5;
  EXPECT_THROW(OusterPcapRecorder(path, sensor), config::ConfigError);
  sensor.rate_hz = 10.0;
  OusterPcapRecorder recorder(path, sensor);
  EXPECT_THROW(recorder.add(Scan::allocate(8, 256)), std::invalid_argument);
  EXPECT_THROW(OusterPcapRecorder("/nonexistent-folder/x.pcap", sensor), WriteError);
  fs::remove(path);
}

}  // namespace
}  // namespace featsense::slam
