#include "featsense/slam/loops/relocalizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::slam::loops {
namespace {

/// Candidates closer than this to one already chosen see the same surroundings and would
/// verify to the same place: the verifications go to distinct places instead (a twin block
/// is tens of metres away).
constexpr double kDistinctPlacesM = 4.0;

/// Earlier matches (the latest, at distinct places) whose place for the session is tried as a
/// guess for the next keyframe.
constexpr size_t kMatchGuesses = 2;

/// Two verified places for one keyframe are ambiguous when the worse fit keeps this fraction
/// of the better one's inliers: a block like another one fits as well; a registration that
/// slid along a wall to a place nearby fits clearly worse.
constexpr double kRivalInlierRatio = 0.85;

bool near_any(const std::vector<size_t>& chosen, const std::vector<Eigen::Isometry3d>& poses,
              size_t candidate) {
  return std::any_of(chosen.begin(), chosen.end(), [&](size_t c) {
    return (poses[c].translation() - poses[candidate].translation()).norm() < kDistinctPlacesM;
  });
}

}  // namespace

RelocalizeSettings relocalize_from_config(const config::Config& config) {
  RelocalizeSettings settings;
  settings.loop = from_config(config);
  settings.confirmations = static_cast<size_t>(config.relocalize.confirmations);
  return settings;
}

Relocalizer::Relocalizer(std::vector<MapKeyframe> map, const RelocalizeSettings& settings,
                         PlaceVerifier verifier, std::shared_ptr<const MapLayout> layout)
    : map_(std::move(map)),
      settings_(settings),
      verifier_(std::move(verifier)),
      layout_(verifier_ ? std::move(layout) : nullptr) {
  map_poses_.reserve(map_.size());
  for (const MapKeyframe& keyframe : map_) map_poses_.push_back(keyframe.T_map_sensor);
}

std::vector<Relocalizer::Candidate> Relocalizer::candidates(
    const ScanContext& descriptor, const Eigen::Isometry3d& T_session_sensor) const {
  std::vector<Candidate> out;
  std::vector<size_t> chosen;
  // The user's guess first: the map keyframes nearest where it puts the scan.
  if (settings_.guess) {
    const Eigen::Isometry3d T_map_query = *settings_.guess * T_session_sensor;
    std::vector<std::pair<double, size_t>> by_distance;
    for (size_t j = 0; j < map_.size(); ++j) {
      const double d = (map_poses_[j].translation() - T_map_query.translation()).norm();
      if (d <= settings_.guess_radius_m) by_distance.emplace_back(d, j);
    }
    std::sort(by_distance.begin(), by_distance.end());
    size_t added = 0;
    for (const auto& [d, j] : by_distance) {
      if (added == settings_.guess_candidates) break;
      if (near_any(chosen, map_poses_, j)) continue;
      out.push_back({j, map_poses_[j].inverse() * T_map_query, "guess", 1.0});
      chosen.push_back(j);
      ++added;
    }
  }
  // Where an earlier keyframe's match puts this one (the latest few places, distinct): its
  // descriptor may well pick a keyframe metres away in a place that looks alike all over.
  size_t from_matches = 0;
  for (auto h = hypotheses_.rbegin(); h != hypotheses_.rend() && from_matches < kMatchGuesses;
       ++h) {
    const Eigen::Isometry3d T_map_query = h->T_map_session * T_session_sensor;
    const size_t nearest = nearest_keyframe(T_map_query.translation(), settings_.loop.drift_base_m);
    if (nearest == map_.size() || near_any(chosen, map_poses_, nearest)) continue;
    out.push_back({nearest, map_poses_[nearest].inverse() * T_map_query, "earlier match", 1.0});
    chosen.push_back(nearest);
    ++from_matches;
  }
  // By descriptor: the nearest ring keys, then the full match with its yaw.
  if (descriptor.empty() || map_.empty()) return out;
  std::vector<std::pair<double, size_t>> by_ring;
  by_ring.reserve(map_.size());
  for (size_t j = 0; j < map_.size(); ++j) {
    if (map_[j].descriptor.rings != descriptor.rings ||
        map_[j].descriptor.sectors != descriptor.sectors)
      continue;
    by_ring.emplace_back(ring_key_distance(descriptor, map_[j].descriptor), j);
  }
  const size_t keep = std::min(settings_.ring_candidates, by_ring.size());
  std::partial_sort(by_ring.begin(), by_ring.begin() + static_cast<std::ptrdiff_t>(keep),
                    by_ring.end());
  std::vector<std::pair<ScanContextMatch, size_t>> matches;
  for (size_t k = 0; k < keep; ++k) {
    const size_t j = by_ring[k].second;
    const ScanContextMatch m = match(descriptor, map_[j].descriptor);
    if (m.distance <= settings_.loop.max_descriptor_distance) matches.emplace_back(m, j);
  }
  std::sort(matches.begin(), matches.end(),
            [](const auto& a, const auto& b) { return a.first.distance < b.first.distance; });
  size_t added = 0;
  for (const auto& [m, j] : matches) {
    if (added == settings_.verifications) break;
    if (near_any(chosen, map_poses_, j)) continue;
    out.push_back({j, descriptor_guess(map_poses_[j], T_session_sensor, m.yaw_rad), "descriptor",
                   m.distance});
    chosen.push_back(j);
    ++added;
  }
  return out;
}

