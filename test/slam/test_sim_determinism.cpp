// The same seed gives byte-identical output, whatever the thread count; another seed gives
// other noise.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "sim_test_util.hpp"

namespace featsense::slam {
namespace {

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string bytes(static_cast<size_t>(std::max<std::streamoff>(in.tellg(), 0)), '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

/// Two frames of the lab scene (noise, drop-outs and mixed pixels on) into `dir`.
void simulate_lab(const std::filesystem::path& dir, uint64_t seed) {
  const mesh::TriangleMesh mesh = build_scene("lab");
  const RayCaster caster(mesh);
  const NamedPath path = scene_path("lab", "drone");
  const auto trajectory = make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
  SimulationSettings settings;
  settings.sensor = test::small_sensor();
  settings.measurement.seed = seed;
  const LidarSimulator sim(mesh, caster, *trajectory, settings);
  SimulationWriter writer(dir.string(), settings.sensor);
  for (uint64_t i = 0; i < 2; ++i) {
    const SimulatedFrame frame = sim.simulate(i);
    writer.add(frame, trajectory->pose(frame.start_s));
  }
  writer.finish(mesh);
}

const char* const kFiles[] = {"frame_000000.pcd",  "frame_000001.pcd", "sequence.yaml", "imu.csv",
                              "gt_trajectory.tum", "gt_mesh.ply",      "gt_points.ply"};

TEST(SimDeterminism, SameSeedSameBytesWhateverTheThreadCount) {
  const auto dir = test::scratch_dir("sim_determinism");
  simulate_lab(dir / "a", 42);
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    simulate_lab(dir / "b", 42);
  }
  for (const char* name : kFiles) {
    const std::string a = read_bytes(dir / "a" / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == read_bytes(dir / "b" / name)) << name << " differs";
  }
}

TEST(SimDeterminism, AnotherSeedGivesOtherNoiseOnTheSameGeometry) {
  const auto dir = test::scratch_dir("sim_seeds");
  simulate_lab(dir / "a", 1);
  simulate_lab(dir / "b", 2);
  EXPECT_FALSE(read_bytes(dir / "a" / "frame_000000.pcd") ==
               read_bytes(dir / "b" / "frame_000000.pcd"));
  // Ground truth does not depend on the noise.
  EXPECT_TRUE(read_bytes(dir / "a" / "gt_trajectory.tum") ==
              read_bytes(dir / "b" / "gt_trajectory.tum"));
  EXPECT_TRUE(read_bytes(dir / "a" / "gt_mesh.ply") == read_bytes(dir / "b" / "gt_mesh.ply"));
}

TEST(SimDeterminism, HashedDrawsAreUniformAndNormal) {
  double sum = 0.0;
  double sum_sq = 0.0;
  double normal_sq = 0.0;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double u =
        hashed_uniform(3, 1, static_cast<uint32_t>(k % 128), static_cast<uint32_t>(k / 128), 0);
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_sq += u * u;
    const double z =
        hashed_normal(3, 1, static_cast<uint32_t>(k % 128), static_cast<uint32_t>(k / 128), 1);
    normal_sq += z * z;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.01);
  EXPECT_NEAR(sum_sq / n - 0.25, 1.0 / 12.0, 0.01);
  EXPECT_NEAR(normal_sq / n, 1.0, 0.02);
}

}  // namespace
}  // namespace featsense::slam
