// Sessions of a saved map mapped again only where they moved: the chunks a moved scan reached
// are those of a full re-map, every other chunk is the map before's byte for byte, and the
// sessions and poses are a full re-map's. On a simulated corridor walk longer than the local
// map, so that a correction of its end leaves its start as it was.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/reintegration_plan.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/sim/prepared_simulation.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "mapping_test_scenes.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;
using test::read_chunks;

constexpr int kFrames = 26;
constexpr size_t kFirstMoved = 18;

class RemapWhereMoved : public ::testing::Test {
 protected:
  /// A corridor walk of 26 slow revolutions (33 m), written once for every test; 1.1 Hz so
  /// that the stamps are not whole seconds, which a double holds exactly.
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() /
                         ("featsense_remap_where_moved_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    slam::SimulationRequest request;
    request.scene = "corridor";
    request.path = "walk";
    request.sensor = "os1-64";
    request.rate_hz = 1.1;
    request.frames = kFrames;
    const slam::PreparedSimulation simulation(request);
    slam::SimulationWriter writer((*root_ / "corridor").string(),
                                  simulation.simulator->settings().sensor);
    for (uint64_t i = 0; i < simulation.frames; ++i) {
      const slam::SimulatedFrame frame = simulation.simulator->simulate(i);
      writer.add(frame, simulation.trajectory->pose(frame.start_s));
    }
    writer.finish(simulation.mesh);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }

  void SetUp() override {
    dir_ = *root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
    config_ = test::small_map_config();
    config_.map.size_m = {12.0, 12.0, 6.0};
    config_.map.shift_threshold_m = 2.0;
  }

  std::string input() const { return (*root_ / "corridor").string(); }
  slam::Trajectory truth() const {
    return slam::read_tum((*root_ / "corridor" / "gt_trajectory.tum").string());
  }
  SessionRemap session(slam::Trajectory poses) const {
    return {{input(), "folder", "given poses"}, std::move(poses), {}};
  }
  void remap(const SessionRemap& s, const fs::path& into) const {
    remap_sessions({s}, into, pass_settings(config_), config_, "os1-64", {});
  }

  static fs::path* root_;
  fs::path dir_;
  config::Config config_;
};

fs::path* RemapWhereMoved::root_ = nullptr;

/// The walk's end moved sideways and turned a little, as a link to another session would.
slam::Trajectory end_moved(slam::Trajectory poses) {
  for (size_t k = kFirstMoved; k < poses.size(); ++k) {
    Eigen::Isometry3d change = Eigen::Isometry3d::Identity();
    change.translation() = Eigen::Vector3d(0.0, 0.05, 0.01);
    change.linear() = Eigen::AngleAxisd(0.2 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).matrix();
    poses.poses[k] = poses.poses[k] * change;
  }
  return poses;
}