size_t Relocalizer::nearest_keyframe(const Eigen::Vector3d& at, double within_m) const {
  size_t nearest = map_.size();
  double best = within_m;
  for (size_t j = 0; j < map_.size(); ++j) {
    const double d = (map_poses_[j].translation() - at).norm();
    if (d <= best) {
      best = d;
      nearest = j;
    }
  }
  return nearest;
}

std::vector<Relocalizer::Candidate> Relocalizer::layout_candidates(
    const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& T_session_sensor,
    const std::vector<Candidate>& tried) {
  std::vector<Candidate> out;
  if (!layout_ || map_.empty()) return out;
  std::vector<Eigen::Vector3d> chosen;
  for (const Candidate& c : tried)
    chosen.push_back((map_poses_[c.map_keyframe] * c.guess).translation());
  const auto start = std::chrono::steady_clock::now();
  const std::vector<LayoutPeak> peaks = layout_->search(points, levelling(T_session_sensor));
  counts_.layout_ms.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  for (const LayoutPeak& peak : peaks) {
    const Eigen::Vector3d at = peak.T_map_query.translation();
    if (std::any_of(chosen.begin(), chosen.end(),
                    [&](const Eigen::Vector3d& c) { return (c - at).norm() < kDistinctPlacesM; }))
      continue;
    // A candidate is kept relative to a map keyframe: the nearest.
    const size_t nearest = nearest_keyframe(at, std::numeric_limits<double>::infinity());
    out.push_back({nearest, map_poses_[nearest].inverse() * peak.T_map_query, "layout", 1.0});
    chosen.push_back(at);
  }
  return out;
}

bool Relocalizer::agree(const Hypothesis& a, const Hypothesis& b) const {
  const double apart_m = std::abs(a.travelled_m - b.travelled_m);
  const double tolerance_m = settings_.agreement_m + settings_.loop.drift_per_m * apart_m;
  const double tolerance_deg = settings_.agreement_deg + settings_.loop.drift_deg_per_m * apart_m;
  return (a.T_map_session.translation() - b.T_map_session.translation()).norm() <= tolerance_m &&
         rotation_angle_deg(a.T_map_session.rotation().transpose() * b.T_map_session.rotation()) <=
             tolerance_deg;
}

std::pair<size_t, size_t> Relocalizer::earlier_keyframes_agreeing(
    const Hypothesis& hypothesis) const {
  // Hypotheses are in keyframe order: one run of them per earlier keyframe.
  size_t agreeing = 1;
  size_t disagreeing = 0;
  for (size_t i = 0; i < hypotheses_.size();) {
    size_t end = i;
    bool agrees = false;
    for (; end < hypotheses_.size() && hypotheses_[end].keyframe == hypotheses_[i].keyframe; ++end)
      agrees = agrees || agree(hypotheses_[end], hypothesis);
    (agrees ? agreeing : disagreeing)++;
    i = end;
  }
  return {agreeing, disagreeing};
}

