#pragma once
// A small mapping run for the engine's tests: the analytic box room (an OS1-128 moving
// through a 20 x 20 x 4 m room), its true poses, and a coarse CPU map that takes a second.

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>

#include "featsense/config/config.hpp"
#include "featsense/mapping/mapper.hpp"
#include "featsense/slam/io/box_room_source.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::test {

inline slam::BoxRoomSettings small_room(int frames = 12) {
  slam::BoxRoomSettings room = slam::default_box_room();
  room.frames = frames;
  return room;
}

/// The room's true path, sampled every 5 ms from the first scan's stamp to past the last.
inline slam::Trajectory room_path(const slam::BoxRoomSettings& room) {
  slam::Trajectory path;
  const double seconds = (room.frames + 1) / room.sensor.rate_hz;
  for (double t = 0.0; t <= seconds; t += 0.005) {
    path.push_back(room.start_stamp_ns + static_cast<int64_t>(t * 1e9),
                   slam::box_room_pose(room, t));
  }
  return path;
}

/// A coarse map on the CPU backend: 10 cm voxels, a local map of 16 x 16 x 8 m.
inline config::Config small_map_config() {
  config::Config config;
  config.map.backend = config::Backend::kCpu;
  config.map.voxel_size_m = 0.1;
  config.map.truncation_m = 0.3;
  config.map.size_m = {16.0, 16.0, 8.0};
  config.map.shift_threshold_m = 1.0;
  return config;
}

/// Settings of a Mapper over the room with its true poses, writing `map_path`.
inline mapping::MapperSettings room_mapper_settings(const slam::BoxRoomSettings& room,
                                                    const std::filesystem::path& map_path) {
  mapping::MapperSettings settings;
  settings.config = small_map_config();
  settings.sensor = room.sensor;
  settings.map_path = map_path;
  settings.given_poses = room_path(room);
  settings.session = {"box room", "simulated", "given poses"};
  return settings;
}

/// Every chunk of a map file by its key.
inline std::map<storage::ChunkKey, storage::Chunk> read_chunks(const std::filesystem::path& path) {
  storage::Hdf5ChunkStore store(path);
  std::map<storage::ChunkKey, storage::Chunk> chunks;
  for (const storage::ChunkKey& key : store.keys()) {
    if (std::optional<storage::Chunk> chunk = store.read(key)) chunks.emplace(key, *chunk);
  }
  return chunks;
}

}  // namespace featsense::test
