// Simulated scans of a Velodyne's firing grid written as its data packets and read back by
// the Velodyne pcap reader: every simulated return comes back, along the same beam within the
// packet format's resolution, one scan per simulated revolution.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/io/pcap_recorders.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "pcap_test_util.hpp"
#include "scan_read_back.hpp"
#include "sim_test_util.hpp"
#include "velodyne/velodyne_firing.hpp"
#include "velodyne/velodyne_firing_geometry.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

struct Recorded {
  std::vector<SimulatedFrame> frames;
  std::vector<Scan> read_back;
  std::string detail;  ///< the reader's account of the stream
  uint64_t packets = 0;
};

/// `count` revolutions of a walk through the box room, recorded as packets and read back.
Recorded record_and_read(const std::string& preset, double rate_hz, int count = 3) {
  const test::BoxRoomWalk walk;
  SimulationSettings settings;
  settings.sensor = velodyne_firing_sensor(preset, rate_hz);
  settings.measurement.seed = 3;
  const LidarSimulator simulator = walk.simulator(settings);

  const fs::path dir = fs::temp_directory_path() / ("featsense_velodyne_recorder_" + preset);
  fs::remove_all(dir);
  fs::create_directories(dir);
  Recorded out;
  {
    VelodynePcapRecorder recorder((dir / "recording.pcap").string(), preset, rate_hz);
    for (int i = 0; i < count; ++i) {
      out.frames.push_back(simulator.simulate(static_cast<uint64_t>(i)));
      recorder.add(out.frames.back().scan);
    }
    recorder.finish();
    out.packets = recorder.packets();
  }
  test::ReadBack read = test::read_back(dir / "recording.pcap");
  out.detail = read.info.detail;
  // The reader's rows are the simulated rows.
  EXPECT_EQ(read.info.sensor.elevation_rad, settings.sensor.elevation_rad);
  out.read_back = std::move(read.scans);
  EXPECT_EQ(read.stats.warning_count, 0u)
      << (read.stats.warnings.empty() ? "" : read.stats.warnings.front());
  fs::remove_all(dir);
  return out;
}

struct RoundTrip {
  size_t simulated = 0;  ///< valid simulated points
  size_t read = 0;       ///< valid points read back
  size_t matched = 0;
  double worst_xyz_m = 0.0;
  double worst_range_m = 0.0;
  double worst_azimuth_centideg = 0.0;
  double worst_time_s = 0.0;  ///< after the slot's firing time is allowed for
  double worst_reflectivity = 0.0;
  size_t beyond_bound = 0;  ///< points farther from their simulated point than the resolution
};