TEST_F(RemapWhereMoved, ChangedChunksAreAFullRemapsAndTheOthersTheMapBefore) {
  remap(session(truth()), dir_ / "before.h5");
  const SavedMap before = read_saved_map(dir_ / "before.h5");
  // As `map --continue` and `merge` have them: the map's own poses (their stamps read back
  // from seconds in a double, a few hundred nanoseconds from the scans'), moved.
  const SessionRemap moved = session(end_moved(before.sessions[0].poses));
  remap(moved, dir_ / "full.h5");
  const ReintegrationCounts counts = remap_sessions_where_moved(
      before, {moved}, dir_ / "where_moved.h5", pass_settings(config_), config_, "os1-64", {});

  ASSERT_FALSE(counts.whole) << counts.why;
  EXPECT_EQ(counts.scans, static_cast<size_t>(kFrames));
  // The moved scans and the one before them, deskewed towards the first moved pose.
  EXPECT_EQ(counts.scans_moved, static_cast<size_t>(kFrames) - kFirstMoved + 1);
  EXPECT_GT(counts.scans_reintegrated, counts.scans_moved);
  EXPECT_LT(counts.scans_reintegrated, static_cast<size_t>(kFrames));
  EXPECT_GT(counts.chunks_kept, 0u);
  EXPECT_GT(counts.chunks_changed, 0u);

  const ReintegrationPlan plan =
      plan_reintegration({{before.sessions[0].poses, moved.poses}}, config_.map,
                         reach_before(config_.map, config_.map));
  EXPECT_EQ(counts.scans_reintegrated, plan.scans_reintegrated);  // every planned scan came
  const auto old_chunks = read_chunks(dir_ / "before.h5");
  const auto full = read_chunks(dir_ / "full.h5");
  const auto after = read_chunks(dir_ / "where_moved.h5");
  size_t changed = 0;
  size_t kept = 0;
  for (const auto& [key, chunk] : after) {
    if (plan.changed.count(key) > 0) {
      ASSERT_TRUE(full.count(key));
      EXPECT_TRUE(chunk == full.at(key))
          << "changed chunk " << key.x << " " << key.y << " " << key.z;
      ++changed;
    } else {
      ASSERT_TRUE(old_chunks.count(key));
      EXPECT_TRUE(chunk == old_chunks.at(key))
          << "kept chunk " << key.x << " " << key.y << " " << key.z;
      ++kept;
    }
  }
  for (const auto& [key, chunk] : full) {
    if (plan.changed.count(key) > 0) {
      EXPECT_TRUE(after.count(key));
    }
  }
  for (const auto& [key, chunk] : old_chunks) {
    if (plan.changed.count(key) == 0) {
      EXPECT_TRUE(after.count(key));
    }
  }
  EXPECT_EQ(changed, counts.chunks_changed);
  EXPECT_EQ(kept, counts.chunks_kept);
  // Where the end moved, the map did change: the test compares something.
  size_t differing = 0;
  for (const auto& [key, chunk] : full)
    differing += old_chunks.count(key) > 0 && !(old_chunks.at(key) == chunk);
  EXPECT_GT(differing, 0u);

  // The sessions and poses of a full re-map.
  storage::Hdf5ChunkStore full_store(dir_ / "full.h5");
  storage::Hdf5ChunkStore after_store(dir_ / "where_moved.h5");
  const auto full_poses = full_store.read_trajectory();
  const auto after_poses = after_store.read_trajectory();
  EXPECT_EQ(full_poses.size(), static_cast<size_t>(kFrames));  // the first and last scan too
  ASSERT_EQ(after_poses.size(), full_poses.size());
  for (size_t i = 0; i < full_poses.size(); ++i) {
    EXPECT_EQ(after_poses[i].t_s, full_poses[i].t_s);
    EXPECT_EQ(after_poses[i].x, full_poses[i].x);
    EXPECT_EQ(after_poses[i].qw, full_poses[i].qw);
  }
  ASSERT_EQ(after_store.read_sessions().size(), 1u);
  EXPECT_EQ(after_store.read_sessions()[0].scans, full_store.read_sessions()[0].scans);
  EXPECT_FALSE(fs::exists(dir_ / "where_moved.h5.changed"));
}

TEST_F(RemapWhereMoved, NothingMovedKeepsEveryChunkAsItWas) {
  remap(session(truth()), dir_ / "before.h5");
  const SavedMap before = read_saved_map(dir_ / "before.h5");
  const ReintegrationCounts counts = remap_sessions_where_moved(
      before, {session(truth())}, dir_ / "after.h5", pass_settings(config_), config_, "os1-64", {});
  EXPECT_EQ(counts.scans_moved, 0u);
  EXPECT_EQ(counts.scans_reintegrated, 0u);
  EXPECT_EQ(counts.chunks_changed, 0u);
  EXPECT_EQ(read_chunks(dir_ / "after.h5"), read_chunks(dir_ / "before.h5"));
}

TEST_F(RemapWhereMoved, AMapKeepingNoPosesOfItsSessionsIsMappedWhole) {
  // Poses that do not split into sessions: nothing tells where each scan wrote.
  remap(session(truth()), dir_ / "before.h5");
  SavedMap before = read_saved_map(dir_ / "before.h5");
  before.sessions[0].poses = {};
  const ReintegrationCounts counts =
      remap_sessions_where_moved(before, {session(end_moved(truth()))}, dir_ / "after.h5",
                                 pass_settings(config_), config_, "os1-64", {});
  EXPECT_TRUE(counts.whole);
  EXPECT_NE(counts.why.find("no poses"), std::string::npos) << counts.why;
  remap(session(end_moved(truth())), dir_ / "full.h5");
  EXPECT_EQ(read_chunks(dir_ / "after.h5"), read_chunks(dir_ / "full.h5"));
}

