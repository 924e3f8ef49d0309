#include "scan_to_map.hpp"

#include <ceres/ceres.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/odometry/degeneracy.hpp"
#include "featsense/slam/odometry/feature_fit.hpp"
#include "featsense/slam/odometry/huber_folding.hpp"
#include "featsense/slam/odometry/point_residuals.hpp"
#include "featsense/slam/odometry/pose_tangent.hpp"

namespace featsense::slam::odometry {
namespace {

constexpr int kNeighbours = 5;
/// Fewer correspondences than this do not pin 6 degrees of freedom down reliably.
constexpr size_t kMinCorrespondences = 10;
/// An outer loop that moves the pose less than this ends the registration: far below the
/// range noise, and small enough that the errors it leaves do not add up over a run.
constexpr double kSettledMoveM = 1e-4;
/// A scan point that has moved less than this since its last search keeps its line or plane.
constexpr double kReuseDistanceM = 0.02;

/// Residuals per Ceres cost function: Ceres' overhead per block (a virtual call, the loss, a
/// Jacobian block written into the problem's matrix) costs more than a residual itself.
constexpr size_t kResidualsPerBlock = 64;

/// `count` residuals from `first` on, each under Huber's loss (folded in, huber_folding.hpp).
template <class Residual>
class RobustBatchCost final : public ceres::CostFunction {
 public:
  RobustBatchCost(const Residual* first, size_t count, double huber)
      : first_(first), count_(count), huber_(huber) {
    set_num_residuals(static_cast<int>(count * Residual::kResiduals));
    mutable_parameter_block_sizes()->assign({4, 3});
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    constexpr int rows = Residual::kResiduals;
    double* jq = jacobians != nullptr ? jacobians[0] : nullptr;
    double* jt = jacobians != nullptr ? jacobians[1] : nullptr;
    for (size_t i = 0; i < count_; ++i) {
      double* r = residuals + i * rows;
      double* q_rows = jq != nullptr ? jq + i * rows * 4 : nullptr;
      double* t_rows = jt != nullptr ? jt + i * rows * 3 : nullptr;
      first_[i].evaluate(parameters[0], parameters[1], r, q_rows, t_rows);
      fold_huber(huber_, rows, r, q_rows, t_rows);
    }
    return true;
  }

