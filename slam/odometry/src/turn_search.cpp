#include "turn_search.hpp"

#include <cmath>

namespace featsense::slam::odometry {
namespace {

/// A start's fit must be below this share of the first registration's to replace it: the
/// scatter of good fits from start to start is a few percent.
constexpr double kClearlyBetter = 0.8;
/// ... with at least this share of its edge and of its surface correspondences, each: a
/// start that matches fewer points can fit the few it keeps closely and still be wrong, and
/// the edges (posts, corners: tens among thousands of ground points) hold the heading and
/// the travel where the surfaces do not.
constexpr double kKeptCorrespondences = 0.9;

bool keeps_correspondences(const OdometryResult& attempt, const OdometryResult& first) {
  return static_cast<double>(attempt.edge_correspondences) >=
             kKeptCorrespondences * static_cast<double>(first.edge_correspondences) &&
         static_cast<double>(attempt.surface_correspondences) >=
             kKeptCorrespondences * static_cast<double>(first.surface_correspondences);
}

/// What the scan brought to `first` before it was registered (the time since the last scan,
/// its feature counts), without what the registration filled in.
OdometryResult before_registration(const OdometryResult& first) {
  OdometryResult r;
  r.elapsed_s = first.elapsed_s;
  r.scan_edges = first.scan_edges;
  r.scan_surfaces = first.scan_surfaces;
  return r;
}

}  // namespace

std::optional<Eigen::Isometry3d> register_from_turned_starts(
    const LocalFeatureMap& map, const TimedFeatures& raw, const RegistrationStart& start,
    const OdometrySettings& settings, double good_fit_m, OdometryResult& result) {
  const OdometryResult first = result;
  const int steps = static_cast<int>(std::floor(settings.turn_search_deg / kTurnSearchStepDeg));
  std::optional<Eigen::Isometry3d> best;
  OdometryResult best_result;
  const double bar_m =
      first.diagnostics.converged ? kClearlyBetter * first.diagnostics.fitness_m : good_fit_m;
  OdometryResult::Timing spent = result.timing;
  for (int k = -steps; k <= steps; ++k) {
    if (k == 0) continue;
    const double turn_rad = k * kTurnSearchStepDeg * M_PI / 180.0;
    RegistrationStart turned = start;
    // About the vertical through the predicted position: the turn a vehicle or a person
    // makes; the registration itself then corrects the rest.
    turned.prediction.linear() =
        Eigen::AngleAxisd(turn_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        start.prediction.linear();
    OdometryResult attempt = before_registration(first);
    const Eigen::Isometry3d pose = register_to_map(map, raw, turned, settings, attempt);
    spent.association_ms += attempt.timing.association_ms;
    spent.solve_ms += attempt.timing.solve_ms;
    if (!attempt.diagnostics.converged) continue;
    if (!keeps_correspondences(attempt, first)) continue;
    const double fit = attempt.diagnostics.fitness_m;
    if (fit >= bar_m) continue;
    if (best && fit >= best_result.diagnostics.fitness_m) continue;
    best = pose;
    best_result = attempt;
  }
  if (best) result = best_result;
  // The search's time counts where the scan's registration time goes.
  result.timing = spent;
  return best;
}

}  // namespace featsense::slam::odometry