// The plan alone, on a straight path: the quarter-voxel rule and new sessions.
slam::Trajectory straight_path(int poses, double step_m) {
  slam::Trajectory path;
  for (int k = 0; k < poses; ++k) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(step_m * k, 0.0, 1.5);
    path.push_back(1'000'000'000LL * (k + 1), pose);
  }
  return path;
}

slam::Trajectory shifted(slam::Trajectory path, double dy_m) {
  for (Eigen::Isometry3d& pose : path.poses) pose.translation().y() += dy_m;
  return path;
}

TEST(ReintegrationPlan, AScanMovesWhenACornerOfItsReachMovesMoreThanAQuarterVoxel) {
  config::MapConfig map;  // 6.4 cm voxels: a quarter is 16 mm
  const LocalMapReach reach = reach_before(map, map);
  const slam::Trajectory path = straight_path(50, 2.0);
  const ReintegrationPlan still = plan_reintegration({{path, shifted(path, 0.015)}}, map, reach);
  EXPECT_EQ(still.scans_moved, 0u);
  EXPECT_EQ(still.scans_reintegrated, 0u);
  EXPECT_TRUE(still.changed.empty());
  const ReintegrationPlan moved = plan_reintegration({{path, shifted(path, 0.017)}}, map, reach);
  EXPECT_EQ(moved.scans_moved, 50u);
  EXPECT_EQ(moved.scans_reintegrated, 50u);

  // A turn of the last pose by 0.05 deg moves the far corners of its reach (about 29 m away)
  // by 25 mm: it and the scan before it (deskewed towards it) moved.
  slam::Trajectory turned = path;
  turned.poses.back().linear() =
      Eigen::AngleAxisd(0.05 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).matrix();
  const ReintegrationPlan end = plan_reintegration({{path, turned}}, map, reach);
  EXPECT_EQ(end.scans_moved, 2u);
  // Only the scans whose local map meets what those two reached: the path is 98 m long.
  EXPECT_GT(end.scans_reintegrated, 2u);
  EXPECT_LT(end.scans_reintegrated, 30u);
  for (const auto& [stamp, origin] : end.sessions[0].origins) EXPECT_GT(stamp, 20'000'000'000LL);
}

TEST(ReintegrationPlan, ASessionNewToTheMapMovedEverywhere) {
  config::MapConfig map;
  const slam::Trajectory path = straight_path(10, 1.0);
  const ReintegrationPlan plan =
      plan_reintegration({{path, path}, {{}, shifted(path, 100.0)}}, map, reach_before(map, map));
  EXPECT_EQ(plan.scans, 20u);
  EXPECT_EQ(plan.scans_moved, 10u);
  EXPECT_TRUE(plan.sessions[0].origins.empty());  // far from the new one
  EXPECT_EQ(plan.sessions[1].origins.size(), 10u);
}

TEST(ReintegrationPlan, ScansAreFoundByStampsReadBackFromTheMap) {
  // The map keeps stamps as seconds in a double: they come back up to ~300 ns off.
  config::MapConfig map;
  const slam::Trajectory path = straight_path(10, 1.0);
  slam::Trajectory read_back = path;
  for (size_t k = 0; k < read_back.size(); ++k) read_back.stamps_ns[k] += k % 2 ? 303 : -303;
  const ReintegrationPlan same =
      plan_reintegration({{read_back, path}}, map, reach_before(map, map));
  EXPECT_EQ(same.scans_moved, 0u);  // the same scans, none moved
  const ReintegrationPlan moved =
      plan_reintegration({{path, shifted(read_back, 0.05)}}, map, reach_before(map, map));
  ASSERT_EQ(moved.scans_reintegrated, 10u);
  const ScanReintegration& scans = moved.sessions[0];
  for (size_t k = 0; k < path.size(); ++k) {
    ASSERT_TRUE(scans.origin_at(path.stamps_ns[k])) << k;
    EXPECT_TRUE(scans.origin_at(path.stamps_ns[k] + 600));
    EXPECT_FALSE(scans.origin_at(path.stamps_ns[k] + 5'000));
    EXPECT_FALSE(scans.origin_at(path.stamps_ns[k] + 500'000'000));
  }
}

}  // namespace
}  // namespace featsense::mapping
