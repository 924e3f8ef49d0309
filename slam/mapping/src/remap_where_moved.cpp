// remap_sessions_where_moved: the plan (reintegration_plan.hpp), the scans it names integrated
// again into a scratch map, then the map after assembled chunk by chunk from the scratch map
// and the map before.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/mapping/map_store.hpp"
#include "featsense/mapping/session_remap.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The local map the map before was made with, from the configuration it keeps; nullopt where
/// it keeps none that reads.
std::optional<config::MapConfig> map_config_of(const SavedMap& before) {
  if (before.metadata.config_yaml.empty()) return std::nullopt;
  try {
    return config::load_config_text(before.metadata.config_yaml, before.path.string()).map;
  } catch (const config::ConfigError&) {
    return std::nullopt;
  }
}

/// Why the map before cannot be kept where nothing moved (empty: it can).
std::string why_whole(const SavedMap& before, const std::vector<SessionRemap>& sessions,
                      const config::Config& config,
                      const std::optional<config::MapConfig>& before_map) {
  if (!config.map.keep_unmoved) return "map.keep_unmoved is false";
  if (sessions.size() < before.sessions.size())
    return "the sessions to map are fewer than the map's";
  for (const SavedSession& s : before.sessions)
    if (s.poses.empty())
      return "session " + std::to_string(s.session.id) + " keeps no poses of its own";
  if (!before_map) return before.path.string() + " keeps no configuration that reads";
  return "";
}

/// The map after: `scratch`'s sessions, poses and keyframes, its chunks where they changed,
/// every other chunk of `before` as stored, still compressed.
void assemble(const fs::path& before_path, const fs::path& scratch_path, const fs::path& into,
              const ChunkSet& changed, ReintegrationCounts& counts) {
  const storage::Hdf5ChunkStore scratch(scratch_path);
  const storage::Hdf5ChunkStore before(before_path);
  counts.chunks_before = before.keys().size();
  const storage::SpliceCounts spliced = storage::splice_maps(
      into, scratch, [&](const storage::ChunkKey& key) { return changed.count(key) > 0; }, before);
  counts.chunks_changed = spliced.from_newer;
  counts.chunks_kept = spliced.from_older;
}

}  // namespace

ReintegrationCounts remap_sessions_where_moved(const SavedMap& before,
                                               const std::vector<SessionRemap>& sessions,
                                               const fs::path& into, const PassSettings& replay,
                                               const config::Config& config,
                                               const std::string& sensor_name,
                                               const RunEvents& events) {
  ReintegrationCounts counts;
  const std::optional<config::MapConfig> before_map = map_config_of(before);
  counts.why = why_whole(before, sessions, config, before_map);
  if (!counts.why.empty()) {
    counts.whole = true;
    const Clock::time_point start = Clock::now();
    counts.scans_reintegrated = remap_sessions(sessions, into, replay, config, sensor_name, events);
    counts.reintegrate_s = seconds_since(start);
    for (const SessionRemap& s : sessions) counts.scans += s.poses.size();
    counts.scans_moved = counts.scans;
    return counts;
  }

  Clock::time_point start = Clock::now();
  std::vector<SessionPoses> poses;
  for (size_t s = 0; s < sessions.size(); ++s) {
    SessionPoses& session = poses.emplace_back();
    if (s < before.sessions.size()) session.before = before.sessions[s].poses;
    session.after = sessions[s].poses;
  }
  const ReintegrationPlan plan =
      plan_reintegration(poses, config.map, reach_before(config.map, *before_map));
  counts.scans = plan.scans;
  counts.scans_moved = plan.scans_moved;
  counts.plan_s = seconds_since(start);
  events.info(
      std::to_string(plan.scans_moved) + " of " + std::to_string(plan.scans) +
      " scans moved by more than a quarter voxel: " + std::to_string(plan.scans_reintegrated) +
      " integrated again for " + std::to_string(plan.changed.size()) + " chunks, the rest of " +
      before.path.string() + " kept as it is");

  start = Clock::now();
  const fs::path scratch = fs::path(into.string() + ".changed");
  const auto remove_scratch = [&] {
    std::error_code ignored;
    fs::remove(scratch, ignored);
    fs::remove(scratch.string() + ".journal", ignored);
  };
  remove_scratch();
  try {
    counts.scans_reintegrated =
        remap_sessions(sessions, scratch, replay, config, sensor_name, events, &plan.sessions);
    counts.reintegrate_s = seconds_since(start);
    if (counts.scans_reintegrated != plan.scans_reintegrated) {
      // A scan of the plan that did not come (unreadable, or not matched to its stamp): the
      // chunks it reaches lack it, as a full re-map's would only if it failed there too.
      events.warn("integrated " + std::to_string(counts.scans_reintegrated) +
                  " scans again where " + std::to_string(plan.scans_reintegrated) +
                  " were planned; the chunks they reach may differ from a full re-map's");
    }
    start = Clock::now();
    assemble(before.path, scratch, into, plan.changed, counts);
    counts.assemble_s = seconds_since(start);
  } catch (...) {
    remove_scratch();
    throw;
  }
  remove_scratch();
  return counts;
}

}  // namespace featsense::mapping
