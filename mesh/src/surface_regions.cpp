// Surfaces read by region: a mesh in memory through a grid of buckets, a tiled point file, a
// moved source.

#include "featsense/mesh/surface_regions.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::mesh {

MeshRegions::MeshRegions(const TriangleMesh& mesh, double cell_m) : mesh_(mesh), cell_m_(cell_m) {
  if (!(cell_m_ > 0.0)) throw MeshError("regions of a mesh: the cell must be positive");
  validate(mesh, "a surface read by region");  // a non-finite vertex has no region
  bounds_.setEmpty();
  for (const Eigen::Vector3f& v : mesh.vertices) bounds_.extend(v.cast<double>());
  if (bounds_.isEmpty()) return;
  // At most 2048 cells a side, whatever lies far out (an outlier 1000 km away).
  const double extent = (bounds_.max() - bounds_.min()).head<2>().maxCoeff();
  cell_m_ = std::max(cell_m_, extent / 2047.0);
  const auto cell_of = [&](double v, int axis) {
    return static_cast<int>(std::floor((v - bounds_.min()[axis]) / cell_m_));
  };
  cells_ = Eigen::Vector2i(cell_of(bounds_.max().x(), 0) + 1, cell_of(bounds_.max().y(), 1) + 1);
  auto cell_range = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    const Eigen::Vector2i a(std::clamp(cell_of(lo.x(), 0), 0, cells_.x() - 1),
                            std::clamp(cell_of(lo.y(), 1), 0, cells_.y() - 1));
    const Eigen::Vector2i b(std::clamp(cell_of(hi.x(), 0), 0, cells_.x() - 1),
                            std::clamp(cell_of(hi.y(), 1), 0, cells_.y() - 1));
    return std::make_pair(a, b);
  };
  // Items: the triangles, then the vertices in no triangle (a comparison counts them too);
  // of a cloud, its points.
  const size_t triangles = mesh.triangles.size();
  if (!mesh.is_point_cloud()) {
    std::vector<bool> referenced(mesh.vertices.size(), false);
    for (const Eigen::Vector3i& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) referenced[static_cast<size_t>(t[k])] = true;
    }
    for (size_t v = 0; v < referenced.size(); ++v) {
      if (!referenced[v]) loose_.push_back(static_cast<uint32_t>(v));
    }
  }
  const size_t items = triangles + (mesh.is_point_cloud() ? mesh.vertices.size() : loose_.size());
  // Two passes, counting then filling: no vector per cell.
  first_.assign(static_cast<size_t>(cells_.x()) * static_cast<size_t>(cells_.y()) + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint64_t> fill;
    if (pass == 1) {
      for (size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
      items_.resize(first_.back());
      fill.assign(first_.begin(), first_.end() - 1);
    }
    for (size_t i = 0; i < items; ++i) {
      const Eigen::AlignedBox3d box =
          i >= triangles ? Eigen::AlignedBox3d(mesh.vertices[vertex_of(i)].cast<double>())
                         : triangle_bounds(mesh, i);
      const auto [a, b] = cell_range(box.min(), box.max());
      for (int y = a.y(); y <= b.y(); ++y) {
        for (int x = a.x(); x <= b.x(); ++x) {
          const size_t c =
              static_cast<size_t>(y) * static_cast<size_t>(cells_.x()) + static_cast<size_t>(x);
          if (pass == 0) {
            ++first_[c + 1];
          } else {
            items_[fill[c]++] = static_cast<uint32_t>(i);
          }
        }
      }
    }
  }
}

size_t MeshRegions::vertex_of(size_t item) const {
  const size_t i = item - mesh_.triangles.size();
  return mesh_.is_point_cloud() ? i : loose_[i];
}

SurfacePiece MeshRegions::read(const Eigen::AlignedBox3d& box) const {
  if (bounds_.isEmpty() || !box.intersects(bounds_)) return {};
  // Cell indices in double first: a box far outside would overflow an int.
  auto cell_of = [&](double v, int axis, int cells) {
    const double c = std::floor((v - bounds_.min()[axis]) / cell_m_);
    return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(cells - 1)));
  };
  const Eigen::Vector2i a(cell_of(box.min().x(), 0, cells_.x()),
                          cell_of(box.min().y(), 1, cells_.y()));
  const Eigen::Vector2i b(cell_of(box.max().x(), 0, cells_.x()),
                          cell_of(box.max().y(), 1, cells_.y()));
  std::vector<uint32_t> found;
  for (int y = a.y(); y <= b.y(); ++y) {
    for (int x = a.x(); x <= b.x(); ++x) {
      const size_t c =
          static_cast<size_t>(y) * static_cast<size_t>(cells_.x()) + static_cast<size_t>(x);
      found.insert(found.end(), items_.begin() + static_cast<std::ptrdiff_t>(first_[c]),
                   items_.begin() + static_cast<std::ptrdiff_t>(first_[c + 1]));
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  std::vector<uint32_t> triangles;
  std::vector<size_t> loose;
  for (uint32_t i : found) {
    if (i >= mesh_.triangles.size()) {
      const size_t v = vertex_of(i);
      if (box.contains(mesh_.vertices[v].cast<double>())) loose.push_back(v);
      continue;
    }
    if (triangle_bounds(mesh_, i).intersects(box)) triangles.push_back(i);
  }
  SurfacePiece piece;
  piece.mesh = triangle_subset(mesh_, triangles, &piece.source_index);
  // The vertices in no triangle (of a cloud, all) after those of the triangles.
  for (size_t v : loose) {
    piece.mesh.vertices.push_back(mesh_.vertices[v]);
    if (mesh_.has_normals()) piece.mesh.normals.push_back(mesh_.normals[v]);
    piece.source_index.push_back(v);
  }
  return piece;
}

SurfacePiece PointFileRegions::read(const Eigen::AlignedBox3d& box) const {
  SurfacePiece piece;
  piece.mesh.vertices = file_.read(box);
  return piece;
}

Eigen::AlignedBox3d moved_box(const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& T) {
  Eigen::AlignedBox3d moved;
  moved.setEmpty();
  if (box.isEmpty()) return moved;
  for (int corner = 0; corner < 8; ++corner) {
    moved.extend(T * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
  }
  return moved;
}

MovedRegions::MovedRegions(const SurfaceRegions& source, const Eigen::Isometry3d& T)
    : source_(source), T_(T) {}

Eigen::AlignedBox3d MovedRegions::bounds() const { return moved_box(source_.bounds(), T_); }

SurfacePiece MovedRegions::read(const Eigen::AlignedBox3d& box) const {
  // What the source has in the box brought back; the points outside `box` that this adds
  // (the moved box is larger) are allowed.
  SurfacePiece piece = source_.read(moved_box(box, T_.inverse()));
  const Eigen::Isometry3f T = T_.cast<float>();
  for (Eigen::Vector3f& v : piece.mesh.vertices) v = T * v;
  for (Eigen::Vector3f& n : piece.mesh.normals) n = T.linear() * n;
  return piece;
}

}  // namespace featsense::mesh
