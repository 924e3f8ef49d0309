// `featsense map` end to end on a simulated sequence: its outputs, continuing a map, the
// errors users meet, and a run stopped by SIGINT or killed with SIGKILL.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/small_map_options.hpp"
#include "common/spawn_command.hpp"
#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

class CliMap : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    sequence_ = new fs::path(scratch_dir("cli_map_sequence") / "lab");
    const CommandResult sim =
        run_featsense("simulate --quiet --scene lab --frames 24 -o " + sequence_->string());
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  static void TearDownTestSuite() { delete sequence_; }

  static std::string sequence() { return sequence_->string(); }
  static std::string gt() { return (*sequence_ / "gt_trajectory.tum").string(); }

 private:
  static fs::path* sequence_;
};
fs::path* CliMap::sequence_ = nullptr;

size_t count_lines(const fs::path& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.empty() || line[0] == '#' ? 0 : 1;
  return n;
}

TEST_F(CliMap, WritesTheMapThePosesAndTheReport) {
  const fs::path out = scratch_dir("cli_map_outputs");
  const CommandResult run =
      run_featsense("map " + sequence() + " -o " + out.string() + " --gt " + gt() + kSmallMap);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"map.h5", "trajectory.tum", "trajectory.kitti", "report.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  EXPECT_EQ(count_lines(out / "trajectory.tum"), 24u);
  EXPECT_EQ(count_lines(out / "trajectory.kitti"), 24u);

  const nlohmann::json report = read_json(out / "report.json");
  EXPECT_EQ(report["frames"], 24);
  EXPECT_EQ(report["input"]["sensor"], "os1-128");
  EXPECT_NE(report["input"]["detail"].get<std::string>().find("sensor"), std::string::npos)
      << "the report says which sensor model and why";
  EXPECT_EQ(report["backend"], "cpu");
  EXPECT_FALSE(report["interrupted"].get<bool>());
  EXPECT_GT(report["scans_per_s"].get<double>(), 0.0);
  EXPECT_GT(report["peak_rss_mb"].get<double>(), 0.0);
  EXPECT_EQ(report["timings"]["integrate"]["count"], 24);
  EXPECT_GT(report["timings"]["integrate"]["median_ms"].get<double>(), 0.0);
  EXPECT_GE(report["map"]["shifts"].get<int>(), 1) << "the lab walk is longer than 1 m";

  storage::Hdf5ChunkStore store(out / "map.h5");
  EXPECT_NEAR(store.metadata().voxel_size_m, 0.1, 1e-12);
  EXPECT_NEAR(store.metadata().truncation_m, 0.3, 1e-12);
  EXPECT_NE(store.metadata().config_yaml.find("voxel_size: 0.1"), std::string::npos);
  EXPECT_EQ(store.read_trajectory().size(), 24u);
  EXPECT_EQ(store.keys().size(), report["map"]["chunks"].get<size_t>());
  EXPECT_GT(store.keys().size(), 4u);
}

TEST_F(CliMap, WithTilesTheMeshIsATileSetAndThePlanComesFromItsOverview) {
  const fs::path out = scratch_dir("cli_map_tiles");
  const CommandResult run = run_featsense("map " + sequence() + " -o " + out.string() + " --gt " +
                                          gt() + " --tiles" + kSmallMap);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"tiles/tileset.json", "tiles/tiles.json", "topdown.png"})
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  EXPECT_FALSE(fs::exists(out / "mesh.ply")) << "no single mesh with --tiles";
  const nlohmann::json report = read_json(out / "report.json");
  const nlohmann::json& mesh = report["mesh"];
  EXPECT_GT(mesh["tiles"]["tiles"].get<size_t>(), 0u);
  EXPECT_EQ(mesh["triangles"], mesh["tiles"]["triangles"]);
  // The small lab fits the overview's budget at full resolution.
  EXPECT_EQ(mesh["overview_level"], 0);
  EXPECT_TRUE(mesh.contains("plan"));
  // The full-resolution tiles are compared with the truth a region at a time: the figures of
  // the same map meshed whole (the tiles weld into its vertices; completeness is against the
  // points the sensor saw, the same points either way).
  ASSERT_TRUE(report["eval"].contains("mesh")) << report["eval"].dump();
  const fs::path whole_out = scratch_dir("cli_map_tiles_whole");
  const CommandResult whole_run = run_featsense("map " + sequence() + " -o " + whole_out.string() +
                                                " --gt " + gt() + kSmallMap);
  ASSERT_EQ(whole_run.exit_code, 0) << whole_run.output;
  const nlohmann::json& tiled = report["eval"]["mesh"];
  const nlohmann::json whole_report = read_json(whole_out / "report.json");
  const nlohmann::json& whole = whole_report["eval"]["mesh"];
  EXPECT_EQ(tiled["points"], whole["points"]);
  EXPECT_NEAR(tiled["accuracy"]["mean_abs"].get<double>(),
              whole["accuracy"]["mean_abs"].get<double>(), 1e-9);
  EXPECT_NEAR(tiled["accuracy"]["p95"].get<double>(), whole["accuracy"]["p95"].get<double>(), 1e-6);
  EXPECT_NEAR(tiled["completeness"]["0.05"].get<double>(),
              whole["completeness"]["0.05"].get<double>(), 1e-12);
  EXPECT_EQ(tiled["completeness_samples"], whole["completeness_samples"]);
  EXPECT_FALSE(tiled.contains("error_files")) << "the error files colour one mesh";
}

