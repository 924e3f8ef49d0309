#include "featsense/mapping/map_store.hpp"

#include <charconv>
#include <cmath>

#include "featsense/config/config_error.hpp"
#include "featsense/mapping/map_sessions.hpp"
#include "featsense/storage/vdb_io.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;

storage::MapMetadata metadata_of(const config::Config& config, const std::string& sensor_name) {
  storage::MapMetadata m;
  m.voxel_size_m = config.map.voxel_size_m;
  m.truncation_m = config.map.truncation_m;
  m.max_weight = config.map.max_weight;
  m.sensor = sensor_name;
  m.config_yaml = config::to_yaml(config);
  return m;
}

/// The map is built in floats (TsdfSettings), and a .vdb holds its voxel size and tau as
/// floats: values that are the same float are the same.
bool same(double a, double b) { return static_cast<float>(a) == static_cast<float>(b); }

/// A length as short text: the float the map uses, in as few digits as tell it apart.
std::string metres(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof(text), static_cast<float>(value)).ptr;
  return std::string(text, end);
}

/// A continued map's geometry must have been adopted before its store is opened.
void check_geometry(const storage::MapMetadata& old_map, const std::string& what,
                    const config::Config& config) {
  if (same(config.map.voxel_size_m, old_map.voxel_size_m) &&
      same(config.map.truncation_m, old_map.truncation_m))
    return;
  throw std::logic_error("the configuration does not hold the voxel size and tau of " + what +
                         " (with_continued_geometry)");
}

/// Copies every chunk of `from` into `to`.
size_t copy_chunks(storage::ChunkStore& from, storage::ChunkStore& to) {
  size_t copied = 0;
  for (const storage::ChunkKey& key : from.keys()) {
    if (std::optional<storage::Chunk> chunk = from.read(key)) {
      to.write(key, *chunk);
      ++copied;
    }
  }
  return copied;
}

}  // namespace

slam::Trajectory from_store_poses(const std::vector<storage::TrajectoryPose>& poses) {
  slam::Trajectory trajectory;
  for (const storage::TrajectoryPose& p : poses) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond(p.qw, p.qx, p.qy, p.qz).normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(p.x, p.y, p.z);
    trajectory.push_back(static_cast<int64_t>(std::llround(p.t_s * 1e9)), pose);
  }
  return trajectory;
}

config::Config with_map_geometry(config::Config config, const storage::MapMetadata& old_map,
                                 const std::string& what, const RunEvents& events) {
  const auto adopt = [&](const std::string& key, double& value, double old_value) {
    const auto given = config.explicit_keys.find(key);
    if (given != config.explicit_keys.end() && !same(value, old_value)) {
      throw config::ConfigError(key + " = " + metres(value) + " (" + given->second +
                                ") differs from the continued map's " + metres(old_value) + " (" +
                                what + "); a map keeps its voxel size and tau: leave " + key +
                                " unset to continue it");
    }
    if (!same(value, old_value)) {
      events.info(key + " = " + metres(old_value) + " of the continued map " + what);
    }
    value = old_value;
  };
  adopt("map.voxel_size", config.map.voxel_size_m, old_map.voxel_size_m);
  adopt("map.truncation", config.map.truncation_m, old_map.truncation_m);
  return config;
}

config::Config with_continued_geometry(config::Config config, const std::string& continue_from,
                                       const RunEvents& events) {
  const fs::path path(continue_from);
  if (!fs::exists(path)) return config;
  if (path.extension() == ".vdb")
    return with_map_geometry(std::move(config), storage::read_vdb_metadata(path), continue_from,
                             events);
  storage::Hdf5ChunkStore old_map(path);
  const storage::MapMetadata metadata = old_map.metadata();
  old_map.close();
  return with_map_geometry(std::move(config), metadata, continue_from, events);
}

void build_then_replace(const fs::path& partial, const fs::path& target,
                        const std::function<void()>& build) {
  const fs::path journal = partial.string() + ".journal";
  const auto remove_partial = [&] {
    std::error_code ignored;
    fs::remove(partial, ignored);
    fs::remove(journal, ignored);
  };
  remove_partial();  // a run killed earlier may have left one
  try {
    build();
  } catch (...) {
    remove_partial();
    throw;
  }
  fs::rename(partial, target);
  // Closed cleanly, its journal holds nothing the file does not.
  std::error_code ignored;
  fs::remove(journal, ignored);
}

std::vector<storage::TrajectoryPose> to_store_poses(const slam::Trajectory& trajectory) {
  std::vector<storage::TrajectoryPose> poses;
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const Eigen::Isometry3d& T = trajectory.poses[i];
    const Eigen::Quaterniond q(T.linear());
    storage::TrajectoryPose p;
    p.t_s = static_cast<double>(trajectory.stamps_ns[i]) * 1e-9;
    p.x = T.translation().x();
    p.y = T.translation().y();
    p.z = T.translation().z();
    p.qx = q.x();
    p.qy = q.y();
    p.qz = q.z();
    p.qw = q.w();
    poses.push_back(p);
  }
  return poses;
}

MapStore open_map_store(const fs::path& path, const config::Config& config,
                        const std::string& sensor_name,
                        const std::optional<std::string>& continue_from, bool overwrite) {
  MapStore result;
  const storage::OpenMode create =
      overwrite ? storage::OpenMode::kCreateOverwrite : storage::OpenMode::kCreate;
  if (!continue_from) {
    if (fs::exists(path) && !overwrite) {
      throw std::runtime_error(path.string() +
                               " exists; pass --overwrite to replace it, or --continue it");
    }
    result.store =
        std::make_unique<storage::Hdf5ChunkStore>(path, create, metadata_of(config, sensor_name));
    return result;
  }

  const fs::path old_path(*continue_from);
  if (!fs::exists(old_path))
    throw std::runtime_error("--continue: no such map: " + old_path.string());
  const bool in_place = fs::exists(path) && fs::equivalent(old_path, path);
  if (old_path.extension() == ".vdb") {
    // A .vdb carries voxel size and tau; the rest of the metadata comes from this run.
    check_geometry(storage::read_vdb_metadata(old_path), old_path.string(), config);
    result.store =
        std::make_unique<storage::Hdf5ChunkStore>(path, create, metadata_of(config, sensor_name));
    result.continued_chunks = storage::import_vdb(old_path, *result.store).chunks;
    return result;
  }
  if (in_place) {
    storage::Hdf5ChunkStore probe(old_path);
    check_geometry(probe.metadata(), old_path.string(), config);
    result.earlier_poses = from_store_poses(probe.read_trajectory());
    result.continued_chunks = probe.keys().size();
    probe.close();
    result.store = std::make_unique<storage::Hdf5ChunkStore>(path, storage::OpenMode::kAppend,
                                                             metadata_of(config, sensor_name));
    return result;
  }
  if (fs::exists(path) && !overwrite) {
    throw std::runtime_error(path.string() + " exists; pass --overwrite to replace it");
  }
  storage::Hdf5ChunkStore old_map(old_path);
  check_geometry(old_map.metadata(), old_path.string(), config);
  result.earlier_poses = from_store_poses(old_map.read_trajectory());
  result.store =
      std::make_unique<storage::Hdf5ChunkStore>(path, create, metadata_of(config, sensor_name));
  result.continued_chunks = copy_chunks(old_map, *result.store);
  copy_sessions(old_map, *result.store);
  return result;
}

}  // namespace featsense::mapping
