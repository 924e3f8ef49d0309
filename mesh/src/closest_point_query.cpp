// The only file that includes CGAL: an AABB tree over the triangles (exact point-to-triangle
// distances) and a k-d tree over the points of a cloud.

#include "internal/closest_point_query.hpp"

#include <Eigen/Geometry>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>
#include <boost/tuple/tuple.hpp>

#include <cmath>
#include <optional>

namespace featsense::mesh::internal {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

using IndexedPoint = boost::tuple<Point, size_t>;
using KdTraits =
    CGAL::Search_traits_adapter<IndexedPoint, CGAL::Nth_of_tuple_property_map<0, IndexedPoint>,
                                CGAL::Search_traits_3<Kernel>>;
using NeighborSearch = CGAL::Orthogonal_k_neighbor_search<KdTraits>;
using KdTree = NeighborSearch::Tree;

Point to_cgal(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }
Point to_cgal(const Eigen::Vector3f& p) { return Point(p.x(), p.y(), p.z()); }
Eigen::Vector3d to_eigen(const Point& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); }

}  // namespace

struct ClosestPointQuery::Impl {
  std::vector<Triangle> triangles;
  std::vector<Eigen::Vector3d> triangle_normals;
  std::optional<AabbTree> aabb;
  std::vector<IndexedPoint> points;
  std::vector<Eigen::Vector3d> point_normals;
  std::optional<KdTree> kd;
};

ClosestPointQuery::ClosestPointQuery(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.is_point_cloud()) {
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      impl_->points.emplace_back(to_cgal(mesh.vertices[i]), i);
    }
    if (impl_->points.empty()) throw MeshError("the reference has no points");
    if (mesh.has_normals()) {
      for (const Eigen::Vector3f& n : mesh.normals) {
        impl_->point_normals.push_back(n.cast<double>().normalized());
      }
    }
    impl_->kd.emplace(impl_->points.begin(), impl_->points.end());
    impl_->kd->build();
    return;
  }
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<size_t>(tri[0])].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[static_cast<size_t>(tri[1])].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[static_cast<size_t>(tri[2])].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0.0)) continue;  // zero area: no closest point of its own, no normal
    impl_->triangles.emplace_back(to_cgal(a), to_cgal(b), to_cgal(c));
    impl_->triangle_normals.push_back(n.normalized());
  }
  if (impl_->triangles.empty()) {
    throw MeshError("the reference mesh is degenerate: all its triangles have zero area");
  }
  impl_->aabb.emplace(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->aabb->build();
  // Built now, not lazily on the first query, so that queries from many threads are safe.
  impl_->aabb->accelerate_distance_queries();
}

ClosestPointQuery::~ClosestPointQuery() = default;

bool ClosestPointQuery::has_normals() const {
  return impl_->aabb.has_value() || !impl_->point_normals.empty();
}

ClosestPoint ClosestPointQuery::closest(const Eigen::Vector3d& query) const {
  ClosestPoint result;
  result.normal.setZero();
  if (impl_->aabb) {
    const auto [point, id] = impl_->aabb->closest_point_and_primitive(to_cgal(query));
    result.point = to_eigen(point);
    result.normal = impl_->triangle_normals[static_cast<size_t>(id - impl_->triangles.cbegin())];
  } else {
    const NeighborSearch search(*impl_->kd, to_cgal(query), 1);
    // A copy: the search iterator's operator-> hands out a proxy that dies with the statement.
    const std::pair<IndexedPoint, double> nearest = *search.begin();
    result.point = to_eigen(boost::get<0>(nearest.first));
    if (!impl_->point_normals.empty()) {
      result.normal = impl_->point_normals[boost::get<1>(nearest.first)];
    }
  }
  result.distance_m = (query - result.point).norm();
  return result;
}

}  // namespace featsense::mesh::internal
