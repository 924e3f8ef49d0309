#include "featsense/slam/odometry/feature_odometry.hpp"

#include <ceres/ceres.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/odometry/degeneracy.hpp"
#include "featsense/slam/odometry/feature_fit.hpp"
#include "featsense/slam/odometry/local_feature_map.hpp"
#include "featsense/slam/odometry/point_residuals.hpp"
#include "featsense/slam/odometry/voxel_filter.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam::odometry {
namespace {

constexpr int kNeighbours = 5;
/// Fewer correspondences than this do not pin 6 degrees of freedom down reliably.
constexpr size_t kMinCorrespondences = 10;

template <class Residual>
class CostFunction final : public ceres::SizedCostFunction<Residual::kResiduals, 4, 3> {
 public:
  explicit CostFunction(const Residual& residual) : residual_(residual) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residual_.evaluate(parameters[0], parameters[1], residuals,
                       jacobians != nullptr ? jacobians[0] : nullptr,
                       jacobians != nullptr ? jacobians[1] : nullptr);
    return true;
  }

 private:
  Residual residual_;
};

struct Correspondences {
  std::vector<PointToLine> lines;
  std::vector<PointToPlane> planes;
  size_t size() const { return lines.size() + planes.size(); }
};

/// The correspondences of `points` at pose T: `search` gives a map point's neighbours, `make`
/// the residual of a fitted line or plane (or nothing).
template <class Residual, class Search, class Make>
std::vector<Residual> match(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& T,
                            Search&& search, Make&& make) {
  // The nearest-neighbour searches dominate: both cores share them, the order stays the scan's.
  std::vector<std::optional<Residual>> found(points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i < range.end(); ++i) {
                        const Eigen::Vector3d p = points[i].cast<double>();
                        const std::vector<Eigen::Vector3d> near = search(T * p);
                        if (near.size() == static_cast<size_t>(kNeighbours))
                          found[i] = make(p, near);
                      }
                    });
  std::vector<Residual> out;
  for (const auto& f : found) {
    if (f) out.push_back(*f);
  }
  return out;
}

