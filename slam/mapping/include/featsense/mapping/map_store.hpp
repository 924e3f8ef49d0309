#pragma once
// The store of a mapping run: a new OUT/map.h5, or one that continues an existing
// map (.h5 or .vdb), whose voxel size and tau then win over the configuration.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/mapping/run_events.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::mapping {

struct MapStore {
  std::unique_ptr<storage::Hdf5ChunkStore> store;
  slam::Trajectory earlier_poses;  ///< the trajectory of the map that was continued
  size_t continued_chunks = 0;
};

/// Creates `path` for a map of `config` (an existing file is an error unless `overwrite`),
/// or, with `continue_from`, a copy of that map at `path` (in place when it is `path`).
/// With `continue_from`, `config` must hold the old map's voxel size and tau already
/// (with_continued_geometry); std::logic_error where it does not.
MapStore open_map_store(const std::filesystem::path& path, const config::Config& config,
                        const std::string& sensor_name,
                        const std::optional<std::string>& continue_from, bool overwrite);

/// `config` with the old map's voxel size and tau (`what` names it) where they were not set;
/// a value set explicitly (config file, --set or an option), even to the default, must be
/// the old map's, else ConfigError naming both. A map keeps its geometry: this is decided
/// once, before a run opens anything.
config::Config with_map_geometry(config::Config config, const storage::MapMetadata& old_map,
                                 const std::string& what, const RunEvents& events = {});

/// with_map_geometry of the map at `continue_from` (.h5 or .vdb); `config` as it is where no
/// such file exists (opening the store says so).
config::Config with_continued_geometry(config::Config config, const std::string& continue_from,
                                       const RunEvents& events = {});

/// The trajectory of a store's poses.
slam::Trajectory from_store_poses(const std::vector<storage::TrajectoryPose>& poses);

/// Runs `build`, which writes the map file `partial`, and renames it over `target` once
/// `build` returns: a map is replaced only by a complete one. Where `build` throws, `partial`
/// (and its journal) is removed and the exception passes on.
void build_then_replace(const std::filesystem::path& partial, const std::filesystem::path& target,
                        const std::function<void()>& build);

/// The store's trajectory form of `trajectory`.
std::vector<storage::TrajectoryPose> to_store_poses(const slam::Trajectory& trajectory);

}  // namespace featsense::mapping
