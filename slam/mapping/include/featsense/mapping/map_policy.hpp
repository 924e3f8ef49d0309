#pragma once
// The decisions of a mapping run after its first pass, each written once as a small function
// with a typed result: whether the recording is mapped again with the poses the loop closure
// corrected, and whether a saved map's earlier sessions are mapped again after a new session
// was linked to them. Both follow one rule: a pose that moved by more than a quarter voxel
// changes the map; less than that, the map stays.

#include <string>

#include "featsense/mapping/loop_stage.hpp"

namespace featsense::mapping {

/// Whether poses that moved by `moved_m` change a map of `voxel_size_m` voxels: more than a
/// quarter voxel.
bool moves_the_map(double moved_m, double voxel_size_m);

/// What became of the second pass (the recording mapped again with corrected poses).
enum class SecondPass {
  kNotNeeded,           ///< no loop closed, no gravity: the first map is final
  kLevelledInPlace,     ///< levelled by gravity alone, no scan moved more than a quarter voxel
  kMapAgain,            ///< the plan: map the recording again with the corrected poses
  kMappedAgain,         ///< done: the map was made again with the corrected poses
  kInterrupted,         ///< stopped: the map keeps the odometry's poses
  kPosesOnly,           ///< no map is made
  kNotReplayable,       ///< the input cannot be read twice: the map keeps the odometry's poses
  kFailed,              ///< the second pass failed: the map keeps the odometry's poses
  kIntoSavedMap,        ///< continued: mapped into the saved map with its placed poses
  kSessionsMappedAgain  ///< continued: every session of the map made again
};

struct SecondPassOutcome {
  SecondPass kind = SecondPass::kNotNeeded;
  std::string reason;  ///< one line for the report
};

/// The plan after a first pass whose loop closure gave `loops` (null: it did not run).
/// `interrupted`: the caller stopped the run; `integrate`: a map is made; `replayable`: the
/// input can be read again.
SecondPassOutcome plan_second_pass(const LoopOutcome* loops, bool interrupted, bool integrate,
                                   bool replayable, double voxel_size_m);

/// What becomes of a saved map's earlier sessions once a new session's links moved their
/// keyframes.
enum class EarlierSessions {
  kUnmoved,      ///< no keyframe moved more than a quarter voxel: the map stays
  kMappedAgain,  ///< every session is mapped again from its input with its corrected poses
  kKept          ///< they moved, but an input cannot be read: the map stays as it was
};

struct EarlierSessionsOutcome {
  EarlierSessions kind = EarlierSessions::kUnmoved;
  std::string reason;  ///< empty where they are mapped again
};

/// `moved_m`: the largest move of an earlier keyframe; `why_unreadable`: why some earlier
/// session's input cannot be read again (empty: all can).
EarlierSessionsOutcome plan_earlier_sessions(double moved_m, double voxel_size_m,
                                             const std::string& why_unreadable);

}  // namespace featsense::mapping
