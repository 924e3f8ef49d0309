#pragma once
// Two maps of the same place, made apart, as one: B is placed in A by the relocalization that
// places a recording (its keyframes, in order, against A's), the sessions of both are linked
// in one pose graph, and every session is mapped again from its input with the corrected
// poses: a TSDF cannot be moved without resampling it, the inputs can be read again.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/mapping/run_events.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/loops/relocalizer.hpp"

namespace featsense::mapping {

struct MergeResult {
  slam::loops::RelocalizationCounts tried;
  /// Where B was placed in A; none: it was not (then nothing was written and `why` says why).
  std::optional<slam::loops::Relocalization> placement;
  std::string why;
  SessionLinks links;
  /// Every session of the merged map, A's then B's, with its final poses.
  std::vector<SessionRemap> sessions;
  /// A's sessions mapped again where they moved, B's all (remap_sessions_where_moved).
  ReintegrationCounts reintegration;
};

/// Reads A and B (each must keep keyframes and name inputs that can be read again), places B
/// in A and writes the merged map to `output` (replaced only once complete), with A's voxel
/// size and tau (with_map_geometry of `config`). Throws std::runtime_error naming the problem;
/// where B cannot be placed, returns the result without a placement and writes nothing.
MergeResult merge_maps(const std::string& first, const std::string& second,
                       const std::filesystem::path& output, config::Config config,
                       const RunEvents& events = {});

}  // namespace featsense::mapping
