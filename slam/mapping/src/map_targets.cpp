#include "map_targets.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <unordered_set>
#include <utility>
#include <vector>

#include "background_thread.hpp"
#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "map_path.hpp"

namespace featsense::mapping {
namespace {

/// The neighbours whose spread is a keyframe point's covariance.
constexpr int kKeyframeNeighbours = 10;
/// A target's grid of where its places were seen from: cells this wide (a metre moves the
/// range a surface was seen at by at most 0.7 m), from path positions up to this far beyond
/// the target (a map's surface reaches half its local map's width from the path: 20 m by
/// default).
constexpr double kSeenFromCell = 1.0;
constexpr double kSeenFromReach = 60.0;
/// A surface no part of the path within that reach is near counts as seen from this far.
constexpr double kUnseenRange = 100.0;
/// Where the sensor has moved this share of the radius from the current target's centre, the
/// next is asked for, and taken: 7.5 m of travel between, for a radius of 60 m (a car at
/// 10 m/s, 0.75 s; a target took 0.45 s to make on 2 cores, the town drive's).
constexpr double kAskNext = 0.25;
constexpr double kTakeNext = 0.375;

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

MapFit measure_map_fit(const MapTarget& target, const slam::refine::GaussianCloud& cloud,
                       const Eigen::Isometry3d& T, double inlier_distance_m,
                       double surface_angle_sigma_rad) {
  MapFit fit;
  // Each inlier's row and its surface's own sigma, for the map's share of the error.
  std::vector<std::pair<Eigen::Matrix<double, 6, 1>, double>> rows;
  fit.points = cloud.size();
  double squares = 0.0;
  // Each inlier's distance to its plane, as a function of a small motion of the sensor
  // (rotation about the sensor, then translation): its row of the point-to-plane problem.
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  const Eigen::Vector3d sensor = T.translation();
  // The map's vertical in the scan's frame, for how upright each point's surface is.
  const Eigen::Vector3d up = T.linear().row(2).transpose();
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d q = T * cloud.points[i];
    if (target.observed.count(grid_key(grid_index(q, target.block_m))) == 0) continue;
    ++fit.observed;
    const bool upright =
        slam::refine::normal_alignment(cloud.covariances[i], up) <= kUprightMaxNormalZ;
    fit.upright_observed += upright;
    const slam::refine::VoxelGaussian* voxel = target.vgicp.fitness.at(q);
    if (voxel == nullptr) continue;
    const double d = voxel->normal.dot(q - voxel->mean);
    if (std::abs(d) > inlier_distance_m) continue;
    ++fit.inliers;
    fit.upright_inliers += upright;
    squares += d * d;
    const Eigen::Vector3d& n = voxel->normal;
    Eigen::Matrix<double, 6, 1> row;
    row << (q - sensor).cross(n), n;
    information.selfadjointView<Eigen::Upper>().rankUpdate(row);
    if (target.seen_from && surface_angle_sigma_rad > 0.0) {
      const Eigen::Vector3f* from = target.seen_from->nearest(voxel->mean);
      const double sigma = from != nullptr ? surface_sigma(voxel->mean, n, from->cast<double>(),
                                                           surface_angle_sigma_rad)
                                           : surface_angle_sigma_rad * kUnseenRange;
      rows.emplace_back(row, sigma);
    }
  }
  if (fit.observed > 0)
    fit.inlier_fraction = static_cast<double>(fit.inliers) / static_cast<double>(fit.observed);
  if (fit.upright_observed > 0) {
    fit.upright_inlier_fraction =
        static_cast<double>(fit.upright_inliers) / static_cast<double>(fit.upright_observed);
  }
  if (fit.points > 0)
    fit.coverage = static_cast<double>(fit.observed) / static_cast<double>(fit.points);
  if (fit.inliers > 0) fit.fitness_m = std::sqrt(squares / static_cast<double>(fit.inliers));
  if (fit.inliers >= 6) {
    const Eigen::Matrix<double, 6, 6> full = information.selfadjointView<Eigen::Upper>();
    // The pose's covariance (fitness_m^2 per measurement); its largest spread per block.
    Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(full);
    if (lu.isInvertible()) {
      const Eigen::Matrix<double, 6, 6> inverse = lu.inverse();
      const Eigen::Matrix<double, 6, 6> covariance = inverse * fit.fitness_m * fit.fitness_m;
      const auto largest = [](const Eigen::Matrix3d& block) {
        return std::sqrt(std::max(
            0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block, Eigen::EigenvaluesOnly)
                     .eigenvalues()
                     .maxCoeff()));
      };
      fit.rotation_sigma_deg = largest(covariance.topLeftCorner<3, 3>()) * 180.0 / M_PI;
      fit.position_sigma_m = largest(covariance.bottomRightCorner<3, 3>());
      // The pose moves by inverse(information) * row * e for an error e of one surface along
      // its normal. A surface's error is shared by every point on it (it does not average out
      // as the points' spread does): each taken at its sigma with the sign that moves each
      // component most.
      Eigen::Matrix<double, 6, 1> shift = Eigen::Matrix<double, 6, 1>::Zero();
      for (const auto& [row, sigma] : rows) shift += (inverse * row).cwiseAbs() * sigma;
      fit.surface_rotation_deg = shift.head<3>().norm() * 180.0 / M_PI;
      fit.surface_position_m = shift.tail<3>().norm();
    }
  }
  return fit;
}

