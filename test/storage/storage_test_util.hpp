#pragma once
// Chunks, keyframes and sessions with known contents for the store tests, the metadata they
// use, and the journal beside a map.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "featsense/storage/chunk.hpp"
#include "featsense/storage/chunk_store.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/map_sessions.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::test {

/// A chunk whose observed voxels (about a quarter, with runs as a surface band would make)
/// follow from `seed` alone, so a test can rebuild the expected contents independently.
inline storage::Chunk make_chunk(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(-32767, 32767);
  std::uniform_int_distribution<int> weight(1, 640);
  std::uniform_int_distribution<int> run(1, 200);
  storage::Chunk chunk;
  std::size_t i = rng() % 1000;
  while (i < storage::kChunkVoxels) {
    const std::size_t length = static_cast<std::size_t>(run(rng));
    for (std::size_t j = i; j < i + length && j < storage::kChunkVoxels; ++j) {
      tsdf::Voxel v;
      v.value = static_cast<int16_t>(value(rng));
      v.weight = static_cast<uint16_t>(weight(rng));
      chunk.voxels[j] = tsdf::pack(v);
    }
    i += length * 4;
  }
  return chunk;
}

/// A keyframe whose contents follow from its key alone: a scan-context-sized descriptor
/// (20 x 60) and `points` points.
inline storage::StoredKeyframe make_keyframe(uint32_t session, uint32_t index,
                                             std::size_t points = 1500) {
  std::mt19937 rng(session * 100003u + index);
  std::uniform_real_distribution<float> height(0.0f, 12.0f);
  std::uniform_int_distribution<int> centimetres(-8000, 8000);
  storage::StoredKeyframe keyframe;
  keyframe.session = session;
  keyframe.index = index;
  const double yaw = 0.1 * index;
  keyframe.pose = {100.0 + session * 1000.0 + index,
                   2.0 * index,
                   -1.5 * session,
                   0.25,
                   0.0,
                   0.0,
                   std::sin(yaw / 2),
                   std::cos(yaw / 2)};
  keyframe.descriptor_rows = 20;
  keyframe.descriptor_cols = 60;
  keyframe.descriptor.resize(20 * 60);
  for (float& cell : keyframe.descriptor) cell = height(rng);
  keyframe.cloud_cm.resize(points * 3);
  for (int16_t& value : keyframe.cloud_cm) value = static_cast<int16_t>(centimetres(rng));
  return keyframe;
}

inline bool same_keyframe(const storage::StoredKeyframe& a, const storage::StoredKeyframe& b) {
  const auto& p = a.pose;
  const auto& q = b.pose;
  return a.session == b.session && a.index == b.index && p.t_s == q.t_s && p.x == q.x &&
         p.y == q.y && p.z == q.z && p.qx == q.qx && p.qy == q.qy && p.qz == q.qz && p.qw == q.qw &&
         a.descriptor_rows == b.descriptor_rows && a.descriptor_cols == b.descriptor_cols &&
         a.descriptor == b.descriptor && a.cloud_cm == b.cloud_cm;
}

inline storage::MapSession make_session(uint32_t id, const std::string& placement) {
  storage::MapSession session;
  session.id = id;
  session.input = "/data/drive_" + std::to_string(id) + ".bag";
  session.format = "ros1-bag";
  session.scans = 1000 + id;
  session.first_stamp_s = 1700000000.25 + 3600.0 * id;
  session.last_stamp_s = session.first_stamp_s + 99.9;
  session.placement = placement;
  return session;
}

inline bool same_session(const storage::MapSession& a, const storage::MapSession& b) {
  return a.id == b.id && a.input == b.input && a.format == b.format && a.scans == b.scans &&
         a.first_stamp_s == b.first_stamp_s && a.last_stamp_s == b.last_stamp_s &&
         a.placement == b.placement;
}

inline storage::MapMetadata test_metadata() {
  storage::MapMetadata m;
  m.voxel_size_m = 0.064;
  m.truncation_m = 0.6;
  m.max_weight = 10.0;
  m.sensor = "ouster-os1-64";
  m.config_yaml = "map:\n  voxel_size_m: 0.064\n  truncation_m: 0.6\n";
  return m;
}

/// The journal written beside `map` (storage/FORMAT.md).
inline std::filesystem::path journal_of(const std::filesystem::path& map) {
  return std::filesystem::path(map.string() + ".journal");
}

/// A store that leaves its journal as it is when closed: what a kill leaves behind.
inline storage::StoreSettings no_checkpoint() {
  storage::StoreSettings settings;
  settings.checkpoint_on_close = false;
  return settings;
}

}  // namespace featsense::test
