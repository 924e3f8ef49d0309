#include "map_path.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace featsense::mapping {
namespace {

void add_thinned(const Eigen::Vector3d& p, double spacing_m, std::vector<Eigen::Vector3d>& out,
                 bool first_of_session) {
  if (first_of_session || out.empty() || (p - out.back()).norm() >= spacing_m) out.push_back(p);
}

}  // namespace

MapPath::MapPath(const SavedMap& saved, double spacing_m) {
  if (!(spacing_m > 0.0)) throw std::invalid_argument("MapPath: the spacing must be positive");
  bool any_poses = false;
  for (const SavedSession& session : saved.sessions) {
    bool first = true;
    for (const Eigen::Isometry3d& pose : session.poses.poses) {
      add_thinned(pose.translation(), spacing_m, positions_, first);
      first = false;
      any_poses = true;
    }
  }
  if (any_poses) return;
  // A map made before sessions were kept: its keyframes are where it was seen from.
  bool first = true;
  for (const slam::loops::MapKeyframe& keyframe : saved.keyframes) {
    add_thinned(keyframe.T_map_sensor.translation(), spacing_m, positions_, first);
    first = false;
  }
}

SeenFrom::SeenFrom(const MapPath& path, const Eigen::Vector3d& centre, double radius_m,
                   double cell_m, double reach_m)
    : origin_(centre.head<2>() - Eigen::Vector2d::Constant(radius_m)), cell_m_(cell_m) {
  if (!(cell_m > 0.0) || !(radius_m > 0.0))
    throw std::invalid_argument("SeenFrom: the cell and the radius must be positive");
  cells_ = static_cast<int>(std::ceil(2.0 * radius_m / cell_m));
  const double within = radius_m + reach_m;
  std::vector<Eigen::Vector3d> near;
  for (const Eigen::Vector3d& p : path.positions())
    if ((p - centre).head<2>().cwiseAbs().maxCoeff() <= within) near.push_back(p);
  if (near.empty()) return;  // no grid: nowhere near the path
  nearest_.resize(static_cast<size_t>(cells_) * static_cast<size_t>(cells_));
  for (int j = 0; j < cells_; ++j) {
    for (int i = 0; i < cells_; ++i) {
      const Eigen::Vector2d c = origin_ + cell_m_ * Eigen::Vector2d(i + 0.5, j + 0.5);
      double best = std::numeric_limits<double>::infinity();
      const Eigen::Vector3d* nearest = nullptr;
      for (const Eigen::Vector3d& p : near) {
        const double d2 = (p.head<2>() - c).squaredNorm();
        if (d2 < best) {
          best = d2;
          nearest = &p;
        }
      }
      const size_t at = static_cast<size_t>(j) * static_cast<size_t>(cells_) + i;
      nearest_[at] = nearest->cast<float>();
    }
  }
}

const Eigen::Vector3f* SeenFrom::nearest(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d at = (p.head<2>() - origin_) / cell_m_;
  const int i = static_cast<int>(std::floor(at.x()));
  const int j = static_cast<int>(std::floor(at.y()));
  if (nearest_.empty() || i < 0 || j < 0 || i >= cells_ || j >= cells_) return nullptr;
  return &nearest_[static_cast<size_t>(j) * static_cast<size_t>(cells_) + i];
}

double surface_sigma(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                     const Eigen::Vector3d& seen_from, double angle_sigma_rad) {
  return angle_sigma_rad * normal.cross(point - seen_from).norm();
}

}  // namespace featsense::mapping
