#pragma once
/// Places a new recording in a saved map: each keyframe of the new session (its pose in the
/// session's own frame, which starts at its first scan) is matched against the map's
/// keyframes as a loop would be (ring keys, then the full Scan Context match with its yaw),
/// and the best few candidates at distinct places are verified by voxelized GICP. A keyframe
/// whose verified candidates put it at two places is ambiguous (a block like another one) and
/// places nothing by itself; a later unambiguous keyframe may pick one of its places. Each
/// unambiguous match says where the session's frame lies in the map; the session is placed
/// once `confirmations` keyframes agree on it (a single good-looking
/// fit is a guess, and the map is never merged on a guess). A user's guess of the session's
/// frame adds the map keyframes around it as candidates; it is verified like any other. A
/// match also guesses where the next keyframes lie: each is tried there too, so that a place
/// that looks alike all over (a room, a corridor) is confirmed where the registration from the
/// descriptor alone would slide.
/// Not thread-safe: one caller, keyframes in order.

#include <Eigen/Geometry>

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/map_keyframe.hpp"
#include "featsense/slam/loops/map_layout.hpp"

namespace featsense::slam::loops {

struct RelocalizeSettings {
  /// Descriptor distance, verification (VGICP, fitness, inliers), the keyframes' points and
  /// the odometry's drift, as for loops.
  LoopSettings loop;
  /// Map keyframes compared in full after the ring keys, and how many of those (at distinct
  /// places) are verified for each keyframe.
  size_t ring_candidates = 20;
  size_t verifications = 4;
  /// Keyframes that must agree on the session's place, and how closely (plus the odometry's
  /// drift between them).
  size_t confirmations = static_cast<size_t>(config::RelocalizeConfig{}.confirmations);
  double agreement_m = 0.5;
  double agreement_deg = 2.0;
  /// A user's guess of T_map_session, and how far the truth may lie from it.
  std::optional<Eigen::Isometry3d> guess;
  double guess_radius_m = 10.0;
  size_t guess_candidates = 3;
  /// Whether the guess narrows the search (every place, however proposed, within
  /// guess_radius_m of it and turned at most guess_angle_deg from it) rather than adding its
  /// places to the rest: where the user knows roughly where the sensor is and which way it
  /// faces, a place elsewhere that looks alike is no match, nor the same street seen the other
  /// way.
  bool guess_only = false;
  double guess_angle_deg = 30.0;
};

/// loop.* and relocalize.confirmations of `config`; the rest as RelocalizeSettings{} has it.
RelocalizeSettings relocalize_from_config(const config::Config& config);

/// Why a candidate or a keyframe did not place the session.
struct RelocalizationCounts {
  size_t keyframes = 0;
  size_t candidates = 0;
  size_t verified = 0;
  std::map<std::string, size_t> rejected;  ///< by reason
  std::vector<double> keyframe_ms;
  std::vector<double> layout_ms;  ///< the layout's search, per keyframe where there is one
};

/// The match that placed the session.
struct Relocalization {
  Eigen::Isometry3d T_map_session = Eigen::Isometry3d::Identity();
  size_t keyframe = 0;      ///< the new session's keyframe (count, from 0) that confirmed it
  size_t map_keyframe = 0;  ///< the map keyframe it matched (index into the map's keyframes)
  int64_t stamp_ns = 0;
  std::string found_by;  ///< "descriptor", "guess" or "earlier match"
  double descriptor_distance = 1.0;
  double fitness_m = 0.0;
  double inlier_fraction = 0.0;
  size_t agreeing = 0;  ///< keyframes that agreed on it, this one included
};

/// A candidate place checked by the caller's own registration in place of the map keyframe's
/// cloud (a localizer's, to the map's surface): the place found and the share of the points
/// on the map there, or why it is not the place.
struct PlaceCheck {
  std::optional<Eigen::Isometry3d> T_map_query;
  double fitness_m = 0.0;
  double inlier_fraction = 0.0;
  /// The share of the points where the map observed anything (inlier_fraction is of those):
  /// of two places for one keyframe, the one with more of all its points on the map is
  /// the better (a place that puts the points where the map never looked fits the few
  /// left).
  double coverage = 1.0;
  std::string rejection;  ///< where there is no place
};
/// From the guess of the query keyframe's pose in the map and its points (sensor frame).
using PlaceVerifier = std::function<PlaceCheck(const Eigen::Isometry3d& T_map_query_guess,
                                               const refine::GaussianCloud& cloud)>;

class Relocalizer {
 public:
  /// `map` sorted by (session, index), each keyframe's travelled_m filled. `verifier`, where
  /// given, checks each candidate in place of the registration to the map keyframe's cloud.
  /// `layout`, where given (with a verifier: its places may lie far from any keyframe),
  /// proposes the places where a keyframe's upright columns best fit the map's, for a
  /// keyframe none of whose other candidates holds.
  Relocalizer(std::vector<MapKeyframe> map, const RelocalizeSettings& settings,
              PlaceVerifier verifier = {}, std::shared_ptr<const MapLayout> layout = nullptr);

  /// The next keyframe of the new session: its stamp, its front-end pose in the session's
  /// frame, how far along the session's path, its points in the sensor frame (deskewed,
  /// thinned). Returns the placement once confirmed (and every call after that).
  std::optional<Relocalization> add_keyframe(int64_t stamp_ns,
                                             const Eigen::Isometry3d& T_session_sensor,
                                             double travelled_m,
                                             const std::vector<Eigen::Vector3f>& points);

  const std::optional<Relocalization>& placement() const { return placement_; }
  const RelocalizationCounts& counts() const { return counts_; }
  const std::vector<MapKeyframe>& map() const { return map_; }

 private:
  struct Candidate {
    size_t map_keyframe = 0;
    Eigen::Isometry3d guess;  ///< T_candidate_query
    std::string found_by;
    double descriptor_distance = 1.0;
  };
  struct Hypothesis {
    size_t keyframe = 0;
    double travelled_m = 0.0;
    Eigen::Isometry3d T_map_session;
  };
  std::vector<Candidate> candidates(const ScanContext& descriptor,
                                    const Eigen::Isometry3d& T_session_sensor) const;
  /// The layout's places for a keyframe, but those near a candidate already tried.
  std::vector<Candidate> layout_candidates(const std::vector<Eigen::Vector3f>& points,
                                           const Eigen::Isometry3d& T_session_sensor,
                                           const std::vector<Candidate>& tried);
  /// The map keyframe nearest `at` within `within_m`; map().size() where none is.
  size_t nearest_keyframe(const Eigen::Vector3d& at, double within_m) const;
  bool agree(const Hypothesis& a, const Hypothesis& b) const;
  /// Earlier keyframes with a place that agrees with `hypothesis` (plus its own: 1 at least),
  /// and those without one. An ambiguous keyframe counts once, with any of its places.
  std::pair<size_t, size_t> earlier_keyframes_agreeing(const Hypothesis& hypothesis) const;

  std::vector<MapKeyframe> map_;
  std::vector<Eigen::Isometry3d> map_poses_;
  RelocalizeSettings settings_;
  PlaceVerifier verifier_;
  std::shared_ptr<const MapLayout> layout_;
  std::vector<Hypothesis> hypotheses_;
  std::optional<Relocalization> placement_;
  RelocalizationCounts counts_;
};

}  // namespace featsense::slam::loops
