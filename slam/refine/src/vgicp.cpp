#include "featsense/slam/refine/vgicp.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Cholesky>

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "featsense/slam/refine/weak_directions.hpp"
#include "featsense/slam/trajectory/rigid_pose.hpp"

namespace featsense::slam::refine {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

VgicpLinearization& operator+=(VgicpLinearization& a, const VgicpLinearization& b) {
  a.cost += b.cost;
  a.gradient += b.gradient;
  a.hessian += b.hessian;
  a.terms += b.terms;
  return a;
}

/// T <- (Exp(w) R, Exp(w) t + v) for the tangent step [w, v].
Eigen::Isometry3d apply_left(const Eigen::Isometry3d& T, const Vector6d& step) {
  const Eigen::Vector3d w = step.head<3>();
  const double angle = w.norm();
  const Eigen::Matrix3d turn = angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                                           : Eigen::Matrix3d::Identity();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = turn * T.linear();
  out.translation() = turn * T.translation() + step.tail<3>();
  // Orthonormal again at every step: a guess that is a product of poses is slightly off
  // SO(3), and a result passed on as the next guess would carry that along.
  return orthonormalised(out);
}

}  // namespace

VgicpFit measure_fit(const VoxelGaussians& target, const GaussianCloud& source,
                     const Eigen::Isometry3d& T, double inlier_distance_m) {
  struct Sum {
    double squared = 0.0;
    size_t inliers = 0;
  };
  const Sum sum = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, source.size(), 512), Sum{},
      [&](const tbb::blocked_range<size_t>& range, Sum s) {
        for (size_t i = range.begin(); i < range.end(); ++i) {
          const Eigen::Vector3d x = T * source.points[i];
          const VoxelGaussian* v = target.at(x);
          if (v == nullptr) continue;
          const double distance = std::abs(v->normal.dot(x - v->mean));
          if (distance < inlier_distance_m) {
            s.squared += distance * distance;
            ++s.inliers;
          }
        }
        return s;
      },
      [](Sum a, const Sum& b) {
        a.squared += b.squared;
        a.inliers += b.inliers;
        return a;
      });
  VgicpFit fit;
  if (sum.inliers > 0) fit.fitness_m = std::sqrt(sum.squared / static_cast<double>(sum.inliers));
  if (source.size() > 0) {
    fit.inlier_fraction = static_cast<double>(sum.inliers) / static_cast<double>(source.size());
  }
  return fit;
}

namespace {

/// A source point and a voxel around it: one term of the cost.
struct Correspondence {
  uint32_t point;
  const VoxelGaussian* voxel;
};

/// The terms at pose T: each source point with the voxel it falls in (voxel_gaussians.hpp).
std::vector<Correspondence> correspond(const VoxelGaussians& target, const GaussianCloud& source,
                                       const Eigen::Isometry3d& T) {
  std::vector<const VoxelGaussian*> voxel_of(source.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, source.size(), 512),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i < range.end(); ++i)
                        voxel_of[i] = target.at(T * source.points[i]);
                    });
  std::vector<Correspondence> out;
  out.reserve(source.size());
  for (size_t i = 0; i < voxel_of.size(); ++i)
    if (voxel_of[i] != nullptr) out.push_back({static_cast<uint32_t>(i), voxel_of[i]});
  return out;
}