/// Every chunk of two stores is equal, and they hold the same keys.
void expect_same_maps(const fs::path& a, const fs::path& b) {
  storage::Hdf5ChunkStore first(a);
  storage::Hdf5ChunkStore second(b);
  ASSERT_EQ(first.keys(), second.keys());
  for (const storage::ChunkKey& key : first.keys()) {
    EXPECT_TRUE(*first.read(key) == *second.read(key))
        << "chunk " << key.x << " " << key.y << " " << key.z;
  }
}

TEST_F(CliMap, ContinuingAMapGivesTheMapOfOneRun) {
  const fs::path dir = scratch_dir("cli_map_continue");
  const std::string common = " --gt " + gt() + kSmallMap;
  ASSERT_EQ(
      run_featsense("map " + sequence() + " -o " + (dir / "whole").string() + common).exit_code, 0);
  const CommandResult first =
      run_featsense("map " + sequence() + " -o " + (dir / "first").string() + " --end 11" + common);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const CommandResult second =
      run_featsense("map " + sequence() + " -o " + (dir / "second").string() +
                    " --start 12 --continue " + (dir / "first" / "map.h5").string() + common);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_EQ(count_lines(dir / "second" / "trajectory.tum"), 12u);
  storage::Hdf5ChunkStore continued(dir / "second" / "map.h5");
  EXPECT_EQ(continued.read_trajectory().size(), 24u) << "the old poses and the new";
  // Each run is a session of the map: the first one's kept, the second's added after it.
  const std::vector<storage::MapSession> sessions = continued.read_sessions();
  ASSERT_EQ(sessions.size(), 2u);
  for (uint32_t id = 0; id < 2; ++id) {
    EXPECT_EQ(sessions[id].id, id);
    EXPECT_EQ(sessions[id].scans, 12u);
    EXPECT_EQ(sessions[id].placement, "given poses");
    EXPECT_EQ(sessions[id].input, sequence());
  }
  EXPECT_LT(sessions[0].last_stamp_s, sessions[1].first_stamp_s);
  continued.close();
  // The report lists them, this run last.
  const nlohmann::json reported = read_json(dir / "second" / "report.json")["sessions"];
  ASSERT_EQ(reported.size(), 2u) << reported.dump(2);
  EXPECT_EQ(reported[1]["id"], 1);
  EXPECT_EQ(reported[1]["scans"], 12);
  EXPECT_EQ(reported[1]["keyframes"], 0) << "no loop closure with given poses";
  expect_same_maps(dir / "whole" / "map.h5", dir / "second" / "map.h5");
}