/// Finds each read-back point's simulated point by row and time, and compares them.
///
/// Times: the reader dates a packet by its capture (the clocks' offset is the smallest
/// capture-minus-stamp time it sees, and a packet is captured when its last firing was
/// measured), so its times lie one packet span after the firings', plus the slot's firing
/// time within its sequence (the simulator fires a column's rows at once), within the
/// rounding of microsecond stamps and the model's firing period (rounding_s).
///
/// Directions: each laser's azimuth is interpolated between two 0.01 deg block azimuths
/// (half a unit each, weighted by at most 1 + 2 f for the slot's fraction f of a step where
/// the reader extrapolates the last block of a packet) and rounded to 0.01 deg again: at most
/// 1 + f_max units. On the VLP-32C the reader gives the packet's last block no turn: its
/// returns come back turned anticlockwise by the laser's fraction of a step.
void compare(const Recorded& r, const std::string& preset, double rate_hz, RoundTrip* result) {
  const VelodyneFiringGeometry g = velodyne_firing_geometry(preset, rate_hz);
  const int per_packet = static_cast<int>(kVelodyneBlocks) * g.columns_per_block;
  const double column_s = 1.0 / (g.columns * g.sensor.rate_hz);
  const double step_rad = 2.0 * M_PI / g.columns;
  const double span_s = (per_packet - 1) * column_s;
  const double unit_m = velodyne_distance_unit_m(g.model);
  std::vector<double> fraction;  // of a column step, per row
  double fraction_max = 0.0;
  double slot_max_s = 0.0;
  for (int laser : g.laser_of_row) {
    const VelodyneFiring firing = velodyne_firing(g.model, 0, static_cast<size_t>(laser), false);
    fraction.push_back(g.columns_per_block * firing.azimuth_fraction);
    fraction_max = std::max(fraction_max, fraction.back());
    slot_max_s = std::max(slot_max_s, firing.time_us * 1e-6);
  }
  const double azimuth_bound_centideg = 1.0 + fraction_max;
  const double azimuth_bound_rad = azimuth_bound_centideg * M_PI / 18000.0;
  // Microsecond stamps and capture times (2 us), and the model's firing period against the
  // simulated one (the motor turns at exactly the rate) over a packet.
  const double model_column_s = 1e-6 *
                                (velodyne_firing(g.model, 1, 0, false).time_us -
                                 velodyne_firing(g.model, 0, 0, false).time_us) /
                                g.columns_per_block;
  const double rounding_s = 2e-6 + (per_packet - 1) * std::abs(column_s - model_column_s);
  constexpr double kFloatM = 1e-5;

  RoundTrip& out = *result;
  std::vector<std::vector<uint8_t>> matched;
  for (const SimulatedFrame& f : r.frames) {
    out.simulated += f.scan.valid_count();
    matched.emplace_back(f.scan.size(), 0);
  }
  const int64_t t0_ns = r.frames.front().scan.stamp_ns;
  for (size_t k = 0; k < r.read_back.size(); ++k) {
    const Scan& read = r.read_back[k];
    const ScanChannel* intensity = read.channel("intensity");
    for (int row = 0; row < read.rows; ++row) {
      for (int rc = 0; rc < read.cols; ++rc) {
        const size_t j = read.index(row, rc);
        if (!read.valid[j]) continue;
        ++out.read;
        const double t_read_s = 1e-9 * static_cast<double>(read.stamp_ns - t0_ns) +
                                static_cast<double>(read.time_offset_s[j]);
        // The firing that the read time falls after (within a few tens of microseconds).
        const int64_t firing =
            static_cast<int64_t>(std::floor((t_read_s - span_s + rounding_s) / column_s));
        const int64_t frame = firing / g.columns;
        const int c = static_cast<int>(firing % g.columns);
        ASSERT_GE(firing, 0);
        ASSERT_EQ(frame, static_cast<int64_t>(k)) << "a revolution is a scan";
        const Scan& made = r.frames[static_cast<size_t>(frame)].scan;
        const size_t i = made.index(row, c);
        ASSERT_TRUE(made.valid[i]) << "row " << row << " column " << c << " of frame " << frame;
        ASSERT_FALSE(matched[static_cast<size_t>(frame)][i]) << "read back twice";
        matched[static_cast<size_t>(frame)][i] = 1;
        ++out.matched;

        const double t_made_s = 1e-9 * static_cast<double>(made.stamp_ns - t0_ns) +
                                static_cast<double>(made.time_offset_s[i]);
        const double late_s = t_read_s - t_made_s - span_s;
        out.worst_time_s = std::max({out.worst_time_s, -late_s, late_s - slot_max_s});

        Eigen::Vector3d expected = made.xyz[i].cast<double>();
        if (g.model == VelodyneModel::kVlp32c && firing % per_packet == per_packet - 1) {
          expected = Eigen::AngleAxisd(fraction[static_cast<size_t>(row)] * step_rad,
                                       Eigen::Vector3d::UnitZ()) *
                     expected;
        }
        const Eigen::Vector3d got = read.xyz[j].cast<double>();
        const double horizontal_m = expected.head<2>().norm();
        const double bound_m = 0.5 * unit_m + horizontal_m * azimuth_bound_rad + kFloatM;
        const double error_m = (got - expected).norm();
        if (error_m > bound_m && out.beyond_bound++ == 0) {
          ADD_FAILURE() << "row " << row << " column " << c << " of frame " << frame << ": "
                        << error_m * 1e3 << " mm off, more than " << bound_m * 1e3 << " mm";
        }
        out.worst_xyz_m = std::max(out.worst_xyz_m, error_m);
        out.worst_range_m = std::max(out.worst_range_m,
                                     std::abs(double{read.range_m[j]} - double{made.range_m[i]}));
        const double turn = std::remainder(
            std::atan2(got.y(), got.x()) - std::atan2(expected.y(), expected.x()), 2.0 * M_PI);
        out.worst_azimuth_centideg =
            std::max(out.worst_azimuth_centideg, std::abs(turn) * 18000.0 / M_PI);
        out.worst_reflectivity = std::max(
            out.worst_reflectivity,
            std::abs(double{intensity->values[j]} - made.channel("reflectivity")->values[i]));
      }
    }
  }
  EXPECT_EQ(out.beyond_bound, 0u);
  EXPECT_LE(out.worst_range_m, 0.5 * unit_m + kFloatM);
  EXPECT_LE(out.worst_azimuth_centideg, azimuth_bound_centideg + 1e-3);
  EXPECT_LE(out.worst_time_s, rounding_s);
  EXPECT_LE(out.worst_reflectivity, 0.5 + 1e-4);  // whole-number reflectivity
}

