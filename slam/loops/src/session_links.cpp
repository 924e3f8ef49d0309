#include "featsense/slam/loops/session_links.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "featsense/slam/trajectory/rigid_pose.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::slam::loops {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// Earlier-session keyframes closer than this to a chosen one see the same surroundings.
constexpr double kDistinctPlacesM = 4.0;

/// A session no link reaches is held where it was placed, as firmly as a good registration.
constexpr double kAnchorSigmaM = 0.01;
constexpr double kAnchorSigmaRad = 1e-3;

/// [first, end) of each session's keyframes, in the order given.
std::vector<std::pair<size_t, size_t>> session_blocks(const std::vector<MapKeyframe>& keyframes) {
  std::vector<std::pair<size_t, size_t>> blocks;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    if (i == 0 || keyframes[i].session != keyframes[i - 1].session) blocks.emplace_back(i, i);
    blocks.back().second = i + 1;
  }
  return blocks;
}

}  // namespace

SessionLinkResult link_sessions(const std::vector<MapKeyframe>& keyframes,
                                const SessionLinkSettings& settings,
                                std::optional<uint32_t> fresh_session) {
  SessionLinkResult out;
  const LoopSettings& loop = settings.loop;
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(keyframes.size());
  for (const MapKeyframe& keyframe : keyframes) poses.push_back(keyframe.T_map_sensor);
  if (keyframes.empty()) return out;
  const std::vector<std::pair<size_t, size_t>> blocks = session_blocks(keyframes);

  // Each session's chain as placed, before any link moves its estimates.
  std::vector<PoseGraphEdge> edges;
  for (size_t i = 1; i < keyframes.size(); ++i) {
    if (keyframes[i].session != keyframes[i - 1].session) continue;
    PoseGraphEdge edge;
    edge.from = i - 1;
    edge.to = i;
    edge.T_from_to = poses[i - 1].inverse() * poses[i];
    const double travelled_m =
        std::max(0.0, keyframes[i].travelled_m - keyframes[i - 1].travelled_m);
    edge.information = edge_information(loop, Matrix6d::Zero(), 0, loop.min_sigma_m, travelled_m);
    if (!fresh_session || keyframes[i].session != *fresh_session)
      edge.information *= settings.stored_chain_trust;
    edges.push_back(edge);
  }

  const Clock::time_point link_start = Clock::now();
  const auto reject = [&](const char* reason) { ++out.rejected[reason]; };
  for (size_t b = 1; b < blocks.size(); ++b) {
    const auto [first, end] = blocks[b];
    const size_t earlier_end = first;  // every keyframe of the sessions before this one
    double last_link_m = keyframes[first].travelled_m;
    bool linked = false;
    for (size_t i = first; i < end; ++i) {
      const double since_m = keyframes[i].travelled_m - last_link_m;
      if (linked && since_m < loop.search_rest_m) continue;
      const double radius_m = loop.drift_base_m + loop.drift_per_m * since_m;
      const double radius_deg = loop.drift_base_deg + loop.drift_deg_per_m * since_m;
      std::vector<std::pair<double, size_t>> near;
      for (size_t j = 0; j < earlier_end; ++j) {
        const double d = (poses[j].translation() - poses[i].translation()).norm();
        if (d <= radius_m) near.emplace_back(d, j);
      }
      if (near.empty()) continue;
      std::sort(near.begin(), near.end());
      std::vector<size_t> chosen;
      for (const auto& [d, j] : near) {
        if (chosen.size() == settings.candidates) break;
        const bool same_place = std::any_of(chosen.begin(), chosen.end(), [&](size_t c) {
          return (poses[c].translation() - poses[j].translation()).norm() < kDistinctPlacesM;
        });
        if (!same_place) chosen.push_back(j);
      }
      const refine::GaussianCloud cloud =
          refine::with_covariances(keyframes[i].cloud.points(), loop.neighbours);
      for (const size_t j : chosen) {
        ++out.candidates;
        const refine::GaussianCloud target =
            keyframe_target(keyframes, poses, j, loop.target_neighbours, loop.neighbours);
        const refine::VgicpResult result =
            refine::align(target, cloud, poses[j].inverse() * poses[i], loop.vgicp);
        if (const std::optional<LoopRejection> failed = fit_rejection(result, loop)) {
          reject(to_string(*failed));
          continue;
        }
        const Eigen::Isometry3d T_map_query = orthonormalised(poses[j] * result.T_target_source);
        // How far the link moves the keyframe from where the session put it.
        const double moved_m = (T_map_query.translation() - poses[i].translation()).norm();
        const double moved_deg =
            rotation_angle_deg(T_map_query.rotation().transpose() * poses[i].rotation());
        if (moved_m > radius_m || moved_deg > radius_deg) {
          reject(to_string(LoopRejection::inconsistent));
          continue;
        }
        PoseGraphEdge edge;
        edge.from = j;
        edge.to = i;
        edge.T_from_to = result.T_target_source;
        edge.information =
            edge_information(loop, result.hessian, cloud.size(), result.fitness_m, 0.0);
        edge.loop = true;
        edges.push_back(edge);
        out.links.push_back({j, i, keyframes[j].session, keyframes[i].session, result.fitness_m,
                             result.inlier_fraction, 1.0, moved_m, moved_deg});
        // The rest of the session moves with the keyframe: the next searches start from
        // where this link puts them.
        // Kept orthonormal: each link's move is measured from poses it moved before.
        const Eigen::Isometry3d moved = orthonormalised(T_map_query * poses[i].inverse());
        for (size_t k = i; k < end; ++k) poses[k] = orthonormalised(moved * poses[k]);
        last_link_m = keyframes[i].travelled_m;
        linked = true;
        break;
      }
    }
    if (!linked) {
      out.unlinked_sessions.push_back(keyframes[first].session);
      size_t nearest = 0;
      double best = -1.0;
      for (size_t j = 0; j < earlier_end; ++j) {
        const double d = (poses[j].translation() - poses[first].translation()).norm();
        if (best < 0.0 || d < best) {
          best = d;
          nearest = j;
        }
      }
      PoseGraphEdge anchor;
      anchor.from = nearest;
      anchor.to = first;
      anchor.T_from_to = poses[nearest].inverse() * poses[first];
      anchor.information = Matrix6d::Zero();
      anchor.information.diagonal().head<3>().setConstant(1.0 /
                                                          (kAnchorSigmaRad * kAnchorSigmaRad));
      anchor.information.diagonal().tail<3>().setConstant(1.0 / (kAnchorSigmaM * kAnchorSigmaM));
      edges.push_back(anchor);
    }
  }
  out.link_ms = ms_since(link_start);

  const Clock::time_point optimise_start = Clock::now();
  PoseGraph graph;
  for (const Eigen::Isometry3d& pose : poses) graph.add_node(pose);
  for (const PoseGraphEdge& edge : edges) graph.add_edge(edge);
  if (!out.links.empty()) {
    out.summary = graph.optimize(loop.graph);
    for (size_t k = 0; k < out.links.size() && k < out.summary.loop_weights.size(); ++k)
      out.links[k].weight = out.summary.loop_weights[k];
  }
  out.poses = graph.poses();
  out.optimise_ms = ms_since(optimise_start);
  return out;
}

}  // namespace featsense::slam::loops