TEST_F(CliMap, ContinuingFromAVdbKeepsItsVoxelSize) {
  const fs::path dir = scratch_dir("cli_map_continue_vdb");
  ASSERT_EQ(run_featsense("map " + sequence() + " -o " + (dir / "first").string() +
                          " --end 5 --gt " + gt() + kSmallMap)
                .exit_code,
            0);
  const std::string vdb = (dir / "first.vdb").string();
  const CommandResult exported =
      run_featsense("export " + (dir / "first" / "map.h5").string() + " -o " + vdb);
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  // No voxel size given: the .vdb's 0.1 m wins over the default 0.064 m.
  const CommandResult second = run_featsense(
      "map " + sequence() + " -o " + (dir / "second").string() + " --start 6 --end 8 --gt " + gt() +
      " --quiet --backend cpu --set map.size=[16,16,8] --continue " + vdb);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  storage::Hdf5ChunkStore store(dir / "second" / "map.h5");
  EXPECT_NEAR(store.metadata().voxel_size_m, 0.1, 1e-9);
  EXPECT_NEAR(store.metadata().truncation_m, 0.3, 1e-6);
}

TEST_F(CliMap, ContinuingRejectsAGeometrySetExplicitlyEvenToTheDefault) {
  const fs::path dir = scratch_dir("cli_map_continue_explicit");
  // A map at 5 cm voxels and 0.2 m tau, neither the default (0.064 m, 0.25 m).
  const std::string geometry = " --set map.size=[8,8,4] --set map.shift_threshold=1.0";
  const std::string first = (dir / "first" / "map.h5").string();
  const CommandResult mapped =
      run_featsense("map " + sequence() + " -o " + (dir / "first").string() + " --end 3 --gt " +
                    gt() + " --quiet --backend cpu --no-mesh" + geometry +
                    " --set map.voxel_size=0.05 --set map.truncation=0.2");
  ASSERT_EQ(mapped.exit_code, 0) << mapped.output;
  const std::string continued = "map " + sequence() + " --start 4 --end 5 --gt " + gt() +
                                " --quiet --backend cpu --no-mesh" + geometry + " --continue " +
                                first + " -o ";

  CommandResult r =
      run_featsense(continued + (dir / "voxel").string() + " --set map.voxel_size=0.064");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("map.voxel_size = 0.064 (--set map.voxel_size=0.064) differs from the "
                          "continued map's 0.05 (" +
                          first + ")"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line: " << r.output;

  r = run_featsense(continued + (dir / "tau").string() + " --set map.truncation=0.25");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("map.truncation = 0.25 (--set map.truncation=0.25) differs from the "
                          "continued map's 0.2"),
            std::string::npos)
      << r.output;

  // A config file that states the default counts as setting it too, and is named.
  const fs::path yaml = dir / "defaults.yaml";
  std::ofstream(yaml) << "map:\n  voxel_size: 0.064\n";
  r = run_featsense(continued + (dir / "file").string() + " --config " + yaml.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("map.voxel_size = 0.064 (" + yaml.string() + ":2) differs"),
            std::string::npos)
      << r.output;
  for (const char* name : {"voxel", "tau", "file"}) {
    EXPECT_FALSE(fs::exists(dir / name / "map.h5")) << name;
  }

  // Neither key set: the continued map's voxel size and tau are adopted, and said so.
  r = run_featsense("map " + sequence() + " --start 4 --end 5 --gt " + gt() +
                    " --backend cpu --no-mesh" + geometry + " --continue " + first + " -o " +
                    (dir / "adopted").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("map.voxel_size = 0.05 of the continued map " + first), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("map.truncation = 0.2 of the continued map " + first), std::string::npos)
      << r.output;
  storage::Hdf5ChunkStore store(dir / "adopted" / "map.h5");
  EXPECT_NEAR(store.metadata().voxel_size_m, 0.05, 1e-12);
  EXPECT_NEAR(store.metadata().truncation_m, 0.2, 1e-12);
  EXPECT_EQ(store.read_trajectory().size(), 6u) << "the old poses and the new";
}