Correspondences associate(const LocalFeatureMap& map, const std::vector<Eigen::Vector3f>& edges,
                          const std::vector<Eigen::Vector3f>& surfaces, const Eigen::Isometry3d& T,
                          double max_distance) {
  Correspondences c;
  c.lines = match<PointToLine>(
      edges, T,
      [&](const Eigen::Vector3d& x) { return map.nearest_edges(x, kNeighbours, max_distance); },
      [](const Eigen::Vector3d& p,
         const std::vector<Eigen::Vector3d>& near) -> std::optional<PointToLine> {
        if (const auto line = fit_line(near)) return PointToLine{p, line->point, line->direction};
        return std::nullopt;
      });
  c.planes = match<PointToPlane>(
      surfaces, T,
      [&](const Eigen::Vector3d& x) { return map.nearest_surfaces(x, kNeighbours, max_distance); },
      [](const Eigen::Vector3d& p,
         const std::vector<Eigen::Vector3d>& near) -> std::optional<PointToPlane> {
        if (const auto plane = fit_plane(near))
          return PointToPlane{p, plane->normal, plane->offset};
        return std::nullopt;
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

/// J^T J / N over the residual rows, in the tangent [rotation, translation].
Matrix6d information_at(const Correspondences& c, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  Matrix6d h = Matrix6d::Zero();
  size_t rows = 0;
  for (const PointToLine& l : c.lines) {
    const Eigen::Matrix<double, 3, 6> j = l.tangent_jacobian(q);
    h += j.transpose() * j;
    rows += 2;  // the residual lies in the plane normal to the line: two rows' worth
  }
  for (const PointToPlane& p : c.planes) {
    const Eigen::Matrix<double, 1, 6> j = p.tangent_jacobian(q);
    h += j.transpose() * j;
    rows += 1;
  }
  return rows > 0 ? Matrix6d(h / static_cast<double>(rows)) : Matrix6d::Zero();
}

/// The motion `m` scaled to `s` times its length (rotation angle and translation).
Eigen::Isometry3d scaled(const Eigen::Isometry3d& m, double s) {
  return interpolate_pose(Eigen::Isometry3d::Identity(), m, s);
}

/// The tangent step [w, dt] from `from` to `to`: to = (Exp(w) R_from, t_from + dt).
Vector6d tangent_between(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  const Eigen::AngleAxisd turn(Eigen::Matrix3d(to.rotation() * from.rotation().transpose()));
  Vector6d d;
  d.head<3>() = turn.angle() * turn.axis();
  d.tail<3>() = to.translation() - from.translation();
  return d;
}

Eigen::Isometry3d apply_tangent(const Eigen::Isometry3d& from, const Vector6d& d) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  const double angle = d.head<3>().norm();
  const Eigen::Matrix3d turn =
      angle > 0.0 ? Eigen::AngleAxisd(angle, d.head<3>() / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
  out.linear() = turn * from.rotation();
  out.translation() = from.translation() + d.tail<3>();
  return out;
}

bool finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

}  // namespace

FeatureOdometry::FeatureOdometry(const OdometrySettings& settings)
    : settings_(settings),
      map_(std::make_unique<LocalFeatureMap>(settings.edge_voxel_m, settings.surface_voxel_m,
                                             settings.map_radius_m)) {}

FeatureOdometry::~FeatureOdometry() = default;

OdometryResult FeatureOdometry::register_scan(const FeatureSet& features) {
  OdometryResult result;
  std::vector<float> edge_times;
  std::vector<float> surface_times;
  const std::vector<Eigen::Vector3f> raw_edges =
      voxel_filter(features.edges, features.edge_time_s, settings_.edge_voxel_m, &edge_times);
  const std::vector<Eigen::Vector3f> raw_surfaces = voxel_filter(
      features.surfaces, features.surface_time_s, settings_.surface_voxel_m, &surface_times);
  // The points in the sensor frame at the stamp: each moved by the part of the motion since
  // the last scan that the sensor had made when it was measured (constant velocity).
  std::vector<Eigen::Vector3f> edges = raw_edges;
  std::vector<Eigen::Vector3f> surfaces = raw_surfaces;
  result.scan_edges = edges.size();
  result.scan_surfaces = surfaces.size();

  // The constant-velocity prediction, scaled to the time since the last scan.
  Eigen::Isometry3d prediction = last_pose_;
  if (started_) {
    result.elapsed_s = static_cast<double>(features.stamp_ns - last_stamp_ns_) * 1e-9;
    if (result.elapsed_s > 0.0 && last_motion_s_ > 0.0) {
      prediction = last_pose_ * scaled(last_motion_, result.elapsed_s / last_motion_s_);
    }
    if (!finite(prediction)) prediction = last_pose_;
  }
  Eigen::Isometry3d pose = prediction;
  const auto deskew_for = [&](const Eigen::Isometry3d& T) {
    if (!settings_.deskew || !started_ || !(result.elapsed_s > 0.0)) return;
    const Eigen::Isometry3d motion = last_pose_.inverse() * T;
    const auto apply = [&](const std::vector<Eigen::Vector3f>& raw, const std::vector<float>& times,
                           std::vector<Eigen::Vector3f>& out) {
      for (size_t i = 0; i < raw.size(); ++i) {
        const double s = static_cast<double>(times[i]) / result.elapsed_s;
        out[i] = (scaled(motion, s) * raw[i].cast<double>()).cast<float>();
      }
    };
    apply(raw_edges, edge_times, edges);
    apply(raw_surfaces, surface_times, surfaces);
  };

  auto finish = [&](const Eigen::Isometry3d& T) {
    deskew_for(T);
    result.T_map_sensor = T;
    result.T_previous_sensor = last_pose_.inverse() * T;
    if (edges.size() + surfaces.size() > 0) map_->add(edges, surfaces, T);
    if (started_ && result.elapsed_s > 0.0) {
      last_motion_ = result.T_previous_sensor;
      last_motion_s_ = result.elapsed_s;
    }
    if (!started_ || result.elapsed_s > 0.0) last_stamp_ns_ = features.stamp_ns;
    started_ = true;
    last_pose_ = T;
    result.map_edges = map_->edge_count();
    result.map_surfaces = map_->surface_count();
    return result;
  };
  auto fail = [&](std::string why) {
    result.diagnostics.converged = false;
    result.reason = std::move(why);
    return finish(prediction);
  };

  if (edges.empty() && surfaces.empty()) return fail("no features");
  if (map_->empty()) {
    result.reason = "first scan: the map starts here";
    return finish(prediction);
  }

  Correspondences c;
  int iterations = 0;
  for (int step = 0; step < settings_.optimization_steps; ++step) {
    deskew_for(pose);
    c = associate(*map_, edges, surfaces, pose, settings_.max_correspondence_distance_m);
    if (c.size() < kMinCorrespondences) {
      result.edge_correspondences = c.lines.size();
      result.surface_correspondences = c.planes.size();
      return fail("too few correspondences (" + std::to_string(c.size()) + ")");
    }
    Eigen::Quaterniond q(pose.rotation());
    Eigen::Vector3d t = pose.translation();
    ceres::Problem::Options problem_options;
    problem_options.enable_fast_removal = false;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(t.data(), 3);
    auto* loss = new ceres::HuberLoss(settings_.huber_loss_m);
    for (const PointToLine& l : c.lines) {
      problem.AddResidualBlock(new CostFunction<PointToLine>(l), loss, q.coeffs().data(), t.data());
    }
    for (const PointToPlane& p : c.planes) {
      problem.AddResidualBlock(new CostFunction<PointToPlane>(p), loss, q.coeffs().data(),
                               t.data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = settings_.solver_iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    options.function_tolerance = 1e-14;
    options.gradient_tolerance = 1e-16;
    options.parameter_tolerance = 1e-14;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    Eigen::Isometry3d solved = Eigen::Isometry3d::Identity();
    solved.linear() = q.normalized().toRotationMatrix();
    solved.translation() = t;
    if (!finite(solved)) return fail("the solve gave a non-finite pose");
    pose = solved;
  }
  result.diagnostics.iterations = iterations;
  result.edge_correspondences = c.lines.size();
  result.surface_correspondences = c.planes.size();

  // Degeneracy: keep the prediction along the unobservable directions.
  const Degeneracy degeneracy =
      analyse_degeneracy(information_at(c, pose), settings_.degeneracy_threshold);
  result.information_eigenvalues = degeneracy.eigenvalues;
  if (degeneracy.degenerate()) {
    result.diagnostics.degenerate = true;
    result.degenerate_directions = degeneracy.unobservable;
    result.reason = std::to_string(degeneracy.unobservable.size()) +
                    " unobservable direction(s): the prediction is kept along them";
    pose = apply_tangent(prediction,
                         degeneracy.observable_projector * tangent_between(prediction, pose));
  }

  // Divergence: a correction too large for the time elapsed, or worse than the prediction.
  const Vector6d correction = tangent_between(prediction, pose);
  const double dt = std::max(result.elapsed_s, 1e-3);
  if (!correction.allFinite() || correction.tail<3>().norm() > settings_.max_speed_m_s * dt ||
      correction.head<3>().norm() > settings_.max_turn_rate_rad_s * dt) {
    return fail("diverged: the correction of the prediction is too large for the time elapsed");
  }
  const Cost at_pose = cost_at(c, pose, settings_.huber_loss_m);
  const Cost at_prediction = cost_at(c, prediction, settings_.huber_loss_m);
  if (!(at_pose.robust <= at_prediction.robust * (1.0 + 1e-9) + 1e-18)) {
    return fail("diverged: the cost is above the prediction's");
  }
  result.diagnostics.fitness_m = at_pose.mean_distance;
  result.diagnostics.converged = true;
  return finish(pose);
}

}  // namespace featsense::slam::odometry