 private:
  const Residual* first_;
  size_t count_;
  double huber_;
};

/// Adds `residuals` to the problem in blocks of kResidualsPerBlock (they must outlive it).
template <class Residual>
void add_batched(ceres::Problem& problem, const std::vector<Residual>& residuals, double huber,
                 double* q, double* t) {
  for (size_t begin = 0; begin < residuals.size(); begin += kResidualsPerBlock) {
    const size_t count = std::min(kResidualsPerBlock, residuals.size() - begin);
    problem.AddResidualBlock(new RobustBatchCost<Residual>(&residuals[begin], count, huber),
                             nullptr, q, t);
  }
}

struct Correspondences {
  std::vector<PointToLine> lines;
  std::vector<PointToPlane> planes;
  size_t size() const { return lines.size() + planes.size(); }
};

/// Each scan point's line or plane from its last search, and where the point lay then: a
/// point that has moved less than kReuseDistanceM since (the outer loops after the first move
/// the pose by millimetres) keeps it, as its five nearest map points, 0.2 - 0.4 m apart,
/// would be the same.
template <class Residual>
struct MatchCache {
  std::vector<Eigen::Vector3d> searched_at;
  std::vector<std::optional<Residual>> fit;
  std::vector<uint8_t> searched;
};

/// The correspondences of `points` at pose T: `search` finds a map point's neighbours, `make`
/// the residual of a fitted line or plane (or nothing), `cache` keeps them between the outer
/// loops. A point measured `times[i]` after the stamp moves (1 + times[i] / period_s) times as
/// far as the pose (point_residuals.hpp); with period_s 0 the points are rigid.
template <class Residual, class Search, class Make>
std::vector<Residual> match(const std::vector<Eigen::Vector3f>& points,
                            const std::vector<float>& times, double period_s,
                            const Eigen::Isometry3d& T, MatchCache<Residual>& cache,
                            Search&& search, Make&& make) {
  if (cache.fit.size() != points.size()) {
    cache.searched_at.assign(points.size(), Eigen::Vector3d::Zero());
    cache.fit.assign(points.size(), std::nullopt);
    cache.searched.assign(points.size(), 0);
  }
  // The nearest-neighbour searches dominate: both cores share them, the order stays the scan's.
  std::vector<std::optional<Residual>> found(points.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, points.size(), 64),
      [&](const tbb::blocked_range<size_t>& range) {
        std::vector<Eigen::Vector3d> near;
        near.reserve(kNeighbours);
        for (size_t i = range.begin(); i < range.end(); ++i) {
          const Eigen::Vector3d p = points[i].cast<double>();
          const Eigen::Vector3d x = T * p;
          if (!cache.searched[i] || (x - cache.searched_at[i]).norm() >= kReuseDistanceM) {
            search(x, near);
            cache.fit[i] = near.size() == static_cast<size_t>(kNeighbours)
                               ? make(near)
                               : std::optional<Residual>();
            cache.searched_at[i] = x;
            cache.searched[i] = 1;
          }
          if (!cache.fit[i]) continue;
          found[i] = cache.fit[i];
          found[i]->point = p;
          if (period_s > 0.0) {
            found[i]->anchor = x;
            found[i]->gain = 1.0 + static_cast<double>(times[i]) / period_s;
          }
        }
      });
  std::vector<Residual> out;
  for (const auto& f : found) {
    if (f) out.push_back(*f);
  }
  return out;
}

/// The searches' results of one registration, kept between its outer loops.
struct AssociationCache {
  MatchCache<PointToLine> lines;
  MatchCache<PointToPlane> planes;
};

Correspondences associate(const LocalFeatureMap& map, const TimedFeatures& points, double period_s,
                          const Eigen::Isometry3d& T, double max_distance, double plane_tolerance,
                          AssociationCache& cache) {
  Correspondences c;
  c.lines = match<PointToLine>(
      points.edges, points.edge_time_s, period_s, T, cache.lines,
      [&](const Eigen::Vector3d& x, std::vector<Eigen::Vector3d>& near) {
        map.nearest_edges(x, kNeighbours, max_distance, near);
      },
      [](const std::vector<Eigen::Vector3d>& near) -> std::optional<PointToLine> {
        const auto line = fit_line(near);
        if (!line) return std::nullopt;
        PointToLine residual;
        residual.line_point = line->point;
        residual.direction = line->direction;
        return residual;
      });
  c.planes = match<PointToPlane>(
      points.surfaces, points.surface_time_s, period_s, T, cache.planes,
      [&](const Eigen::Vector3d& x, std::vector<Eigen::Vector3d>& near) {
        map.nearest_surfaces(x, kNeighbours, max_distance, near);
      },
      [plane_tolerance](const std::vector<Eigen::Vector3d>& near) -> std::optional<PointToPlane> {
        const auto plane = fit_plane(near, plane_tolerance);
        if (!plane) return std::nullopt;
        PointToPlane residual;
        residual.normal = plane->normal;
        residual.offset = plane->offset;
        return residual;
      });
  return c;
}

/// The robust cost (Ceres' Huber) and the mean distance of the correspondences at a pose.
struct Cost {
  double robust = 0.0;
  double mean_distance = 0.0;
};

Cost cost_at(const Correspondences& c, const Eigen::Isometry3d& T, double huber) {
  const Eigen::Quaterniond q(T.rotation());
  const Eigen::Vector3d t = T.translation();
  Cost cost;
  auto add = [&](double distance2) {
    cost.robust +=
        distance2 <= huber * huber ? distance2 : 2.0 * huber * std::sqrt(distance2) - huber * huber;
    cost.mean_distance += std::sqrt(distance2);
  };
  for (const PointToLine& l : c.lines) {
    Eigen::Vector3d r;
    l.evaluate(q.coeffs().data(), t.data(), r.data(), nullptr, nullptr);
    add(r.squaredNorm());
  }
  for (const PointToPlane& p : c.planes) {
    double r = 0.0;
    p.evaluate(q.coeffs().data(), t.data(), &r, nullptr, nullptr);
    add(r * r);
  }
  if (c.size() > 0) cost.mean_distance /= static_cast<double>(c.size());
  return cost;
}

/// J^T J over the residual rows, in the tangent [rotation, translation], and the rows'
/// mean square, each clipped at the Huber scale `huber`.
struct Information {
  Matrix6d jtj = Matrix6d::Zero();
  size_t rows = 0;
  double mean_square_m2 = 0.0;