void expect_round_trip(const std::string& preset, double rate_hz, const std::string& product) {
  SCOPED_TRACE(preset);
  constexpr int kFrames = 3;
  const Recorded r = record_and_read(preset, rate_hz, kFrames);
  EXPECT_NE(r.detail.find(product), std::string::npos) << r.detail;
  const VelodyneFiringGeometry g = velodyne_firing_geometry(preset, rate_hz);
  const uint64_t per_packet = kVelodyneBlocks * static_cast<uint64_t>(g.columns_per_block);
  EXPECT_EQ(r.packets, (kFrames * static_cast<uint64_t>(g.columns) + per_packet - 1) / per_packet);
  ASSERT_EQ(r.read_back.size(), r.frames.size());
  RoundTrip t;
  compare(r, preset, rate_hz, &t);
  EXPECT_GT(t.simulated, kFrames * r.frames.front().scan.size() / 2);
  EXPECT_EQ(t.read, t.simulated);
  EXPECT_EQ(t.matched, t.simulated);
  std::ostringstream figures;
  figures << preset << " at " << g.sensor.rate_hz << " Hz, " << g.columns
          << " firings: " << t.simulated << " points, " << t.read << " read back; worst xyz "
          << t.worst_xyz_m * 1e3 << " mm, range " << t.worst_range_m * 1e3 << " mm, azimuth "
          << t.worst_azimuth_centideg << " x 0.01 deg, time beyond the firing bound "
          << t.worst_time_s * 1e6 << " us, reflectivity " << t.worst_reflectivity;
  ::testing::Test::RecordProperty("figures", figures.str());
  std::cout << figures.str() << "\n";
}

TEST(VelodynePcapRecorder, Hdl32eScansReadBackAsSimulated) {
  expect_round_trip("hdl32", 10.0, "HDL-32E (product id 0x21)");
}

TEST(VelodynePcapRecorder, Vlp32cScansReadBackAsSimulated) {
  expect_round_trip("vlp32c", 10.0, "VLP-32C (product id 0x28)");
}

// At 20 Hz: at 10 Hz a turn's 1808 firing sequences outnumber the vlp16 preset's 1800
// columns, and the reader keeps one firing of the few that share a column.
TEST(VelodynePcapRecorder, Vlp16ScansOfTwoSequencesPerBlockReadBackAsSimulated) {
  expect_round_trip("vlp16", 20.0, "VLP-16 (product id 0x22)");
}

TEST(VelodynePcapRecorder, ScanAfterAGapStartsAPacketOfItsOwn) {
  const test::BoxRoomWalk walk;
  SimulationSettings settings;
  settings.sensor = velodyne_firing_sensor("vlp32c");
  const LidarSimulator simulator = walk.simulator(settings);
  const fs::path path = fs::temp_directory_path() / "featsense_velodyne_gap.pcap";
  std::vector<Scan> made;
  VelodynePcapRecorder recorder(path.string(), "vlp32c");
  for (uint64_t frame : {0, 2}) {  // the second revolution is missing
    made.push_back(simulator.simulate(frame).scan);
    recorder.add(made.back());
  }
  recorder.finish();
  EXPECT_EQ(recorder.packets(), 2u * ((1808u + 11u) / 12u));  // each turn's last one filled
  const auto source = open_scan_source(path.string());
  std::vector<Scan> read;
  while (auto scan = source->next()) read.push_back(std::move(*scan));
  fs::remove(path);
  EXPECT_EQ(source->stats().warning_count, 0u);
  ASSERT_EQ(read.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(read[k].valid_count(), made[k].valid_count());
    // One packet's span late (compare() says why), within a firing.
    EXPECT_NEAR(1e-9 * static_cast<double>(read[k].stamp_ns - made[k].stamp_ns),
                11.0 / (1808 * 10.0), 1.0 / (1808 * 10.0));
  }
}

