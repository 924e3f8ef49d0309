// One map from several recordings: `featsense map --continue` without poses places a recording
// by its keyframes, a chain of sessions gives the map of one run with the same final poses, a
// recording of another place is refused with the map left as it was, and `featsense merge`.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/file_bytes.hpp"
#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/small_map_options.hpp"
#include "common/spawn_command.hpp"
#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

// Keyframes every 0.3 m give a walk of a metre a few of them.
const std::string kSmall = kSmallMap + " --no-mesh --set loop.keyframe_distance=0.3";

// Scans placed rigidly at their stamps: a deskewed scan of a continued run is moved within its
// sweep as the odometry placed it, which its pose alone does not say; without deskewing, the
// final poses are all there is to a map (and the odometry is a few centimetres worse). The
// local map holds the whole room: which rays a moving local map cuts off depends on where it
// stands, and a session starts its own.
const std::string kRigid = kSmall + " --set odometry.deskew=false --set map.size=[40,40,12]";

class CliMapSessions : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    const fs::path dir = scratch_dir("cli_map_sessions_input");
    lab_ = new fs::path(dir / "lab");
    corridor_ = new fs::path(dir / "corridor");
    CommandResult sim =
        run_featsense("simulate --quiet --scene lab --frames 24 -o " + lab_->string());
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
    sim = run_featsense("simulate --quiet --scene corridor --frames 20 -o " + corridor_->string());
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  static void TearDownTestSuite() {
    delete lab_;
    delete corridor_;
  }
  static std::string lab() { return lab_->string(); }
  static std::string corridor() { return corridor_->string(); }

 private:
  static fs::path* lab_;
  static fs::path* corridor_;
};
fs::path* CliMapSessions::lab_ = nullptr;
fs::path* CliMapSessions::corridor_ = nullptr;

/// stamp (ns, rounded to the microsecond) -> x y z of a TUM file.
std::map<long long, std::vector<double>> read_positions(const fs::path& path) {
  std::map<long long, std::vector<double>> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0, x = 0, y = 0, z = 0;
    fields >> t >> x >> y >> z;
    out[std::llround(t * 1e6)] = {x, y, z};
  }
  return out;
}

/// The same chunks, and every voxel the same weight and a value within one fixed-point step
/// (poses written as text and read back differ in their ninth decimal), but for a few voxels in
/// a hundred thousand that a ray grazes differently.
void expect_maps_within_resolution(const fs::path& a, const fs::path& b) {
  storage::Hdf5ChunkStore first(a);
  storage::Hdf5ChunkStore second(b);
  ASSERT_EQ(first.keys(), second.keys());
  size_t observed = 0;
  size_t different = 0;
  for (const storage::ChunkKey& key : first.keys()) {
    const storage::Chunk x = *first.read(key);
    const storage::Chunk y = *second.read(key);
    for (size_t i = 0; i < x.voxels.size(); ++i) {
      const int value_x = static_cast<int16_t>(x.voxels[i] & 0xFFFFu);
      const int value_y = static_cast<int16_t>(y.voxels[i] & 0xFFFFu);
      const unsigned weight_x = x.voxels[i] >> 16;
      observed += weight_x > 0 ? 1 : 0;
      if (weight_x != (y.voxels[i] >> 16) || std::abs(value_x - value_y) > 1) ++different;
    }
  }
  EXPECT_GT(observed, 10000u);
  EXPECT_LE(different, observed / 100000) << different << " of " << observed << " voxels";
}

