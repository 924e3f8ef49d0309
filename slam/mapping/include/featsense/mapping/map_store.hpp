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
/// With `continue_from`, config.map.voxel_size and map.truncation are set to the old map's;
/// a configuration that set either explicitly (config.explicit_keys) to another value, the
/// default included, is a ConfigError naming both.
MapStore open_map_store(const std::filesystem::path& path, config::Config& config,
                        const std::string& sensor_name,
                        const std::optional<std::string>& continue_from, bool overwrite,
                        const RunEvents& events = {});

/// The old map's voxel size and tau (`what` names it) win over values that were not set; a
/// value set explicitly (config file, --set or an option), even to the default, must be the
/// old map's, else ConfigError naming both.
void adopt_map_geometry(const storage::MapMetadata& old_map, const std::string& what,
                        config::Config& config, const RunEvents& events = {});

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
