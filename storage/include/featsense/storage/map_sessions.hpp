#pragma once
/// What a map keeps of the runs that made it: every session (one run of `featsense map`, the
/// first or a continuation) and the keyframes it placed, so that a later recording can be
/// relocalized in the map and loops can be closed across sessions. Plain data, so that the
/// store does not depend on the loop closure whose keyframes these are.

#include <cstddef>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "featsense/storage/chunk_store.hpp"

namespace featsense::storage {

/// A keyframe is identified by its session and its index within that session: writing the
/// same key again replaces the keyframe.
struct KeyframeKey {
  uint32_t session = 0;
  uint32_t index = 0;
  bool operator<(const KeyframeKey& o) const {
    return std::tie(session, index) < std::tie(o.session, o.index);
  }
  bool operator==(const KeyframeKey& o) const { return session == o.session && index == o.index; }
};

struct StoredKeyframe {
  uint32_t session = 0;
  uint32_t index = 0;  ///< within its session
  /// The keyframe's stamp (pose.t_s, seconds) and T_map_sensor, as in the trajectory.
  TrajectoryPose pose;
  /// The place descriptor, `descriptor_rows` x `descriptor_cols` floats, row-major.
  uint16_t descriptor_rows = 0;
  uint16_t descriptor_cols = 0;
  std::vector<float> descriptor;
  /// The keyframe's cloud in the sensor frame: x y z per point, centimetres.
  std::vector<int16_t> cloud_cm;

  KeyframeKey key() const { return {session, index}; }
  std::size_t points() const { return cloud_cm.size() / 3; }
};

/// One run that made or continued the map.
struct MapSession {
  uint32_t id = 0;
  std::string input;   ///< the recording's path, as given
  std::string format;  ///< the reader's format name
  uint64_t scans = 0;
  double first_stamp_s = 0.0;
  double last_stamp_s = 0.0;
  /// How the session was placed in the map: "first session", "relocalized", "given poses", or
  /// any other text.
  std::string placement;
};

}  // namespace featsense::storage
