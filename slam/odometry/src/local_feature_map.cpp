#include "featsense/slam/odometry/local_feature_map.hpp"

#include <tbb/parallel_invoke.h>
#include <nanoflann.hpp>

#include <array>
#include <unordered_set>

#include "featsense/slam/odometry/voxel_filter.hpp"

namespace featsense::slam::odometry {
namespace {

/// nanoflann's view of a point vector.
struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t index, size_t dim) const {
    return points[index][static_cast<int>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>,
                                                   PointCloud, 3, uint32_t>;

/// One of the two maps: points, their voxels and the tree over them.
class VoxelMap {
 public:
  explicit VoxelMap(double voxel_m) : inverse_voxel_(static_cast<float>(1.0 / voxel_m)) {}

  void add(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& T_map_sensor) {
    const Eigen::Isometry3f T = T_map_sensor.cast<float>();
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3f x = T * p;
      if (!x.allFinite()) continue;
      if (voxels_.insert(voxel_key(x, inverse_voxel_)).second) cloud_.points.push_back(x);
    }
  }

  void crop(const Eigen::Vector3f& center, float radius) {
    const float radius2 = radius * radius;
    std::vector<Eigen::Vector3f> kept;
    kept.reserve(cloud_.points.size());
    for (const Eigen::Vector3f& p : cloud_.points) {
      if ((p - center).squaredNorm() <= radius2) kept.push_back(p);
    }
    if (kept.size() == cloud_.points.size()) return;
    cloud_.points.swap(kept);
    voxels_.clear();
    for (const Eigen::Vector3f& p : cloud_.points) voxels_.insert(voxel_key(p, inverse_voxel_));
  }

  void rebuild() {
    tree_.reset();
    if (!cloud_.points.empty()) {
      tree_ = std::make_unique<KdTree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    }
  }

  void nearest(const Eigen::Vector3d& query, int k, double max_distance,
               std::vector<Eigen::Vector3d>& found) const {
    found.clear();
    if (tree_ == nullptr || k <= 0) return;
    std::array<uint32_t, 16> index{};
    std::array<float, 16> distance2{};
    const size_t want = std::min<size_t>(static_cast<size_t>(k), index.size());
    const Eigen::Vector3f q = query.cast<float>();
    const size_t n = tree_->knnSearch(q.data(), want, index.data(), distance2.data());
    const double max2 = max_distance * max_distance;
    for (size_t i = 0; i < n; ++i) {
      if (distance2[i] > max2) break;
      found.push_back(cloud_.points[index[i]].cast<double>());
    }
  }

  size_t size() const { return cloud_.points.size(); }

 private:
  float inverse_voxel_;
  PointCloud cloud_;
  std::unordered_set<uint64_t> voxels_;
  std::unique_ptr<KdTree> tree_;
};

}  // namespace

struct LocalFeatureMap::Impl {
  VoxelMap edges;
  VoxelMap surfaces;
  float radius;
};

LocalFeatureMap::LocalFeatureMap(double edge_voxel_m, double surface_voxel_m, double radius_m)
    : impl_(new Impl{VoxelMap(edge_voxel_m), VoxelMap(surface_voxel_m),
                     static_cast<float>(radius_m)}) {}

LocalFeatureMap::~LocalFeatureMap() = default;

void LocalFeatureMap::add(const std::vector<Eigen::Vector3f>& edges,
                          const std::vector<Eigen::Vector3f>& surfaces,
                          const Eigen::Isometry3d& T_map_sensor) {
  const Eigen::Vector3f center = T_map_sensor.translation().cast<float>();
  // The two maps are independent: updated side by side where there are cores for it.
  const auto update = [&](VoxelMap& map, const std::vector<Eigen::Vector3f>& points) {
    map.add(points, T_map_sensor);
    map.crop(center, impl_->radius);
    map.rebuild();
  };
  tbb::parallel_invoke([&] { update(impl_->edges, edges); },
                       [&] { update(impl_->surfaces, surfaces); });
}

void LocalFeatureMap::nearest_edges(const Eigen::Vector3d& query, int k, double max_distance_m,
                                    std::vector<Eigen::Vector3d>& found) const {
  impl_->edges.nearest(query, k, max_distance_m, found);
}

void LocalFeatureMap::nearest_surfaces(const Eigen::Vector3d& query, int k, double max_distance_m,
                                       std::vector<Eigen::Vector3d>& found) const {
  impl_->surfaces.nearest(query, k, max_distance_m, found);
}

size_t LocalFeatureMap::edge_count() const { return impl_->edges.size(); }
size_t LocalFeatureMap::surface_count() const { return impl_->surfaces.size(); }

}  // namespace featsense::slam::odometry