/// The cost of the fixed terms at T and, when `derivatives`, its gradient and Hessian.
VgicpLinearization evaluate(const GaussianCloud& source, const std::vector<Correspondence>& terms,
                            const Eigen::Isometry3d& T, bool derivatives,
                            double robust_scale = 0.0) {
  const double k2 = robust_scale * robust_scale;
  const Eigen::Matrix3d R = T.rotation();
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, terms.size(), 512), VgicpLinearization{},
      [&](const tbb::blocked_range<size_t>& range, VgicpLinearization sum) {
        for (size_t k = range.begin(); k < range.end(); ++k) {
          const Correspondence& c = terms[k];
          const Eigen::Vector3d x = T * source.points[c.point];
          const Eigen::Vector3d e = c.voxel->mean - x;
          // The combined covariance is a sum of positive definite ones: its 3x3 inverse in
          // closed form (cofactors) is exact enough and several times cheaper than a solve.
          const Eigen::Matrix3d C =
              c.voxel->covariance + R * source.covariances[c.point] * R.transpose();
          Eigen::Matrix3d W;
          double determinant = 0.0;
          bool invertible = false;
          C.computeInverseAndDetWithCheck(W, determinant, invertible, 1e-12);
          if (!invertible || !(determinant > 0.0)) continue;
          const double d2 = e.dot(W * e);
          // Geman-McClure: rho(d2) = k2 d2 / (k2 + d2), its slope the term's weight
          // (iteratively reweighted least squares).
          const double weight = k2 > 0.0 ? (k2 / (k2 + d2)) * (k2 / (k2 + d2)) : 1.0;
          sum.cost += k2 > 0.0 ? k2 * d2 / (k2 + d2) : d2;
          ++sum.terms;
          if (!derivatives) continue;
          W *= weight;
          // e(step) = mu - (Exp(w) x + v) = e + [x]x w - v to first order.
          Eigen::Matrix<double, 3, 6> J;
          J.leftCols<3>() = skew(x);
          J.rightCols<3>() = -Eigen::Matrix3d::Identity();
          const Eigen::Matrix<double, 6, 3> JtW = J.transpose() * W;
          sum.gradient += JtW * e;
          sum.hessian += JtW * J;
        }
        return sum;
      },
      [](VgicpLinearization a, const VgicpLinearization& b) { return a += b; });
}

}  // namespace

VgicpLinearization linearize(const VoxelGaussians& target, const GaussianCloud& source,
                             const Eigen::Isometry3d& T) {
  return evaluate(source, correspond(target, source, T), T, true);
}

namespace {

/// One source of a registration: its cloud, its pose (updated as the solve goes) and its
/// share of each step (1 for a lone source).
struct Part {
  const GaussianCloud* cloud;
  Eigen::Isometry3d T;
  double share;
  size_t source = 0;  ///< its index among align_shared's sources
};

/// The cost of all parts over their fixed terms and, when `derivatives`, its gradient and
/// Hessian in the shared step (a part's step is its share of it).
VgicpLinearization evaluate_parts(const std::vector<Part>& parts,
                                  const std::vector<std::vector<Correspondence>>& terms,
                                  const std::vector<Eigen::Isometry3d>& poses, bool derivatives,
                                  double robust_scale) {
  VgicpLinearization sum;
  for (size_t i = 0; i < parts.size(); ++i) {
    const VgicpLinearization part =
        evaluate(*parts[i].cloud, terms[i], poses[i], derivatives, robust_scale);
    const double s = parts[i].share;
    sum.cost += part.cost;
    sum.terms += part.terms;
    sum.gradient += s * part.gradient;
    sum.hessian += s * s * part.hessian;
  }
  return sum;
}

/// Each part's terms over `target`'s voxels at its current pose, with those poses.
struct PartTerms {
  std::vector<std::vector<Correspondence>> terms;
  std::vector<Eigen::Isometry3d> poses;
};

PartTerms terms_at(const VoxelGaussians& target, const std::vector<Part>& parts) {
  PartTerms held;
  for (const Part& part : parts) {
    held.terms.push_back(correspond(target, *part.cloud, part.T));
    held.poses.push_back(part.T);
  }
  return held;
}

/// The parts' poses after a shared step.
std::vector<Eigen::Isometry3d> stepped(const std::vector<Part>& parts, const Vector6d& step) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(parts.size());
  for (const Part& part : parts) poses.push_back(apply_left(part.T, part.share * step));
  return poses;
}