TEST_F(CliMap, WithoutGivenPosesTheOdometryEstimatesThem) {
  // The simulated sequence's ground truth sits beside it: the map frame starts at its first
  // pose and the report compares the estimated path with it.
  const fs::path out = scratch_dir("cli_map_odometry") / "out";
  const CommandResult run =
      run_featsense("map " + sequence() + " -o " + out.string() + " --end 11" + kSmallMap);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(count_lines(out / "trajectory.tum"), 12u);
  const nlohmann::json report = read_json(out / "report.json");
  ASSERT_TRUE(report.contains("odometry")) << report.dump(2);
  EXPECT_EQ(report["odometry"]["scans"].get<size_t>(), 12u);
  EXPECT_GT(report["odometry"]["features_per_scan"].get<double>(), 100.0);
  EXPECT_EQ(report["odometry"]["intensity_fusion"], "on");
  ASSERT_TRUE(report["eval"].contains("traj")) << report.dump(2);
  // A sensor moving through a furnished room at walking speed, range noise on: the path
  // within a few centimetres of the truth after 1.1 s.
  EXPECT_LT(report["eval"]["traj"]["ape"]["rmse"].get<double>(), 0.05) << report["eval"].dump(2);
  // The refinement (on by default) held the scans until their poses were final and mapped
  // every one of them; the odometry's own poses are compared with the truth too.
  ASSERT_TRUE(report.contains("refine")) << report.dump(2);
  EXPECT_EQ(report["refine"]["scans"].get<size_t>(), 12u);
  EXPECT_GE(report["refine"]["registrations"].get<size_t>(), 1u);
  EXPECT_GE(report["refine"]["most_scans_held"].get<size_t>(), 2u);
  EXPECT_TRUE(report["eval"].contains("traj_unrefined")) << report["eval"].dump(2);
  EXPECT_EQ(report["timings"]["refine"]["count"].get<size_t>(), 12u);
  for (const char* stage : {"features", "registration"}) {
    EXPECT_EQ(report["odometry"]["timings"][stage]["count"].get<size_t>(), 12u) << stage;
    EXPECT_GT(report["odometry"]["timings"][stage]["median_ms"].get<double>(), 0.0) << stage;
  }

  // A reference trajectory of the user's: the path is compared with it (after alignment).
  const fs::path other = scratch_dir("cli_map_odometry") / "reference";
  const CommandResult referenced =
      run_featsense("map " + sequence() + " -o " + other.string() + " --end 5" + kSmallMap +
                    " --no-mesh --reference-trajectory " + gt());
  ASSERT_EQ(referenced.exit_code, 0) << referenced.output;
  const nlohmann::json second = read_json(other / "report.json");
  ASSERT_TRUE(second["eval"].contains("traj")) << second.dump(2);
  EXPECT_EQ(second["eval"]["traj"]["ape"]["count"].get<size_t>(), 6u);
  EXPECT_LT(second["eval"]["traj"]["ape"]["rmse"].get<double>(), 0.05);
}

