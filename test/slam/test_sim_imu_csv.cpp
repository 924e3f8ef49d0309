// imu.csv of a simulated folder: the simulator's IMU samples written beside the frames and
// read back with them, each in the frame of its sweep; and the file's damage rules.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/io/imu_csv.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "sim_test_util.hpp"

namespace featsense::slam {
namespace {

std::vector<Scan> read_all(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

/// Three frames of the lab scene with the simulator's IMU into `dir`; the frames' samples.
std::vector<std::vector<ImuSample>> simulate_lab(const std::filesystem::path& dir) {
  const mesh::TriangleMesh mesh = build_scene("lab");
  const RayCaster caster(mesh);
  const NamedPath path = scene_path("lab", "drone");
  const auto trajectory = make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  const LidarSimulator sim(mesh, caster, *trajectory, settings);
  SimulationWriter writer(dir.string(), settings.sensor);
  std::vector<std::vector<ImuSample>> samples;
  for (uint64_t i = 0; i < 3; ++i) {
    const SimulatedFrame frame = sim.simulate(i);
    samples.push_back(frame.scan.imu);
    writer.add(frame, trajectory->pose(frame.start_s));
  }
  writer.finish(mesh);
  return samples;
}

TEST(SimImuCsv, SamplesRoundTripWithTheirFrames) {
  const auto dir = test::scratch_dir("sim_imu_csv_round_trip");
  const std::vector<std::vector<ImuSample>> written = simulate_lab(dir);
  ASSERT_TRUE(std::filesystem::exists(dir / "imu.csv"));
  const std::unique_ptr<ScanSource> source = open_scan_folder(dir.string(), {});
  EXPECT_NE(source->info().imu.find("imu.csv"), std::string::npos) << source->info().imu;
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(source->stats().warning_count, 0u);
  for (size_t f = 0; f < scans.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    // The simulator's samples of the sweep [stamp, stamp + 100 ms): it may add the one at the
    // next sweep's first instant, which belongs to that sweep.
    std::vector<ImuSample> expected;
    for (const ImuSample& sample : written[f]) {
      if (sample.stamp_ns < scans[f].stamp_ns + 100'000'000) expected.push_back(sample);
    }
    ASSERT_EQ(expected.size(), 10u);  // 100 Hz over a 10 Hz sweep
    ASSERT_EQ(scans[f].imu.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(scans[f].imu[i].stamp_ns, expected[i].stamp_ns);
      EXPECT_EQ(scans[f].imu[i].accel_mps2, expected[i].accel_mps2);  // exactly: %.17g
      EXPECT_EQ(scans[f].imu[i].gyro_radps, expected[i].gyro_radps);
    }
  }

  SourceOptions off;
  off.imu = false;
  const std::unique_ptr<ScanSource> without = open_scan_folder(dir.string(), off);
  EXPECT_TRUE(without->info().imu.empty());
  for (const Scan& scan : read_all(*without)) EXPECT_TRUE(scan.imu.empty());
}

TEST(SimImuCsv, BadLinesAreSkippedAndABadHeaderIsAnError) {
  std::vector<std::string> skipped;
  size_t count = 0;
  const std::vector<ImuSample> samples = parse_imu_csv(
      "stamp_ns,ax,ay,az,gx,gy,gz\n"
      "100,1,2,3,4,5,6\n"
      "200,1,2,3\n"
      "300,1,2,3,4,5,nan\n"
      "x00,1,2,3,4,5,6\n"
      "\n"
      "400,0.5,0,9.81,0,0,0.25\r\n",
      "imu.csv", &skipped, &count);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].stamp_ns, 100);
  EXPECT_EQ(samples[0].gyro_radps, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(samples[1].stamp_ns, 400);
  EXPECT_EQ(samples[1].accel_mps2, Eigen::Vector3d(0.5, 0, 9.81));
  EXPECT_EQ(count, 3u);
  ASSERT_EQ(skipped.size(), 3u);
  EXPECT_NE(skipped[0].find("line 3"), std::string::npos) << skipped[0];

  EXPECT_THROW(parse_imu_csv("t,ax\n1,2\n", "imu.csv", &skipped, &count), InputError);
  EXPECT_THROW(parse_imu_csv("", "imu.csv", &skipped, &count), InputError);

  std::string line;
  ImuSample sample;
  sample.stamp_ns = -5;
  sample.accel_mps2 = Eigen::Vector3d(0.1, 1.0 / 3.0, -9.80665);
  sample.gyro_radps = Eigen::Vector3d(1e-300, 2.5, -0.0);
  append_imu_csv_line(sample, &line);
  const std::vector<ImuSample> back =
      parse_imu_csv(std::string(kImuCsvHeader) + "\n" + line, "x", &skipped, &count);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].stamp_ns, -5);
  EXPECT_EQ(back[0].accel_mps2, sample.accel_mps2);
  EXPECT_EQ(back[0].gyro_radps, sample.gyro_radps);
}

}  // namespace
}  // namespace featsense::slam