/// The steps that minimise the cost of `parts` over `target`'s voxels from their poses, by
/// Levenberg-Marquardt; the parts' poses are updated. Returns the steps taken, for poses
/// that share in the correction without a cloud of their own (apply_steps).
std::vector<Vector6d> solve_parts(const VoxelGaussians& target, std::vector<Part>& parts,
                                  const VgicpSettings& settings, VgicpResult& result) {
  std::vector<Vector6d> steps;
  double lambda = 1e-4;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    ++result.iterations;
    // The terms are found again at every iteration and held while the steps are tried, so
    // that a step is judged on the same terms as the cost it is compared with.
    const PartTerms held = terms_at(target, parts);
    const std::vector<std::vector<Correspondence>>& terms = held.terms;
    const std::vector<Eigen::Isometry3d>& poses = held.poses;
    const VgicpLinearization at = evaluate_parts(parts, terms, poses, true, settings.robust_scale);
    if (at.terms < 6) break;  // too few correspondences to fix a pose
    bool accepted = false;
    bool settled = false;
    Vector6d step = Vector6d::Zero();
    // Levenberg-Marquardt: damp the Gauss-Newton step until it lowers the cost.
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      Matrix6d damped = at.hessian;
      damped.diagonal() += lambda * at.hessian.diagonal().cwiseMax(1e-9);
      step = damped.ldlt().solve(-at.gradient);
      if (!step.allFinite()) break;
      const std::vector<Eigen::Isometry3d> candidate = stepped(parts, step);
      const VgicpLinearization next =
          evaluate_parts(parts, terms, candidate, false, settings.robust_scale);
      if (next.cost <= at.cost) {
        // A step that lowers the cost by a millionth or less: the terms are at their minimum
        // (at fine voxels the points keep trading voxels by fractions of a millimetre).
        settled = at.cost - next.cost <= 1e-6 * at.cost;
        for (size_t i = 0; i < parts.size(); ++i) parts[i].T = candidate[i];
        steps.push_back(step);
        lambda = std::max(lambda / 10.0, 1e-9);
        accepted = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) {
      // No damped step lowers the cost of these terms: at their minimum.
      result.converged = step.allFinite();
      break;
    }
    if (settled || (step.tail<3>().norm() < settings.step_tolerance_m &&
                    10.0 * step.head<3>().norm() < settings.step_tolerance_m)) {
      result.converged = true;
      break;
    }
  }
  return steps;
}

/// The pose that minimises the cost over `target`'s voxels from `guess`: fills the pose,
/// converged and iterations (the diagnostics that need a second look at the result are
/// describe()'s).
VgicpResult solve(const VoxelGaussians& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings) {
  VgicpResult result;
  result.T_target_source = guess;
  if (source.size() == 0 || target.size() == 0 || !guess.matrix().allFinite()) return result;
  std::vector<Part> parts = {{&source, guess, 1.0}};
  solve_parts(target, parts, settings, result);
  if (!parts.front().T.matrix().allFinite()) {
    return VgicpResult{guess, false, result.iterations, 0.0, 0.0, {}};
  }
  result.T_target_source = parts.front().T;
  return result;
}

/// The result's Hessian over `solved` (the voxels it was solved on) and its fitness and
/// inliers over `measured`.
void describe(VgicpResult& result, const VoxelGaussians& solved, const VoxelGaussians& measured,
              const GaussianCloud& source, const VgicpSettings& settings) {
  result.hessian = linearize(solved, source, result.T_target_source).hessian;
  const VgicpFit fit =
      measure_fit(measured, source, result.T_target_source, settings.inlier_distance_m);
  result.fitness_m = fit.fitness_m;
  result.inlier_fraction = fit.inlier_fraction;
}

}  // namespace

VgicpResult align_to_voxels(const VoxelGaussians& target, const GaussianCloud& source,
                            const Eigen::Isometry3d& guess, const VgicpSettings& settings) {
  VgicpResult result = solve(target, source, guess, settings);
  if (source.size() > 0 && target.size() > 0 && result.T_target_source.matrix().allFinite()) {
    describe(result, target, target, source, settings);
  }
  return result;
}

namespace {

std::vector<VoxelGaussians> levels_of(const GaussianCloud& cloud, const VgicpSettings& settings) {
  std::vector<VoxelGaussians> levels;
  levels.reserve(settings.voxel_sizes_m.size());
  for (const double voxel_m : settings.voxel_sizes_m) levels.emplace_back(cloud, voxel_m);
  return levels;
}

}  // namespace

VgicpTarget::VgicpTarget(const GaussianCloud& cloud, const VgicpSettings& settings)
    : levels(levels_of(cloud, settings)), fitness(cloud, settings.fitness_voxel_m) {}

VgicpTarget::VgicpTarget(std::vector<VoxelGaussians> levels_in, VoxelGaussians fitness_in)
    : levels(std::move(levels_in)), fitness(std::move(fitness_in)) {}

VgicpResult align(const VgicpTarget& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings,
                  size_t first_level) {
  VgicpResult result;
  result.T_target_source = guess;
  // A first level beyond the finest is the finest.
  const size_t first = target.levels.empty() ? 0 : std::min(first_level, target.levels.size() - 1);
  for (size_t l = first; l < target.levels.size(); ++l) {
    const int iterations = result.iterations;
    result = solve(target.levels[l], source, result.T_target_source, settings);
    result.iterations += iterations;
  }
  if (!target.levels.empty() && source.size() > 0 && target.levels.back().size() > 0) {
    describe(result, target.levels.back(), target.fitness, source, settings);
  }
  return result;
}

