// A map made again only where scans moved, against a full re-map, with the same poses in both
// (given, so bit for bit the same): the time of each, alternating, and every chunk of the
// result compared with the full re-map's (where it changed) and the map before's (elsewhere).
// Poses after a chosen scan are corrected as a loop closure would: a rigid change that grows
// along the path to a shift and a turn at its end.
//
// Usage: bench_remap_where_moved RECORDING [--from 0.5] [--shift-m 0.03] [--yaw-deg 0.02]
//                                [--rounds 1] [--work DIR]
// RECORDING: a folder of scans with gt_trajectory.tum (featsense simulate). Prints JSON.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/reintegration_plan.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace {

namespace fs = std::filesystem;
using featsense::mapping::SessionRemap;

struct Options {
  std::string recording;
  double from = 0.5;
  double shift_m = 0.03;
  double yaw_deg = 0.02;
  int rounds = 1;
  fs::path work;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&] {
      if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
      return std::string(argv[++i]);
    };
    if (arg == "--from") {
      o.from = std::stod(value());
    } else if (arg == "--shift-m") {
      o.shift_m = std::stod(value());
    } else if (arg == "--yaw-deg") {
      o.yaw_deg = std::stod(value());
    } else if (arg == "--rounds") {
      o.rounds = std::stoi(value());
    } else if (arg == "--work") {
      o.work = value();
    } else if (o.recording.empty()) {
      o.recording = arg;
    } else {
      throw std::invalid_argument("unexpected argument " + arg);
    }
  }
  if (o.recording.empty()) throw std::invalid_argument("no recording given");
  if (o.work.empty()) o.work = fs::temp_directory_path() / "featsense_bench_remap_where_moved";
  return o;
}

/// The poses from scan `from * size` on, corrected by a change that grows to `shift_m` sideways
/// and `yaw_deg` at the last scan.
featsense::slam::Trajectory corrected(const featsense::slam::Trajectory& poses, const Options& o) {
  featsense::slam::Trajectory out;
  const size_t first = static_cast<size_t>(o.from * static_cast<double>(poses.size()));
  for (size_t k = 0; k < poses.size(); ++k) {
    Eigen::Isometry3d pose = poses.poses[k];
    if (k > first) {
      const double f =
          static_cast<double>(k - first) / static_cast<double>(poses.size() - 1 - first);
      Eigen::Isometry3d change = Eigen::Isometry3d::Identity();
      change.translation() = Eigen::Vector3d(0.6 * f, 0.8 * f, 0.1 * f) * o.shift_m;
      change.linear() =
          Eigen::AngleAxisd(f * o.yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).matrix();
      pose = change * pose;
    }
    out.push_back(poses.stamps_ns[k], pose);
  }
  return out;
}

double seconds_of(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int run(const Options& o) {
  namespace mapping = featsense::mapping;
  fs::create_directories(o.work);
  featsense::config::Config config;
  config.map.backend = featsense::config::Backend::kCpu;
  const mapping::PassSettings replay = mapping::pass_settings(config);
  const std::string sensor = "os1-128";
  const auto session = [&](featsense::slam::Trajectory poses) {
    return SessionRemap{{o.recording, "folder", "given poses"}, std::move(poses), {}};
  };
  const fs::path before_path = o.work / "before.h5";
  const featsense::slam::Trajectory truth =
      featsense::slam::read_tum((fs::path(o.recording) / "gt_trajectory.tum").string());
  const double before_s = seconds_of(
      [&] { mapping::remap_sessions({session(truth)}, before_path, replay, config, sensor, {}); });
  const mapping::SavedMap before = mapping::read_saved_map(before_path);
  // As `map --continue` and `merge` have them: the map's own poses, corrected.
  const SessionRemap moved = session(corrected(before.sessions[0].poses, o));

  std::vector<double> full_s;
  std::vector<double> moved_s;
  mapping::ReintegrationCounts counts;
  for (int round = 0; round < o.rounds; ++round) {
    full_s.push_back(seconds_of(
        [&] { mapping::remap_sessions({moved}, o.work / "full.h5", replay, config, sensor, {}); }));
    moved_s.push_back(seconds_of([&] {
      counts = mapping::remap_sessions_where_moved(before, {moved}, o.work / "moved.h5", replay,
                                                   config, sensor, {});
    }));
  }

  const auto plan =
      mapping::plan_reintegration({{before.sessions[0].poses, moved.poses}}, config.map,
                                  mapping::reach_before(config.map, config.map));
  // Chunk by chunk, one of each map in memory at a time.
  featsense::storage::Hdf5ChunkStore old_store(before_path);
  featsense::storage::Hdf5ChunkStore full_store(o.work / "full.h5");
  featsense::storage::Hdf5ChunkStore after_store(o.work / "moved.h5");
  const auto same = [](featsense::storage::Hdf5ChunkStore& a, featsense::storage::Hdf5ChunkStore& b,
                       const featsense::storage::ChunkKey& key) {
    const auto x = a.read(key);
    const auto y = b.read(key);
    return x && y && *x == *y;
  };
  size_t changed_equal = 0, changed_differing = 0, kept_equal = 0, kept_differing = 0;
  for (const auto& key : after_store.keys()) {
    if (plan.changed.count(key) > 0) {
      ++(same(after_store, full_store, key) ? changed_equal : changed_differing);
    } else {
      ++(same(after_store, old_store, key) ? kept_equal : kept_differing);
    }
  }
  std::set<featsense::storage::ChunkKey> present;
  for (const auto& key : after_store.keys()) present.insert(key);
  size_t missing = 0;  // a full re-map's chunk the result lacks, or a kept one it dropped
  for (const auto& key : full_store.keys())
    missing += plan.changed.count(key) > 0 && present.count(key) == 0;
  for (const auto& key : old_store.keys())
    missing += plan.changed.count(key) == 0 && present.count(key) == 0;

  const auto list = [](const std::vector<double>& v) {
    std::string s = "[";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
    return s + "]";
  };
  std::printf(
      "{\"recording\": \"%s\", \"scans\": %zu, \"map_before_s\": %.3f,\n"
      " \"full_remap_s\": %s, \"where_moved_s\": %s,\n"
      " \"scans_moved\": %zu, \"scans_integrated_again\": %zu, \"plan_s\": %.3f, "
      "\"integrate_s\": %.3f, \"assemble_s\": %.3f,\n"
      " \"chunks_made_again\": %zu, \"chunks_kept\": %zu,\n"
      " \"changed_equal_to_full\": %zu, \"changed_differing\": %zu, \"kept_equal_to_before\": "
      "%zu, \"kept_differing\": %zu, \"chunks_missing\": %zu}\n",
      o.recording.c_str(), counts.scans, before_s, list(full_s).c_str(), list(moved_s).c_str(),
      counts.scans_moved, counts.scans_reintegrated, counts.plan_s, counts.reintegrate_s,
      counts.assemble_s, counts.chunks_changed, counts.chunks_kept, changed_equal,
      changed_differing, kept_equal, kept_differing, missing);
  return changed_differing == 0 && kept_differing == 0 && missing == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "bench_remap_where_moved: " << e.what() << "\n";
    return 2;
  }
}