std::optional<Relocalization> Relocalizer::add_keyframe(
    int64_t stamp_ns, const Eigen::Isometry3d& T_session_sensor, double travelled_m,
    const std::vector<Eigen::Vector3f>& points) {
  if (placement_) return placement_;
  const auto start = std::chrono::steady_clock::now();
  const size_t keyframe = counts_.keyframes++;
  const auto done = [&] {
    counts_.keyframe_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  };
  const LoopSettings& loop = settings_.loop;
  // The points as the map keeps its keyframes' (centimetres), so both sides are alike.
  const std::vector<Eigen::Vector3f> kept = CompactCloud(points).points();
  const ScanContext descriptor = levelled_scan_context(T_session_sensor, kept, loop.scan_context);
  const std::vector<Candidate> found = candidates(descriptor, T_session_sensor);
  const refine::GaussianCloud cloud = refine::with_covariances(kept, loop.neighbours);
  const auto reject = [&](const char* reason) { ++counts_.rejected[reason]; };
  struct Verified {
    const Candidate* candidate;
    refine::VgicpResult result;
    Eigen::Isometry3d T_map_query;
    double coverage = 1.0;
    /// The share of all its points on the map.
    double support() const { return result.inlier_fraction * coverage; }
  };
  std::vector<Verified> verified;
  // Where the guess narrows the search, a place farther from it or turned from it is not
  // tried, nor one that the registration moved there.
  const auto away_from_guess = [&](const Candidate& candidate, const Eigen::Isometry3d& at) {
    if (!settings_.guess || !(settings_.guess_only || candidate.found_by == "guess")) return false;
    const Eigen::Isometry3d believed = *settings_.guess * T_session_sensor;
    if ((at.translation() - believed.translation()).norm() > settings_.guess_radius_m) return true;
    return settings_.guess_only && rotation_angle_deg(believed.rotation().transpose() *
                                                      at.rotation()) > settings_.guess_angle_deg;
  };
  const auto verify = [&](const std::vector<Candidate>& list) {
    counts_.candidates += list.size();
    for (const Candidate& candidate : list) {
      if (away_from_guess(candidate, map_poses_[candidate.map_keyframe] * candidate.guess)) {
        reject("away from the guess");
        continue;
      }
      refine::VgicpResult result;
      std::optional<Eigen::Isometry3d> placed;
      double coverage = 1.0;
      if (verifier_) {
        const PlaceCheck check =
            verifier_(map_poses_[candidate.map_keyframe] * candidate.guess, cloud);
        if (check.T_map_query) {
          placed = check.T_map_query;
          result.T_target_source = map_poses_[candidate.map_keyframe].inverse() * *placed;
          result.converged = true;
          result.fitness_m = check.fitness_m;
          result.inlier_fraction = check.inlier_fraction;
          coverage = check.coverage;
        } else {
          reject(check.rejection.c_str());
        }
      } else {
        const refine::GaussianCloud target = keyframe_target(
            map_, map_poses_, candidate.map_keyframe, loop.target_neighbours, loop.neighbours);
        result = refine::align(target, cloud, candidate.guess, loop.vgicp);
        if (const std::optional<LoopRejection> failed = fit_rejection(result, loop)) {
          reject(to_string(*failed));
        } else {
          placed = map_poses_[candidate.map_keyframe] * result.T_target_source;
        }
      }
      if (!placed) continue;
      const Eigen::Isometry3d T_map_query = *placed;
      if (away_from_guess(candidate, T_map_query)) {
        reject("away from the guess");
        continue;
      }
      ++counts_.verified;
      verified.push_back({&candidate, result, T_map_query, coverage});
    }
  };
  verify(found);
  // The places laid over the whole map only where the keyframe's own proposals hold none: a
  // room or a block that looks alike turned or a street further is found by them too, and
  // where a descriptor already found the place they would only make it ambiguous.
  std::vector<Candidate> wider;
  if (verified.empty()) {
    wider = layout_candidates(kept, T_session_sensor, found);
    verify(wider);
  }
  if (verified.empty()) {
    done();
    return std::nullopt;
  }
  const Verified& best = *std::max_element(
      verified.begin(), verified.end(),
      [](const Verified& a, const Verified& b) { return a.support() < b.support(); });
  const auto session_at = [&](const Verified& v) {
    return Hypothesis{keyframe, travelled_m, v.T_map_query * T_session_sensor.inverse()};
  };
  const bool ambiguous = std::any_of(verified.begin(), verified.end(), [&](const Verified& rival) {
    return (rival.T_map_query.translation() - best.T_map_query.translation()).norm() >
               loop.ambiguity_m &&
           rival.support() >= kRivalInlierRatio * best.support();
  });
  if (ambiguous) {
    // Each of its places stays a hypothesis that a later, unambiguous keyframe may pick.
    counts_.rejected["ambiguous"] += verified.size();
    for (const Verified& v : verified) hypotheses_.push_back(session_at(v));
    done();
    return std::nullopt;
  }
  const Hypothesis hypothesis = session_at(best);
  const auto [agreeing, disagreeing] = earlier_keyframes_agreeing(hypothesis);
  hypotheses_.push_back(hypothesis);
  // Confirmed by enough keyframes, and by more than any other place was.
  if (agreeing >= settings_.confirmations && agreeing > disagreeing) {
    Relocalization placed;
    placed.T_map_session = hypothesis.T_map_session;
    placed.keyframe = keyframe;
    placed.map_keyframe = best.candidate->map_keyframe;
    placed.stamp_ns = stamp_ns;
    placed.found_by = best.candidate->found_by;
    placed.descriptor_distance = best.candidate->descriptor_distance;
    placed.fitness_m = best.result.fitness_m;
    placed.inlier_fraction = best.result.inlier_fraction;
    placed.agreeing = agreeing;
    placement_ = placed;
  } else {
    reject(disagreeing > 0 ? "disagrees with an earlier match" : "awaiting confirmation");
  }
  done();
  return placement_;
}

}  // namespace featsense::slam::loops