VgicpResult align(const GaussianCloud& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings) {
  return align(VgicpTarget(target, settings), source, guess, settings);
}

namespace {

/// The fit of several sources at their poses, as one cloud.
VgicpFit measure_fit(const VoxelGaussians& target, const std::vector<Part>& parts,
                     double inlier_distance_m) {
  double squared = 0.0, inliers = 0.0, points = 0.0;
  for (const Part& part : parts) {
    const VgicpFit fit = measure_fit(target, *part.cloud, part.T, inlier_distance_m);
    const double n = fit.inlier_fraction * static_cast<double>(part.cloud->size());
    squared += fit.fitness_m * fit.fitness_m * n;
    inliers += n;
    points += static_cast<double>(part.cloud->size());
  }
  VgicpFit fit;
  if (inliers > 0.0) fit.fitness_m = std::sqrt(squared / inliers);
  if (points > 0.0) fit.inlier_fraction = inliers / points;
  return fit;
}

}  // namespace

namespace {

/// The shared correction's Hessian at the solution over the finest voxels decides which of its
/// directions the clouds constrain; the steps lose their part along the weak ones and the parts
/// are moved again from their guesses.
void keep_weak_directions(const VoxelGaussians& finest, const std::vector<SharedSource>& sources,
                          double min_ratio, std::vector<Part>& parts, SharedVgicpResult& result) {
  const PartTerms held = terms_at(finest, parts);
  const VgicpLinearization at = evaluate_parts(parts, held.terms, held.poses, true, 0.0);
  // The turns' lever arm: the points' RMS distance from the centre of rotation (the origin).
  double squares = 0.0;
  size_t points = 0;
  for (const Part& part : parts) {
    for (const Eigen::Vector3d& p : part.cloud->points) squares += (part.T * p).squaredNorm();
    points += part.cloud->size();
  }
  const double lever_arm_m = points > 0 ? std::sqrt(squares / static_cast<double>(points)) : 0.0;
  const WeakDirections weak = weak_directions(at.hessian, lever_arm_m, min_ratio);
  result.weak_directions = weak.count;
  result.weakest_ratio = weak.weakest_ratio;
  if (weak.count == 0) return;
  for (Vector6d& step : result.steps) step = weak.keep_strong * step;
  for (Part& part : parts)
    part.T = apply_steps(sources[part.source].guess, result.steps, part.share);
}

}  // namespace

SharedVgicpResult align_shared(const VgicpTarget& target, const std::vector<SharedSource>& sources,
                               const VgicpSettings& settings) {
  SharedVgicpResult result;
  std::vector<Part> parts;
  for (size_t i = 0; i < sources.size(); ++i) {
    const SharedSource& source = sources[i];
    result.poses.push_back(source.guess);
    if (source.cloud && source.cloud->size() > 0 && source.guess.matrix().allFinite()) {
      parts.push_back({source.cloud, source.guess, source.share, i});
    }
  }
  if (parts.empty() || target.levels.empty() || target.levels.back().size() == 0) return result;
  result.guess_fit = measure_fit(target.fitness, parts, settings.inlier_distance_m);
  VgicpResult solved;
  for (const VoxelGaussians& level : target.levels) {
    if (level.size() == 0) continue;
    solved.converged = false;
    const std::vector<Vector6d> steps = solve_parts(level, parts, settings, solved);
    result.steps.insert(result.steps.end(), steps.begin(), steps.end());
  }
  for (const Part& part : parts) {
    if (!part.T.matrix().allFinite()) return SharedVgicpResult{result.poses, {}, false, 0, {}, {}};
  }
  result.converged = solved.converged;
  result.iterations = solved.iterations;
  if (settings.min_constraint_ratio > 0.0 && !result.steps.empty()) {
    keep_weak_directions(target.levels.back(), sources, settings.min_constraint_ratio, parts,
                         result);
  }
  result.result_fit = measure_fit(target.fitness, parts, settings.inlier_distance_m);
  for (size_t i = 0; i < sources.size(); ++i) {
    result.poses[i] = apply_steps(sources[i].guess, result.steps, sources[i].share);
  }
  return result;
}

Eigen::Isometry3d apply_steps(const Eigen::Isometry3d& guess, const std::vector<Vector6d>& steps,
                              double share) {
  Eigen::Isometry3d T = guess;
  for (const Vector6d& step : steps) T = apply_left(T, share * step);
  return T;
}

}  // namespace featsense::slam::refine