TEST_F(CliMap, ClosedLoopsMapTheRecordingAgainWithTheCorrectedPoses) {
  // The walk is 3 m long: with keyframes every 0.3 m and revisits allowed 1 m back, the
  // keyframes close loops with those before them, as a longer run does with a real revisit.
  const std::string loops =
      " --set loop.keyframe_distance=0.3 --set loop.min_separation=1 "
      "--set loop.min_separation_s=0.5";
  const fs::path dir = scratch_dir("cli_map_loops");
  const CommandResult run = run_featsense("map " + sequence() + " -o " + (dir / "out").string() +
                                          kSmallMap + loops + " --no-mesh");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = read_json(dir / "out" / "report.json");
  ASSERT_TRUE(report.contains("loops")) << report.dump(2);
  const nlohmann::json& closed = report["loops"];
  EXPECT_GE(closed["keyframes"].get<size_t>(), 8u) << closed.dump(2);
  ASSERT_GE(closed["accepted"].get<size_t>(), 1u) << closed.dump(2);
  EXPECT_EQ(closed["loops"].size(), closed["accepted"].get<size_t>());
  EXPECT_EQ(closed["second_pass"], "mapped again with the corrected poses");
  EXPECT_EQ(closed["second_pass_run"]["scans"].get<size_t>(), 24u);
  EXPECT_LE(closed["loops"][0]["fitness_m"].get<double>(), 0.12);
  // The map of the second pass replaced the first; the poses are the corrected ones.
  EXPECT_TRUE(fs::exists(dir / "out" / "map.h5"));
  EXPECT_FALSE(fs::exists(dir / "out" / "map.corrected.h5"));
  EXPECT_EQ(count_lines(dir / "out" / "trajectory.tum"), 24u);
  {
    // The map keeps the run as its session, and its keyframes at their corrected poses, for
    // a later recording to be placed by.
    storage::Hdf5ChunkStore stored(dir / "out" / "map.h5");
    const std::vector<storage::TrajectoryPose> poses = stored.read_trajectory();
    EXPECT_EQ(poses.size(), 24u);
    const std::vector<storage::MapSession> sessions = stored.read_sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].scans, 24u);
    EXPECT_EQ(sessions[0].placement, "odometry from the true first pose, loops closed");
    EXPECT_EQ(report["sessions"][0]["keyframes"], closed["keyframes"]);
    const std::vector<storage::StoredKeyframe> keyframes = stored.read_keyframes();
    EXPECT_EQ(keyframes.size(), closed["keyframes"].get<size_t>());
    for (const storage::StoredKeyframe& keyframe : keyframes) {
      EXPECT_EQ(keyframe.session, 0u);
      EXPECT_EQ(keyframe.descriptor.size(),
                static_cast<size_t>(keyframe.descriptor_rows) * keyframe.descriptor_cols);
      EXPECT_GT(keyframe.descriptor_rows, 0u);
      EXPECT_GT(keyframe.points(), 100u);
      const auto at = std::find_if(poses.begin(), poses.end(), [&](const auto& p) {
        return std::abs(p.t_s - keyframe.pose.t_s) < 1e-6;
      });
      ASSERT_NE(at, poses.end()) << keyframe.pose.t_s;
      // The corrected trajectory passes through the keyframes' poses.
      EXPECT_NEAR(at->x, keyframe.pose.x, 1e-3);
      EXPECT_NEAR(at->y, keyframe.pose.y, 1e-3);
      EXPECT_NEAR(at->z, keyframe.pose.z, 1e-3);
    }
  }
  ASSERT_TRUE(report["eval"].contains("traj_before_loops")) << report["eval"].dump(2);
  EXPECT_LT(report["eval"]["traj"]["ape"]["rmse"].get<double>(), 0.05);

  // The poses alone: no map, the same report sections.
  const CommandResult poses =
      run_featsense("map " + sequence() + " -o " + (dir / "poses").string() + kSmallMap + loops +
                    " --poses-only");
  ASSERT_EQ(poses.exit_code, 0) << poses.output;
  EXPECT_FALSE(fs::exists(dir / "poses" / "map.h5"));
  EXPECT_FALSE(fs::exists(dir / "poses" / "mesh.ply"));
  EXPECT_EQ(count_lines(dir / "poses" / "trajectory.tum"), 24u);
  const nlohmann::json poses_report = read_json(dir / "poses" / "report.json");
  EXPECT_EQ(poses_report["loops"]["second_pass"], "--poses-only: no map");

  // Switched off: the report says why.
  const CommandResult off = run_featsense("map " + sequence() + " -o " + (dir / "off").string() +
                                          " --end 5 --no-mesh --no-loop-closure" + kSmallMap);
  ASSERT_EQ(off.exit_code, 0) << off.output;
  const nlohmann::json off_report = read_json(dir / "off" / "report.json");
  EXPECT_EQ(off_report["loops"]["enabled"], false);
  EXPECT_EQ(off_report["loops"]["why"], "loop.enabled is false");
}

