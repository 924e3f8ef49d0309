#pragma once
/// The keyframes of every session of a map in one pose graph. Each session after the first is
/// linked to the sessions before it where it passes their places: each of its keyframes looks
/// for the nearest earlier-session keyframe within the drift radius (from the current
/// estimate, which every accepted link moves along with the rest of the session), verifies it
/// by voxelized GICP as a loop, and an accepted link becomes a robust edge of the graph. Each
/// session's chain of keyframes is an edge between consecutive keyframes, as placed; a
/// session whose poses were made consistent by its own loops (a stored one) is trusted more
/// than a fresh odometry chain. A session no link reaches is held where it was placed. The
/// first keyframe of the first session is the map frame (fixed).

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/map_keyframe.hpp"
#include "featsense/slam/loops/pose_graph.hpp"

namespace featsense::slam::loops {

struct SessionLinkSettings {
  /// Verification, drift radius, rest between links and edge noise, as for loops.
  LoopSettings loop;
  /// How much more a stored session's chain is trusted than a fresh odometry chain (its
  /// information times this): its own loops made it consistent.
  double stored_chain_trust = 10.0;
  /// Earlier-session keyframes verified per keyframe (at distinct places, nearest first).
  size_t candidates = 1;
};

/// A verified link: keyframe `to` (a later session) seen from keyframe `from`.
struct SessionLink {
  size_t from = 0;  ///< index into the keyframes given
  size_t to = 0;
  uint32_t from_session = 0;
  uint32_t to_session = 0;
  double fitness_m = 0.0;
  double inlier_fraction = 0.0;
  double weight = 1.0;  ///< the graph's final weight of the link
  /// How far the link moved `to` from where the session put it when it was accepted.
  double moved_m = 0.0;
  double moved_deg = 0.0;
};

struct SessionLinkResult {
  /// Every keyframe's pose after the optimisation, in the order given.
  std::vector<Eigen::Isometry3d> poses;
  std::vector<SessionLink> links;
  size_t candidates = 0;
  std::map<std::string, size_t> rejected;  ///< by reason
  /// Sessions no link reached, held where they were placed.
  std::vector<uint32_t> unlinked_sessions;
  PoseGraphSummary summary;
  double link_ms = 0.0;
  double optimise_ms = 0.0;
};

/// `keyframes`: every session's, grouped by session in the order the sessions were made, each
/// session's in order, placed in the map frame, travelled_m filled. `fresh_session`: the one
/// whose chain is a fresh odometry's (none: every session is stored).
SessionLinkResult link_sessions(const std::vector<MapKeyframe>& keyframes,
                                const SessionLinkSettings& settings,
                                std::optional<uint32_t> fresh_session);

}  // namespace featsense::slam::loops