TEST(VelodynePcapRecorder, FiringSensorIsTheModelsFiringGrid) {
  const config::SensorModel hdl = velodyne_firing_sensor("hdl32");
  EXPECT_EQ(hdl.beams, 32);
  EXPECT_EQ(hdl.columns, 2170);                                   // 46.08 us per firing at 10 Hz
  EXPECT_EQ(velodyne_firing_sensor("vlp32c").columns, 1808);      // 55.296 us
  EXPECT_EQ(velodyne_firing_sensor("vlp16", 20.0).columns, 904);  // two sequences a block
  EXPECT_EQ(velodyne_firing_sensor("hdl32", 12.5).rate_hz, 12.5);
}

TEST(VelodynePcapRecorder, WhatIsNoWritableVelodyneIsRefused) {
  const std::string path = (fs::temp_directory_path() / "featsense_velodyne_bad.pcap").string();
  EXPECT_THROW(velodyne_firing_sensor("vls128"), config::ConfigError);
  EXPECT_THROW(velodyne_firing_sensor("hdl64"), config::ConfigError);
  EXPECT_THROW(velodyne_firing_sensor("os1-128"), config::ConfigError);
  EXPECT_THROW(velodyne_firing_sensor("hdl32", 30.0), config::ConfigError);
  EXPECT_THROW(VelodynePcapRecorder(path, "os1-128"), config::ConfigError);
  try {
    velodyne_firing_sensor("vls128");
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("writing VLS-128 packets is not supported"),
              std::string::npos)
        << e.what();
  }
  VelodynePcapRecorder recorder(path, "hdl32");
  EXPECT_THROW(recorder.add(Scan::allocate(32, 1800)), std::invalid_argument);
  EXPECT_THROW(VelodynePcapRecorder("/nonexistent-folder/x.pcap", "hdl32"), WriteError);
  fs::remove(path);
}

TEST(VelodynePcapRecorder, OtherDatagramsOnTheDataPortAreCountedPositionPacketsNot) {
  const test::BoxRoomWalk walk;
  SimulationSettings settings;
  settings.sensor = velodyne_firing_sensor("hdl32", 10.0);
  const LidarSimulator simulator = walk.simulator(settings);
  const fs::path dir = fs::temp_directory_path() / "featsense_velodyne_foreign_datagrams";
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    VelodynePcapRecorder recorder((dir / "clean.pcap").string(), "hdl32", 10.0);
    for (uint64_t i = 0; i < 2; ++i) recorder.add(simulator.simulate(i).scan);
    recorder.finish();
  }
  // Among the data packets: position packets on 8308 (as every Velodyne sends), three
  // datagrams of another size on the data port and one on another port.
  std::vector<test::CapturedFrame> frames =
      test::read_pcap_frames(test::read_file(dir / "clean.pcap"));
  ASSERT_GT(frames.size(), 100u);
  const auto extra = [&](size_t at, size_t bytes, uint16_t port) {
    test::CapturedFrame frame = frames[at];
    frame.bytes = test::ethernet_ipv4_udp(std::vector<uint8_t>(bytes, 0x5A), port, 9000);
    frames.insert(frames.begin() + static_cast<std::ptrdiff_t>(at), frame);
  };
  for (size_t at : {5, 40, 80}) extra(at, 512, 8308);
  for (size_t at : {20, 60}) extra(at, 100, 2368);
  extra(70, 1248, 2368);
  extra(90, 300, 5000);
  test::write_file(dir / "mixed.pcap", test::write_pcap(frames));

  const test::ReadBack clean_read = test::read_back(dir / "clean.pcap");
  const test::ReadBack mixed_read = test::read_back(dir / "mixed.pcap");
  fs::remove_all(dir);
  const std::vector<Scan>& clean = clean_read.scans;
  const std::vector<Scan>& mixed = mixed_read.scans;
  const ReadStats& clean_stats = clean_read.stats;
  const ReadStats& mixed_stats = mixed_read.stats;
  ASSERT_EQ(clean_stats.warning_count, 0u);
  ASSERT_EQ(mixed.size(), clean.size());
  for (size_t i = 0; i < clean.size(); ++i) EXPECT_EQ(mixed[i].valid, clean[i].valid) << i;
  ASSERT_EQ(mixed_stats.warning_count, 1u);
  const std::string& warning = mixed_stats.warnings.front();
  EXPECT_NE(warning.find("3 datagrams on the data port 2368"), std::string::npos) << warning;
  EXPECT_NE(warning.find("2 of 100 bytes, 1 of 1248 bytes"), std::string::npos) << warning;
}

}  // namespace
}  // namespace featsense::slam
