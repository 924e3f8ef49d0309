#include "featsense/mapping/map_sessions.hpp"

#include <algorithm>
#include <stdexcept>

#include "featsense/mapping/map_store.hpp"

namespace featsense::mapping {
namespace {

/// Keyframes written between two flushes: each is held in memory until a flush.
constexpr size_t kBatch = 256;

storage::StoredKeyframe stored(const slam::loops::KeyframeRecord& record, uint32_t session,
                               uint32_t index) {
  storage::StoredKeyframe keyframe;
  keyframe.session = session;
  keyframe.index = index;
  slam::Trajectory one;
  one.push_back(record.stamp_ns, record.T_map_sensor);
  keyframe.pose = to_store_poses(one).front();
  const slam::loops::ScanContext& descriptor = record.descriptor;
  if (!descriptor.empty()) {
    keyframe.descriptor_rows = static_cast<uint16_t>(descriptor.rings);
    keyframe.descriptor_cols = static_cast<uint16_t>(descriptor.sectors);
    keyframe.descriptor = descriptor.bins;
  }
  keyframe.cloud_cm = record.cloud.coordinates();
  return keyframe;
}

}  // namespace

uint32_t record_session(storage::Hdf5ChunkStore& store, const SessionDescription& session,
                        const slam::Trajectory& poses,
                        const std::vector<slam::loops::KeyframeRecord>& keyframes) {
  std::vector<storage::MapSession> sessions = store.read_sessions();
  uint32_t id = 0;
  for (const storage::MapSession& earlier : sessions) id = std::max(id, earlier.id + 1);
  storage::MapSession added;
  added.id = id;
  added.input = session.input;
  added.format = session.format;
  added.placement = session.placement;
  added.scans = poses.size();
  if (!poses.empty()) {
    added.first_stamp_s = static_cast<double>(poses.stamps_ns.front()) * 1e-9;
    added.last_stamp_s = static_cast<double>(poses.stamps_ns.back()) * 1e-9;
  }
  sessions.push_back(added);
  store.write_sessions(sessions);
  std::vector<storage::StoredKeyframe> batch;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    batch.push_back(stored(keyframes[i], id, static_cast<uint32_t>(i)));
    if (batch.size() == kBatch || i + 1 == keyframes.size()) {
      store.write_keyframes(batch);
      store.flush();
      batch.clear();
    }
  }
  return id;
}

void copy_sessions(const storage::Hdf5ChunkStore& from, storage::Hdf5ChunkStore& to) {
  const std::vector<storage::MapSession> sessions = from.read_sessions();
  if (!sessions.empty()) to.write_sessions(sessions);
  size_t held = 0;
  for (const storage::KeyframeKey& key : from.keyframe_keys()) {
    if (std::optional<storage::StoredKeyframe> keyframe = from.read_keyframe(key)) {
      to.write_keyframes({*keyframe});
      if (++held % kBatch == 0) to.flush();  // each is held in memory until a flush
    }
  }
}

}  // namespace featsense::mapping