TEST_F(CliMapSessions, ThreeSessionsPlacedByTheirKeyframesGiveTheMapOfOneRun) {
  const fs::path dir = scratch_dir("cli_map_sessions_chain");
  // The first third from the true first pose (the simulation's ground truth beside it), the
  // other two continued without poses: each starts in a frame of its own and is placed by its
  // keyframes.
  CommandResult run =
      run_featsense("map " + lab() + " --end 7 -o " + (dir / "a").string() + kRigid);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("map " + lab() + " --start 8 --end 15 --continue " +
                      (dir / "a" / "map.h5").string() + " -o " + (dir / "b").string() + kRigid);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("map " + lab() + " --start 16 --continue " + (dir / "b" / "map.h5").string() +
                      " -o " + (dir / "c").string() + kRigid);
  ASSERT_EQ(run.exit_code, 0) << run.output;

  const nlohmann::json report = read_json(dir / "c" / "report.json");
  const nlohmann::json& placed = report["relocalization"];
  ASSERT_TRUE(placed["placed"].get<bool>()) << placed.dump(2);
  EXPECT_GE(placed["agreeing"].get<size_t>(), 2u);
  EXPECT_GE(placed["links"]["count"].get<size_t>(), 1u) << placed.dump(2);
  ASSERT_EQ(report["sessions"].size(), 3u);
  for (size_t s = 1; s < 3; ++s) {
    EXPECT_EQ(report["sessions"][s]["placement"].get<std::string>().rfind("relocalized", 0), 0u)
        << report["sessions"][s].dump();
    EXPECT_GT(report["sessions"][s]["keyframes"].get<size_t>(), 0u);
  }
  // Placed where the truth is (the map's frame is the truth's: the first session started from
  // the true first pose), within what an odometry that does not deskew can tell.
  const auto truth = read_positions(fs::path(lab()) / "gt_trajectory.tum");
  const auto placed_poses = read_positions(dir / "c" / "trajectory.tum");
  ASSERT_EQ(placed_poses.size(), 8u);
  for (const auto& [stamp, p] : placed_poses) {
    const std::vector<double>& t = truth.at(stamp);
    EXPECT_LT(std::hypot(p[0] - t[0], p[1] - t[1], p[2] - t[2]), 0.25) << stamp;
  }

  // The map of all three is the map of one run over the recording with the final poses the
  // map keeps.
  storage::Hdf5ChunkStore chained(dir / "c" / "map.h5");
  const std::vector<storage::TrajectoryPose> poses = chained.read_trajectory();
  chained.close();
  ASSERT_EQ(poses.size(), 24u);
  {
    std::ofstream out(dir / "final.tum");
    out.precision(12);
    for (const storage::TrajectoryPose& p : poses)
      out << p.t_s << " " << p.x << " " << p.y << " " << p.z << " " << p.qx << " " << p.qy << " "
          << p.qz << " " << p.qw << "\n";
  }
  run = run_featsense("map " + lab() + " --gt " + (dir / "final.tum").string() + " -o " +
                      (dir / "one").string() + kRigid);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  expect_maps_within_resolution(dir / "one" / "map.h5", dir / "c" / "map.h5");
}

TEST_F(CliMapSessions, ARecordingOfAnotherPlaceIsRefusedAndTheMapStaysAsItWas) {
  const fs::path dir = scratch_dir("cli_map_sessions_refused");
  CommandResult run = run_featsense("map " + lab() + " -o " + (dir / "lab").string() + kSmall);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path map = dir / "lab" / "map.h5";
  const std::string before = file_bytes(map);
  // In place (the map's own folder), and stopped after a few scans.
  run = run_featsense("map " + corridor() + " --continue " + map.string() + " -o " +
                      (dir / "lab").string() + kSmall + " --set relocalize.max_scans=10");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("could not be placed"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("first 10 scans"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("is unchanged"), std::string::npos) << run.output;
  EXPECT_TRUE(file_bytes(map) == before) << "the map changed";
  const nlohmann::json report = read_json(dir / "lab" / "report.json");
  EXPECT_FALSE(report["relocalization"]["placed"].get<bool>()) << report.dump(2);

  // The poses alone: the lab's own recording placed, the map untouched.
  run = run_featsense("map " + lab() + " --start 12 --continue " + map.string() + " -o " +
                      (dir / "poses").string() + kSmall + " --poses-only");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(read_json(dir / "poses" / "report.json")["relocalization"]["placed"].get<bool>());
  EXPECT_TRUE(fs::exists(dir / "poses" / "trajectory.tum"));
  EXPECT_FALSE(fs::exists(dir / "poses" / "map.h5"));
  EXPECT_TRUE(file_bytes(map) == before) << "the map changed";

  // A map made with given poses keeps no keyframes: it is continued with poses.
  run = run_featsense("map " + lab() + " --end 5 --gt " + lab() + "/gt_trajectory.tum -o " +
                      (dir / "given").string() + kSmall);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("map " + lab() + " --start 6 --continue " +
                      (dir / "given" / "map.h5").string() + " -o " + (dir / "more").string() +
                      kSmall);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("keeps no keyframes"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir / "more" / "map.h5"));
}