MapTargets::MapTargets(MapSurface& surface, double radius_m,
                       const slam::refine::VgicpSettings& vgicp, double block_m,
                       const MapPath* path)
    : surface_(surface), radius_m_(radius_m), vgicp_(vgicp), block_m_(block_m), path_(path) {
  if (vgicp_.voxel_sizes_m.empty())
    throw std::invalid_argument("MapTargets: the registration needs at least one voxel size");
  thread_ = std::thread([this] { run(); });
}

MapTargets::~MapTargets() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

std::shared_ptr<const MapTarget> build_map_target(
    MapSurface& surface, const Eigen::Vector3d& centre, double radius_m,
    const std::vector<double>& voxel_sizes_m, double fitness_voxel_m, double block_m,
    double upright_max_normal_z, const KeyframePoints* beyond, const MapPath* path) {
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(radius_m);
  const std::vector<std::shared_ptr<const ChunkSurface>> surfaces =
      surface.surfaces_in(Eigen::AlignedBox3d(centre - reach, centre + reach));
  std::vector<slam::refine::VoxelGaussian> parts;
  std::unordered_set<uint64_t> observed;
  // The observed blocks' columns, each once, for a target searched from above.
  const bool with_upright = upright_max_normal_z >= 0.0;
  std::unordered_set<uint64_t> columns;
  std::vector<Eigen::Vector2f> observed_columns;
  const auto observe = [&](const std::array<int32_t, 3>& block) {
    observed.insert(grid_key(block));
    if (with_upright && columns.insert(grid_key({block[0], block[1], 0})).second)
      observed_columns.emplace_back(static_cast<float>((block[0] + 0.5) * block_m),
                                    static_cast<float>((block[1] + 0.5) * block_m));
  };
  const double radius2 = radius_m * radius_m;
  for (const std::shared_ptr<const ChunkSurface>& chunk : surfaces) {
    for (const SurfaceCell& cell : chunk->cells) {
      if ((cell.mean.cast<double>() - centre).head<2>().squaredNorm() > radius2) continue;
      parts.push_back(to_voxel_gaussian(cell));
    }
    for (const std::array<int32_t, 3>& block : chunk->observed_blocks) observe(block);
  }
  if (beyond != nullptr) {
    // Where the surface observed nothing, the keyframes' points, each with the covariance of
    // its neighbours: a wall the mapping run saw from afar. Their blocks count as observed
    // where they hold one (free space there was not observed).
    std::vector<Eigen::Vector3f> outside;
    for (const Eigen::Vector3f& p : beyond->near(centre, radius_m))
      if (observed.count(grid_key(grid_index(p.cast<double>(), block_m))) == 0)
        outside.push_back(p);
    const slam::refine::GaussianCloud cloud =
        slam::refine::with_covariances(outside, kKeyframeNeighbours);
    for (size_t i = 0; i < cloud.size(); ++i) {
      slam::refine::VoxelGaussian part;
      part.mean = cloud.points[i];
      part.covariance = cloud.covariances[i];
      part.points = 1;
      parts.push_back(part);
      observe(grid_index(cloud.points[i], block_m));
    }
  }
  std::vector<slam::refine::VoxelGaussians> levels;
  for (const double voxel_m : voxel_sizes_m) levels.emplace_back(parts, voxel_m);
  slam::refine::VoxelGaussians fitness(parts, fitness_voxel_m);
  auto made = std::make_shared<MapTarget>(
      centre, slam::refine::VgicpTarget(std::move(levels), std::move(fitness)));
  made->observed = std::move(observed);
  made->block_m = block_m;
  if (path != nullptr)
    made->seen_from.emplace(*path, centre, radius_m, kSeenFromCell, kSeenFromReach);
  if (with_upright) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    for (const slam::refine::VoxelGaussian& part : parts) {
      eigen.computeDirect(part.covariance);
      if (std::abs(eigen.eigenvectors().col(0).z()) <= upright_max_normal_z)
        made->upright.push_back(part.mean.head<2>().cast<float>());
    }
    made->observed_columns = std::move(observed_columns);
  }
  return made;
}