TEST_F(CliMap, BadInputGivesOneClearError) {
  const fs::path dir = scratch_dir("cli_map_errors");
  const std::string out = " -o " + (dir / "out").string();

  ASSERT_EQ(
      run_featsense("map " + sequence() + out + " --end 2 --gt " + gt() + kSmallMap).exit_code, 0);
  CommandResult r = run_featsense("map " + sequence() + out + " --end 2 --gt " + gt() + kSmallMap);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("exists; pass --overwrite"), std::string::npos) << r.output;
  EXPECT_EQ(
      run_featsense("map " + sequence() + out + " --end 2 --overwrite --gt " + gt() + kSmallMap)
          .exit_code,
      0);

  r = run_featsense("map " + sequence() + " -o " + (dir / "other").string() + " --gt " + gt() +
                    kSmallMap + " --set map.voxel_size=0.2 --continue " +
                    (dir / "out" / "map.h5").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("map.voxel_size = 0.2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("differs from the continued map's 0.1"), std::string::npos) << r.output;

  const fs::path foreign = dir / "foreign.h5";
  std::ofstream(foreign) << "not an HDF5 file";
  r = run_featsense("map " + sequence() + " -o " + (dir / "other2").string() + " --gt " + gt() +
                    kSmallMap + " --continue " + foreign.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find(foreign.string()), std::string::npos) << r.output;

  const fs::path wrong_times = dir / "late.tum";
  std::ofstream(wrong_times) << "1000.0 0 0 1 0 0 0 1\n1001.0 1 0 1 0 0 0 1\n";
  r = run_featsense("map " + sequence() + " -o " + (dir / "late").string() + " --gt " +
                    wrong_times.string() + kSmallMap);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no scan was mapped: skipped: no pose for scan 0"), std::string::npos)
      << r.output;

  // --backend goes through the config's schema: its message names the option and the key.
  r = run_featsense("map " + sequence() + " -o " + (dir / "gpu").string() + " --gt " + gt() +
                    kSmallMap + " --backend gpu");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("config: --backend gpu: map.backend: unknown value 'gpu'"),
            std::string::npos)
      << r.output;

  r = run_featsense("map " + sequence() + " -o " + (dir / "range").string() + " --gt " + gt() +
                    kSmallMap + " --start ten");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--start: expected a frame index"), std::string::npos) << r.output;
}

/// Frames of the sequence the runs stopped by a signal map: so many that the run is still
/// mapping at its first flush (after 1 s) even on a loaded machine (24 frames, about 1.6 s of
/// mapping on 2 cores, were at times all mapped by then).
constexpr size_t kLongRunFrames = 72;

/// A run of `featsense map` over a long sequence of its own (about 300 MB of frames, removed
/// again when the run's test ends).
class LongRun {
 public:
  explicit LongRun(const std::string& name)
      : sequence_(scratch_dir(name + "_sequence") / "lab"), out_(scratch_dir(name)) {
    const CommandResult sim =
        run_featsense("simulate --quiet --scene lab --frames " + std::to_string(kLongRunFrames) +
                      " -o " + sequence_.string());
    EXPECT_EQ(sim.exit_code, 0) << sim.output;
  }
  ~LongRun() { fs::remove_all(sequence_.parent_path()); }
  LongRun(const LongRun&) = delete;
  LongRun& operator=(const LongRun&) = delete;

  const fs::path& out() const { return out_; }
  pid_t start() const {
    return spawn_featsense("map " + sequence_.string() + " -o " + out_.string() + " --gt " +
                               (sequence_ / "gt_trajectory.tum").string() +
                               " --quiet --backend cpu --set map.flush_interval=1",
                           out_.parent_path() / (out_.filename().string() + ".log"));
  }

 private:
  fs::path sequence_;
  fs::path out_;
};

TEST_F(CliMap, KillNineLeavesAReadableMap) {
  const LongRun run("cli_map_kill");
  const fs::path& out = run.out();
  const pid_t child = run.start();
  ASSERT_TRUE(killed_after_first_flush(out / "map.h5.journal", child));
  storage::Hdf5ChunkStore store(out / "map.h5");  // replays the journal
  EXPECT_GT(store.keys().size(), 0u);
  for (const storage::ChunkKey& key : store.keys()) ASSERT_TRUE(store.read(key).has_value());
}

TEST_F(CliMap, SigintWritesTheMapOfWhatWasRead) {
  const LongRun run("cli_map_sigint");
  const fs::path& out = run.out();
  const pid_t child = run.start();
  ASSERT_TRUE(wait_for_first_flush(out / "map.h5.journal", child))
      << "the run ended before its first flush";
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const nlohmann::json report = read_json(out / "report.json");
  EXPECT_TRUE(report["interrupted"].get<bool>());
  // The signal came while frames were still being mapped: only those read are in the map.
  const size_t frames = report["frames"].get<size_t>();
  EXPECT_GT(frames, 0u);
  EXPECT_LT(frames, kLongRunFrames);
  storage::Hdf5ChunkStore store(out / "map.h5");
  EXPECT_EQ(store.read_trajectory().size(), frames);
  EXPECT_EQ(store.keys().size(), report["map"]["chunks"].get<size_t>());
}

}  // namespace
}  // namespace featsense::test