  /// J^T J / N: what degeneracy is judged on.
  Matrix6d per_row() const {
    return rows > 0 ? Matrix6d(jtj / static_cast<double>(rows)) : Matrix6d::Zero();
  }
  /// The inverse covariance: J^T J / s^2.
  Matrix6d precision() const {
    return mean_square_m2 > 0.0 ? Matrix6d(jtj / mean_square_m2) : Matrix6d::Zero();
  }
};

Information information_at(const Correspondences& c, const Eigen::Isometry3d& T, double huber) {
  const Eigen::Quaterniond q(T.rotation());
  const Eigen::Vector3d t = T.translation();
  const double huber2 = huber * huber;
  Information info;
  double squares = 0.0;
  for (const PointToLine& l : c.lines) {
    const Eigen::Matrix<double, 3, 6> j = l.tangent_jacobian(q);
    info.jtj += j.transpose() * j;
    info.rows += 2;  // the residual lies in the plane normal to the line: two rows' worth
    Eigen::Vector3d r;
    l.evaluate(q.coeffs().data(), t.data(), r.data(), nullptr, nullptr);
    squares += std::min(r.squaredNorm(), 2.0 * huber2);
  }
  for (const PointToPlane& p : c.planes) {
    const Eigen::Matrix<double, 1, 6> j = p.tangent_jacobian(q);
    info.jtj += j.transpose() * j;
    info.rows += 1;
    double r = 0.0;
    p.evaluate(q.coeffs().data(), t.data(), &r, nullptr, nullptr);
    squares += std::min(r * r, huber2);
  }
  if (info.rows > 0) info.mean_square_m2 = squares / static_cast<double>(info.rows);
  return info;
}

bool finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// One outer loop's solve: Ceres from `pose` over the correspondences.
Eigen::Isometry3d solve(const Correspondences& c, const Eigen::Isometry3d& pose,
                        const OdometrySettings& settings, int& iterations) {
  Eigen::Quaterniond q(pose.rotation());
  Eigen::Vector3d t = pose.translation();
  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  problem.AddParameterBlock(t.data(), 3);
  add_batched(problem, c.lines, settings.huber_loss_m, q.coeffs().data(), t.data());
  add_batched(problem, c.planes, settings.huber_loss_m, q.coeffs().data(), t.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = settings.solver_iterations;
  // The residual blocks are evaluated in parallel (64 residuals each: worth a thread).
  options.num_threads = tbb::this_task_arena::max_concurrency();
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  // Ceres' own tolerances: a relative change of the cost below 1e-6 or of the pose below
  // 1e-8 ends the solve (tighter ones only spent iterations on digits below the noise).
  options.function_tolerance = 1e-6;
  options.gradient_tolerance = 1e-10;
  options.parameter_tolerance = 1e-8;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  Eigen::Isometry3d solved = Eigen::Isometry3d::Identity();
  solved.linear() = q.normalized().toRotationMatrix();
  solved.translation() = t;
  return solved;
}

}  // namespace

bool settled(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double move_m) {
  const double turn_rad = move_m / 10.0;  // the same move at 10 m
  const Vector6d change = tangent_between(from, to);
  return change.tail<3>().norm() < move_m && change.head<3>().norm() < turn_rad;
}

Eigen::Isometry3d register_to_map(const LocalFeatureMap& map, const TimedFeatures& raw,
                                  const RegistrationStart& start, const OdometrySettings& settings,
                                  OdometryResult& result) {
  const Eigen::Isometry3d& prediction = start.prediction;
  const bool deskew = settings.deskew && start.deskew && start.elapsed_s > 0.0;
  const auto fail = [&](std::string why) {
    result.diagnostics.converged = false;
    result.reason = std::move(why);
    return prediction;
  };

  Eigen::Isometry3d pose = prediction;
  Correspondences c;
  AssociationCache cache;
  int iterations = 0;
  for (int step = 0; step < settings.optimization_steps; ++step) {
    const auto association_start = Clock::now();
    const TimedFeatures points = deskew ? deskewed(raw, SweepMotion(start.previous.inverse() * pose,
                                                                    start.elapsed_s, start.twist))
                                        : raw;
    c = associate(map, points, deskew ? start.elapsed_s : 0.0, pose,
                  settings.max_correspondence_distance_m, settings.plane_tolerance_m, cache);
    result.timing.association_ms += ms_since(association_start);
    if (c.size() < kMinCorrespondences) {
      result.edge_correspondences = c.lines.size();
      result.surface_correspondences = c.planes.size();
      return fail("too few correspondences (" + std::to_string(c.size()) + ")");
    }
    const auto solve_start = Clock::now();
    const Eigen::Isometry3d solved = solve(c, pose, settings, iterations);
    result.timing.solve_ms += ms_since(solve_start);
    if (!finite(solved)) return fail("the solve gave a non-finite pose");
    const bool done = settled(pose, solved, kSettledMoveM);
    pose = solved;
    if (done) break;  // another association would find the same correspondences
  }
  result.diagnostics.iterations = iterations;
  result.edge_correspondences = c.lines.size();
  result.surface_correspondences = c.planes.size();

  // Degeneracy: keep the prediction along the unobservable directions.
  const Information information = information_at(c, pose, settings.huber_loss_m);
  const Degeneracy degeneracy =
      analyse_degeneracy(information.per_row(), settings.degeneracy_threshold);
  result.information_eigenvalues = degeneracy.eigenvalues;
  result.diagnostics.degenerate = degeneracy.degenerate();
  result.degenerate_directions = degeneracy.unobservable;
  if (degeneracy.degenerate()) {
    result.reason = std::to_string(degeneracy.unobservable.size()) +
                    " unobservable direction(s): the prediction is kept along them";
    pose = apply_tangent(prediction,
                         degeneracy.observable_projector * tangent_between(prediction, pose));
  }

  // Divergence: a correction too large for the time elapsed, or worse than the prediction.
  const Vector6d correction = tangent_between(prediction, pose);
  const double dt = std::max(start.elapsed_s, 1e-3);
  if (!correction.allFinite() || correction.tail<3>().norm() > settings.max_speed_m_s * dt ||
      correction.head<3>().norm() > settings.max_turn_rate_rad_s * dt) {
    return fail("diverged: the correction of the prediction is too large for the time elapsed");
  }
  const Cost at_pose = cost_at(c, pose, settings.huber_loss_m);
  const Cost at_prediction = cost_at(c, prediction, settings.huber_loss_m);
  if (!(at_pose.robust <= at_prediction.robust * (1.0 + 1e-9) + 1e-18)) {
    return fail("diverged: the cost is above the prediction's");
  }
  result.diagnostics.fitness_m = at_pose.mean_distance;
  result.diagnostics.converged = true;
  result.precision = information.precision();
  return pose;
}

}  // namespace featsense::slam::odometry