TEST_F(CliMapSessions, MergeJoinsTwoMapsMadeApart) {
  const fs::path dir = scratch_dir("cli_map_sessions_merge");
  // The second half in a folder of its own without the ground truth: its map starts in its
  // own frame.
  const fs::path second = dir / "second_half";
  fs::create_directories(second);
  for (const auto& entry : fs::directory_iterator(lab())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("gt_", 0) == 0) continue;
    fs::create_symlink(entry.path(), second / name);
  }
  CommandResult run =
      run_featsense("map " + lab() + " --end 11 -o " + (dir / "a").string() + kSmall);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("map " + second.string() + " --start 12 -o " + (dir / "b").string() + kSmall);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("merge " + (dir / "a" / "map.h5").string() + " " +
                      (dir / "b" / "map.h5").string() + " -o " + (dir / "c.h5").string() +
                      " --quiet --backend cpu");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = read_json(dir / "c.report.json");
  EXPECT_TRUE(report["placed"].get<bool>()) << report.dump(2);
  ASSERT_EQ(report["sessions"].size(), 2u);
  EXPECT_FALSE(fs::exists(dir / "c.h5.partial"));
  // The second map's poses, placed in the first's frame (the truth's).
  const auto truth = read_positions(fs::path(lab()) / "gt_trajectory.tum");
  const auto merged = read_positions(dir / "c.session1.tum");
  ASSERT_EQ(merged.size(), 12u);
  for (const auto& [stamp, p] : merged) {
    const std::vector<double>& t = truth.at(stamp);
    EXPECT_LT(std::hypot(p[0] - t[0], p[1] - t[1], p[2] - t[2]), 0.05) << stamp;
  }
  storage::Hdf5ChunkStore store(dir / "c.h5");
  EXPECT_EQ(store.read_trajectory().size(), 24u);
  EXPECT_GT(store.keys().size(), 0u);
}

TEST_F(CliMapSessions, KillNineDuringAContinuedRunLeavesTheMapReadable) {
  // A recording long enough that its mapping pass is still running at its first flush, the
  // map continued in its own folder.
  const fs::path dir = scratch_dir("cli_map_sessions_kill");
  const fs::path sequence = dir / "lab";
  CommandResult run =
      run_featsense("simulate --quiet --scene lab --frames 72 -o " + sequence.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path out = dir / "map";
  run = run_featsense("map " + sequence.string() + " --end 23 -o " + out.string() + kSmall);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::vector<storage::ChunkKey> before;
  {
    storage::Hdf5ChunkStore old_map(out / "map.h5");
    before = old_map.keys();
  }
  const pid_t child = spawn_featsense("map " + sequence.string() + " --start 24 --continue " +
                                          (out / "map.h5").string() + " -o " + out.string() +
                                          kSmall + " --set map.flush_interval=1",
                                      dir / "continue.log");
  // The recording is placed first (nothing written), then mapped into the map.
  ASSERT_TRUE(killed_after_first_flush(out / "map.h5.journal", child, std::chrono::seconds(300)));
  storage::Hdf5ChunkStore store(out / "map.h5");  // replays the journal
  for (const storage::ChunkKey& key : before) EXPECT_TRUE(store.read(key).has_value());
  for (const storage::ChunkKey& key : store.keys()) ASSERT_TRUE(store.read(key).has_value());
  EXPECT_GE(store.keys().size(), before.size());
  ASSERT_GE(store.read_sessions().size(), 1u);
  EXPECT_EQ(store.read_sessions()[0].scans, 24u);
  EXPECT_GT(store.read_keyframes().size(), 0u);
  fs::remove_all(sequence);
}

}  // namespace
}  // namespace featsense::test
