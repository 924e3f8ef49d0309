// The comparison of compare_to_reference.cpp, a region (an x, y cell, every height) at a time.

#include "featsense/mesh/region_comparison.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "internal/closest_point_query.hpp"
#include "internal/comparison_figures.hpp"
#include "internal/distance_accumulator.hpp"
#include "internal/surface_sampling.hpp"

namespace featsense::mesh {
namespace {

/// Half the height of a column: regions take every height.
constexpr double kColumnHalfHeight = 1e6;

struct Cell {
  int64_t x = 0, y = 0;
};

int64_t cell_index(double v, double size) { return static_cast<int64_t>(std::floor(v / size)); }

bool in_cell(const Eigen::Vector3f& p, const Cell& cell, double size) {
  return cell_index(p.x(), size) == cell.x && cell_index(p.y(), size) == cell.y;
}

std::vector<Cell> cells_over(const Eigen::AlignedBox3d& bounds, double size) {
  std::vector<Cell> cells;
  if (bounds.isEmpty()) return cells;
  for (int64_t y = cell_index(bounds.min().y(), size); y <= cell_index(bounds.max().y(), size);
       ++y) {
    for (int64_t x = cell_index(bounds.min().x(), size); x <= cell_index(bounds.max().x(), size);
         ++x) {
      cells.push_back({x, y});
    }
  }
  return cells;
}

/// The cell's column, `pad` wider in x and y, z from `z_lo` to `z_hi`.
Eigen::AlignedBox3d column(const Cell& cell, double size, double pad, double z_lo, double z_hi) {
  return Eigen::AlignedBox3d(Eigen::Vector3d(static_cast<double>(cell.x) * size - pad,
                                             static_cast<double>(cell.y) * size - pad, z_lo),
                             Eigen::Vector3d(static_cast<double>(cell.x + 1) * size + pad,
                                             static_cast<double>(cell.y + 1) * size + pad, z_hi));
}

/// The cell's column with a millimetre of slack: a point a rounding away from the cell's edge
/// is still read, and the cell it falls in (in_cell) takes it.
Eigen::AlignedBox3d whole_column(const Cell& cell, double size) {
  return column(cell, size, 1e-3, -kColumnHalfHeight, kColumnHalfHeight);
}

/// A query over a piece; null when it has nothing to query (no points, or triangles of zero
/// area only).
std::unique_ptr<internal::ClosestPointQuery> query_of(const TriangleMesh& piece) {
  if (piece.vertices.empty()) return nullptr;
  try {
    return std::make_unique<internal::ClosestPointQuery>(piece);
  } catch (const MeshError&) {
    return nullptr;
  }
}

uint64_t cell_seed(uint64_t seed, const Cell& cell) {
  uint64_t z = seed ^ (static_cast<uint64_t>(cell.x) * 0x9E3779B97F4A7C15ull) ^
               (static_cast<uint64_t>(cell.y) * 0xC2B2AE3D27D4EB4Full);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// The triangles of `piece` whose centroid lies in `cell`, as a mesh of their own.
TriangleMesh owned_triangles(const TriangleMesh& piece, const Cell& cell, double size) {
  TriangleMesh owned;
  for (const Eigen::Vector3i& t : piece.triangles) {
    const Eigen::Vector3f centroid =
        (piece.vertices[static_cast<size_t>(t[0])] + piece.vertices[static_cast<size_t>(t[1])] +
         piece.vertices[static_cast<size_t>(t[2])]) /
        3.0f;
    if (!in_cell(centroid, cell, size)) continue;
    const int first = static_cast<int>(owned.vertices.size());
    for (int k = 0; k < 3; ++k) owned.vertices.push_back(piece.vertices[static_cast<size_t>(t[k])]);
    owned.triangles.emplace_back(first, first + 1, first + 2);
  }
  return owned;
}

struct Distance {
  double distance_m = std::numeric_limits<double>::infinity();
  double side = 0.0;  ///< (p - closest) . normal
};

Distance distance_to(const internal::ClosestPointQuery& query, const Eigen::Vector3d& p) {
  const internal::ClosestPoint c = query.closest(p);
  return {c.distance_m, (p - c.point).dot(c.normal)};
}

/// A vertex whose nearest reference point is farther than the margin.
struct Pending {
  Eigen::Vector3d p;
  size_t slot = 0;
  Distance best;
};

class RegionComparison {
 public:
  RegionComparison(const SurfaceRegions& estimate, const SurfaceRegions& reference,
                   const CompareSettings& settings, const RegionComparisonSettings& regions)
      : estimate_(estimate),
        reference_(reference),
        settings_(settings),
        regions_(regions),
        size_(regions.region_size_m),
        distances_(settings) {}

  CompareResult run() {
    if (!(size_ > 0.0) || !(regions_.margin_m >= 0.0)) {
      throw MeshError("the regions of a comparison need a positive size and margin");
    }
    if (estimate_.bounds().isEmpty()) throw MeshError("the estimate has no vertices");
    if (reference_.bounds().isEmpty()) throw MeshError("the reference has no vertices");
    result_.reference_is_mesh = !reference_.is_point_cloud();
    result_.signed_distances = result_.reference_is_mesh;
    const std::vector<Cell> estimate_cells = cells_over(estimate_.bounds(), size_);
    const std::vector<Cell> reference_cells = cells_over(reference_.bounds(), size_);
    total_ = (regions_.accuracy ? estimate_cells.size() : 0) +
             (regions_.completeness ? reference_cells.size() : 0);
    if (regions_.accuracy) {
      const std::optional<uint64_t> n = estimate_.vertex_count();
      if (regions_.keep_distances && n) {
        ordered_ = true;
        result_.unsigned_distance_m.assign(*n, 0.0f);
        result_.signed_distance_m.assign(*n, 0.0f);
      }
      for (const Cell& cell : estimate_cells) {
        accuracy_in(cell);
        step();
      }
      settle_pending(reference_cells);
      if (!reference_usable_) {
        throw MeshError("the reference mesh is degenerate: all its triangles have zero area");
      }
    }
    distances_.fill(&result_);
    within_.assign(settings_.thresholds_m.size(), 0);
    if (regions_.completeness) completeness(reference_cells);
    internal::fill_scores(settings_, distances_.within(), within_, &result_);
    return std::move(result_);
  }

 private:
  void step() {
    ++done_;
    if (regions_.progress) regions_.progress(done_, total_);
  }

  void record(size_t slot, const Distance& d) {
    const double sign = d.side > 0.0 ? 1.0 : (d.side < 0.0 ? -1.0 : 0.0);
    const auto value = static_cast<float>(d.distance_m);
    const float signed_value = result_.signed_distances ? static_cast<float>(sign) * value : value;
    distances_.add(value, signed_value);
    if (!regions_.keep_distances) return;
    result_.unsigned_distance_m[slot] = value;
    result_.signed_distance_m[slot] = signed_value;
  }

  void note_reference(const internal::ClosestPointQuery& query) {
    reference_usable_ = true;
    if (!result_.reference_is_mesh) result_.signed_distances = query.has_normals();
  }

  void accuracy_in(const Cell& cell) {
    const SurfacePiece piece = estimate_.read(whole_column(cell, size_));
    std::vector<size_t> owned;
    double z_lo = kColumnHalfHeight, z_hi = -kColumnHalfHeight;
    for (size_t i = 0; i < piece.mesh.vertices.size(); ++i) {
      const Eigen::Vector3f& v = piece.mesh.vertices[i];
      if (!in_cell(v, cell, size_)) continue;
      owned.push_back(i);
      z_lo = std::min(z_lo, static_cast<double>(v.z()));
      z_hi = std::max(z_hi, static_cast<double>(v.z()));
    }
    if (owned.empty()) return;
    const double margin = regions_.margin_m;
    const SurfacePiece near =
        reference_.read(column(cell, size_, margin, z_lo - margin, z_hi + margin));
    const std::unique_ptr<internal::ClosestPointQuery> query = query_of(near.mesh);
    std::vector<Distance> distances(owned.size());
    if (query) {
      note_reference(*query);
      tbb::parallel_for(size_t{0}, owned.size(), [&](size_t k) {
        distances[k] = distance_to(*query, piece.mesh.vertices[owned[k]].cast<double>());
      });
    }
    for (size_t k = 0; k < owned.size(); ++k) {
      size_t slot = 0;  // unused where the distances are not kept
      if (ordered_) {
        slot = static_cast<size_t>(piece.source_index[owned[k]]);
      } else if (regions_.keep_distances) {
        slot = result_.unsigned_distance_m.size();
        result_.unsigned_distance_m.push_back(0.0f);
        result_.signed_distance_m.push_back(0.0f);
      }
      if (distances[k].distance_m <= margin) {
        record(slot, distances[k]);
      } else {
        pending_.push_back({piece.mesh.vertices[owned[k]].cast<double>(), slot, distances[k]});
      }
    }
  }

  /// The vertices beyond the margin against the whole reference, nearest regions first.
  void settle_pending(std::vector<Cell> cells) {
    if (pending_.empty()) return;
    Eigen::AlignedBox3d around;
    around.setEmpty();
    for (const Pending& p : pending_) around.extend(p.p);
    const Eigen::Vector3d centre = around.center();
    auto distance = [&](const Cell& cell) {
      return whole_column(cell, size_).exteriorDistance(centre);
    };
    std::sort(cells.begin(), cells.end(),
              [&](const Cell& a, const Cell& b) { return distance(a) < distance(b); });
    for (const Cell& cell : cells) {
      const SurfacePiece piece = reference_.read(whole_column(cell, size_));
      const std::unique_ptr<internal::ClosestPointQuery> query = query_of(piece.mesh);
      if (!query) continue;
      note_reference(*query);
      Eigen::AlignedBox3d extent;
      extent.setEmpty();
      for (const Eigen::Vector3f& v : piece.mesh.vertices) extent.extend(v.cast<double>());
      tbb::parallel_for(size_t{0}, pending_.size(), [&](size_t k) {
        Pending& p = pending_[k];
        if (extent.exteriorDistance(p.p) >= p.best.distance_m) return;
        const Distance d = distance_to(*query, p.p);
        if (d.distance_m < p.best.distance_m) p.best = d;
      });
    }
    for (const Pending& p : pending_) record(p.slot, p.best);
    pending_.clear();
  }

  /// Samples per square metre of a mesh reference: the settings', lowered so that the whole
  /// reference draws at most max_samples.
  double sample_density(const std::vector<Cell>& cells) {
    double area = 0.0;
    for (const Cell& cell : cells) {
      area += surface_area_m2(
          owned_triangles(reference_.read(whole_column(cell, size_)).mesh, cell, size_));
    }
    double density = settings_.samples_per_m2;
    if (area * density > static_cast<double>(settings_.max_samples)) {
      density = static_cast<double>(settings_.max_samples) / area;
    }
    return density;
  }

  void completeness(const std::vector<Cell>& cells) {
    const double reach =
        settings_.thresholds_m.empty()
            ? 0.0
            : *std::max_element(settings_.thresholds_m.begin(), settings_.thresholds_m.end()) +
                  0.01;
    const bool mesh = result_.reference_is_mesh;
    if (mesh) result_.samples_per_m2 = sample_density(cells);
    // A tiny mesh may draw no sample at this density: its vertices stand in, as they do in
    // compare_to_reference.
    for (bool vertices_stand_in : {false, true}) {
      if (vertices_stand_in && (!mesh || result_.reference_samples > 0)) break;
      for (const Cell& cell : cells) {
        const SurfacePiece piece = reference_.read(whole_column(cell, size_));
        std::vector<Eigen::Vector3d> samples;
        if (mesh && !vertices_stand_in) {
          samples =
              internal::sample_surface(owned_triangles(piece.mesh, cell, size_),
                                       result_.samples_per_m2, cell_seed(settings_.seed, cell));
        } else {
          for (const Eigen::Vector3f& v : piece.mesh.vertices) {
            if (in_cell(v, cell, size_)) samples.push_back(v.cast<double>());
          }
        }
        if (!vertices_stand_in) step();
        count_within(cell, samples, reach);
      }
    }
  }

  void count_within(const Cell& cell, const std::vector<Eigen::Vector3d>& samples, double reach) {
    if (samples.empty()) return;
    result_.reference_samples += samples.size();
    double z_lo = kColumnHalfHeight, z_hi = -kColumnHalfHeight;
    for (const Eigen::Vector3d& s : samples) {
      z_lo = std::min(z_lo, s.z());
      z_hi = std::max(z_hi, s.z());
    }
    const SurfacePiece near =
        estimate_.read(column(cell, size_, reach, z_lo - reach, z_hi + reach));
    const std::unique_ptr<internal::ClosestPointQuery> query = query_of(near.mesh);
    if (!query) return;  // nothing of the estimate near: none within any threshold
    std::vector<float> distances(samples.size());
    tbb::parallel_for(size_t{0}, samples.size(), [&](size_t i) {
      distances[i] = static_cast<float>(query->closest(samples[i]).distance_m);
    });
    for (size_t k = 0; k < settings_.thresholds_m.size(); ++k) {
      const double t = settings_.thresholds_m[k];
      within_[k] += static_cast<size_t>(
          std::count_if(distances.begin(), distances.end(), [t](float d) { return d <= t; }));
    }
  }

  const SurfaceRegions& estimate_;
  const SurfaceRegions& reference_;
  const CompareSettings& settings_;
  const RegionComparisonSettings& regions_;
  double size_;
  CompareResult result_;
  internal::DistanceAccumulator distances_;
  bool ordered_ = false;
  bool reference_usable_ = false;
  std::vector<Pending> pending_;
  std::vector<size_t> within_;
  size_t done_ = 0;
  size_t total_ = 0;
};

}  // namespace

CompareResult compare_by_region(const SurfaceRegions& estimate, const SurfaceRegions& reference,
                                const CompareSettings& settings,
                                const RegionComparisonSettings& regions) {
  return RegionComparison(estimate, reference, settings, regions).run();
}

}  // namespace featsense::mesh
