#include "featsense/slam/odometry/local_feature_map.hpp"

#include <tbb/parallel_invoke.h>
// nanoflann's dynamic trees copy an empty tree's bounding box before it is set (unused then);
// GCC's flow analysis flags that copy inside the header.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <nanoflann.hpp>
#pragma GCC diagnostic pop

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

/// nanoflann's logarithmic index: static trees of 1, 2, 4 ... points, a scan's new points
/// merged into them and the points that left the radius marked removed, so that a scan costs
/// in proportion to what it changed, not to the map (rebuilding one tree over the whole
/// surface map, 40,000-120,000 points at 0.2 m voxels, took 10-27 ms a scan). Its searches
/// give the same nearest points as one tree over the points kept.
using KdTree =
    nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>,
                                               PointCloud, 3, uint32_t>;

/// Removed points are dropped, and the trees made again over those kept, once they outnumber
/// them: memory at most twice the map's.
constexpr size_t kCompactWhenRemovedPerKept = 1;

/// One of the two maps: points, their voxels and the trees over them.
class VoxelMap {
 public:
  explicit VoxelMap(double voxel_m) : inverse_voxel_(static_cast<float>(1.0 / voxel_m)) {}

  /// Adds `points` (sensor frame) at `T_map_sensor` where their voxels are free, then drops
  /// what lies farther than `radius` from `center`.
  void update(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& T_map_sensor,
              const Eigen::Vector3f& center, float radius) {
    // Made over no points: the trees take each point as addPoints gives it.
    if (tree_ == nullptr) tree_ = std::make_unique<KdTree>(3, cloud_, kTreeParams);
    const size_t first_new = cloud_.points.size();
    const Eigen::Isometry3f T = T_map_sensor.cast<float>();
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3f x = T * p;
      if (!x.allFinite()) continue;
      if (voxels_.insert(voxel_key(x, inverse_voxel_)).second) {
        cloud_.points.push_back(x);
        kept_.push_back(1);
      }
    }
    if (cloud_.points.size() > first_new)
      tree_->addPoints(static_cast<uint32_t>(first_new),
                       static_cast<uint32_t>(cloud_.points.size() - 1));
    const float radius2 = radius * radius;
    for (size_t i = 0; i < cloud_.points.size(); ++i) {
      if (!kept_[i] || (cloud_.points[i] - center).squaredNorm() <= radius2) continue;
      kept_[i] = 0;
      voxels_.erase(voxel_key(cloud_.points[i], inverse_voxel_));
      tree_->removePoint(i);
      ++removed_;
    }
    if (removed_ > kCompactWhenRemovedPerKept * size()) compact();
  }

  void nearest(const Eigen::Vector3d& query, int k, double max_distance,
               std::vector<Eigen::Vector3d>& found) const {
    found.clear();
    if (tree_ == nullptr || size() == 0 || k <= 0) return;
    std::array<uint32_t, 16> index{};
    std::array<float, 16> distance2{};
    const size_t want = std::min<size_t>(static_cast<size_t>(k), index.size());
    const Eigen::Vector3f q = query.cast<float>();
    nanoflann::KNNResultSet<float, uint32_t> result(want);
    result.init(index.data(), distance2.data());
    // The largest tree first: its nearest points bound the search of the small ones, most of
    // which it then prunes at their root.
    const auto& trees = tree_->getAllIndices();
    for (auto tree = trees.rbegin(); tree != trees.rend(); ++tree)
      tree->findNeighbors(result, q.data(), nanoflann::SearchParams());
    const size_t n = result.size();
    const double max2 = max_distance * max_distance;
    for (size_t i = 0; i < n; ++i) {
      if (distance2[i] > max2) break;
      found.push_back(cloud_.points[index[i]].cast<double>());
    }
  }

  size_t size() const { return cloud_.points.size() - removed_; }

 private:
  inline static const nanoflann::KDTreeSingleIndexAdaptorParams kTreeParams{10};

  /// The kept points alone, in their order, and the trees made again over them.
  void compact() {
    size_t to = 0;
    for (size_t i = 0; i < cloud_.points.size(); ++i)
      if (kept_[i]) cloud_.points[to++] = cloud_.points[i];
    cloud_.points.resize(to);
    kept_.assign(to, 1);
    removed_ = 0;
    tree_ = std::make_unique<KdTree>(3, cloud_, kTreeParams);
  }

  float inverse_voxel_;
  PointCloud cloud_;
  std::vector<uint8_t> kept_;  ///< per point of cloud_: not yet removed
  size_t removed_ = 0;
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
    map.update(points, T_map_sensor, center, impl_->radius);
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
