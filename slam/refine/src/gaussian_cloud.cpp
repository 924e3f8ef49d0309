#include "featsense/slam/refine/gaussian_cloud.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace featsense::slam::refine {
namespace {

struct PointView {
  const std::vector<Eigen::Vector3f>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(size_t index, size_t dim) const {
    return (*points)[index][static_cast<int>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointView>,
                                                   PointView, 3, uint32_t>;

/// A plane-like covariance's spread across the plane; along it, 1.
constexpr double kThickness = 1e-3;

/// Plane-like: the neighbourhood's axes kept, its spread replaced by (1, 1, kThickness).
Eigen::Matrix3d regularised(const Eigen::Matrix3d& covariance) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(covariance);
  const Eigen::Vector3d values(kThickness, 1.0, 1.0);  // ascending, as the eigenvalues
  return eigen.eigenvectors() * values.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace

double normal_alignment(const Eigen::Matrix3d& covariance, const Eigen::Vector3d& direction) {
  // C = I - (1 - t) n n' (t the thickness): d'C d = 1 - (1 - t) (n . d)^2, trace C = 2 + t
  // (both scaled alike where C is).
  const double trace = covariance.trace();
  if (!(trace > 0.0)) return 1.0;
  const double along = direction.dot(covariance * direction) * (2.0 + kThickness) / trace;
  return std::sqrt(std::clamp((1.0 - along) / (1.0 - kThickness), 0.0, 1.0));
}

GaussianCloud with_covariances(const std::vector<Eigen::Vector3f>& input, int neighbours,
                               std::vector<uint32_t>* kept, size_t every) {
  every = std::max<size_t>(every, 1);
  std::vector<Eigen::Vector3f> points;
  std::vector<uint32_t> source_index;
  points.reserve(input.size());
  source_index.reserve(input.size());
  for (size_t i = 0; i < input.size(); ++i) {
    if (!input[i].allFinite()) continue;
    points.push_back(input[i]);
    source_index.push_back(static_cast<uint32_t>(i));
  }
  if (kept) kept->clear();
  GaussianCloud out;
  const size_t k = static_cast<size_t>(std::max(neighbours, 3));
  if (points.size() < k) return out;
  const PointView view{&points};
  KdTree tree(3, view, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  std::vector<Eigen::Matrix3d> covariances(points.size());
  std::vector<uint8_t> good(points.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 256),
                    [&](const tbb::blocked_range<size_t>& range) {
                      std::vector<uint32_t> index(k);
                      std::vector<float> distance2(k);
                      for (size_t i = range.begin(); i < range.end(); ++i) {
                        if (i % every != 0) continue;
                        const size_t n =
                            tree.knnSearch(points[i].data(), k, index.data(), distance2.data());
                        if (n < 3) continue;
                        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
                        for (size_t j = 0; j < n; ++j) mean += points[index[j]].cast<double>();
                        mean /= static_cast<double>(n);
                        Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
                        for (size_t j = 0; j < n; ++j) {
                          const Eigen::Vector3d d = points[index[j]].cast<double>() - mean;
                          c += d * d.transpose();
                        }
                        covariances[i] = regularised(c / static_cast<double>(n));
                        good[i] = covariances[i].allFinite();
                      }
                    });
  for (size_t i = 0; i < points.size(); i += every) {
    if (!good[i]) continue;
    out.points.push_back(points[i].cast<double>());
    out.covariances.push_back(covariances[i]);
    if (kept) kept->push_back(source_index[i]);
  }
  return out;
}

GaussianCloud transformed(const GaussianCloud& cloud, const Eigen::Isometry3d& T) {
  GaussianCloud out;
  out.points.reserve(cloud.size());
  out.covariances.reserve(cloud.size());
  const Eigen::Matrix3d R = T.rotation();
  for (size_t i = 0; i < cloud.size(); ++i) {
    out.points.push_back(T * cloud.points[i]);
    out.covariances.push_back(R * cloud.covariances[i] * R.transpose());
  }
  return out;
}

}  // namespace featsense::slam::refine