std::shared_ptr<const MapTarget> MapTargets::build(const Eigen::Vector3d& centre) {
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<const MapTarget> target =
      build_map_target(surface_, centre, radius_m_, vgicp_.voxel_sizes_m, vgicp_.fitness_voxel_m,
                       block_m_, -1.0, nullptr, path_);
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.built;
  counts_.build_ms += ms_since(start);
  return target;
}

std::shared_ptr<const MapTarget> MapTargets::around(const Eigen::Vector3d& position) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto near = [&](const std::shared_ptr<const MapTarget>& target, double within) {
    return target && (target->centre - position).head<2>().norm() <= within;
  };
  if (!near(current_, kTakeNext * radius_m_)) {
    const auto start = std::chrono::steady_clock::now();
    bool waited = requested_.has_value() || building_;
    wake_.wait(lock, [&] { return !requested_ && !building_; });
    if (near(next_, 0.5 * radius_m_)) {
      current_ = std::move(next_);
    } else if (!near(current_, 0.5 * radius_m_)) {
      // Far from both: one made in the background for another place is of no use.
      lock.unlock();
      std::shared_ptr<const MapTarget> target = build(position);
      lock.lock();
      current_ = std::move(target);
      waited = true;
    }
    next_.reset();
    if (waited) {
      ++counts_.waited;
      counts_.wait_ms += ms_since(start);
    }
  }
  if (!near(current_, kAskNext * radius_m_) && !requested_ && !building_ && !next_) {
    requested_ = position;
    wake_.notify_all();
  }
  return current_;
}

void MapTargets::run() {
  // Below the tracking, which is what the user waits for, and leaving it a core.
  BackgroundThread background(kBackgroundNice);
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || requested_.has_value(); });
    if (stop_) return;
    const Eigen::Vector3d centre = *requested_;
    requested_.reset();
    building_ = true;
    lock.unlock();
    std::shared_ptr<const MapTarget> target;
    try {
      background.run([&] { target = build(centre); });
    } catch (...) {
      // The next request (or the tracking's own build) meets the error again, where it can
      // be reported.
    }
    lock.lock();
    building_ = false;
    next_ = std::move(target);
    wake_.notify_all();
  }
}

MapTargetCounts MapTargets::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

}  // namespace featsense::mapping
