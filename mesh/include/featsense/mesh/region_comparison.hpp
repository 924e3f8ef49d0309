#pragma once
/// compare_to_reference's figures a square region at a time: memory bounded by what lies in
/// and around one region, whatever the size of the map and of its truth.
///
/// The rule: the regions are cells of `region_size_m` in x and y (from 0, every height); a
/// vertex of the estimate (a sample of the reference) belongs to the region its x, y fall in.
/// - Accuracy: each vertex is compared with the reference read around its region, `margin_m`
///   wider. A distance within the margin is exact (a nearer point would lie in what was
///   read). A vertex farther than the margin from all of it is settled at the end against
///   the whole reference, a region at a time, nearest regions first, skipping those farther
///   than its best so far; with settings.max_dist_m at most the margin it is simply beyond
///   max_dist. So the distances, statistics and precision equal compare_to_reference's.
/// - Completeness: each reference sample is compared with the estimate read around its
///   region, the largest threshold (plus a centimetre) wider: exact for every threshold.
///   A point-cloud reference's samples are its points: the completeness equals
///   compare_to_reference's. A mesh reference is sampled region by region (its triangles
///   belonging to the region of their centroid, a seed per region) at the density that
///   compare_to_reference uses (max_samples over the total area): the same expected
///   figure, other random samples.
/// Per-vertex distances (CompareResult::unsigned_distance_m, where kept) are in the
/// estimate's vertex order where it has one (SurfaceRegions::vertex_count), else in the order
/// of the regions. The median and p95 are within 0.003 % of the exact order statistics (a
/// histogram of |d|, internal/distance_accumulator.hpp), in the whole comparison too.

#include <functional>

#include "featsense/mesh/compare_to_reference.hpp"
#include "featsense/mesh/surface_regions.hpp"

namespace featsense::mesh {

struct RegionComparisonSettings {
  double region_size_m = 50.0;
  double margin_m = 2.0;
  bool accuracy = true;      ///< estimate -> reference (distances, accuracy, precision)
  bool completeness = true;  ///< reference -> estimate
  /// Per-vertex distances in the result (CompareResult::unsigned_distance_m, for a mesh
  /// coloured by them); without them the figures alone, in memory that does not grow with
  /// the estimate.
  bool keep_distances = true;
  /// Called after each region with (regions done, regions), for progress.
  std::function<void(size_t, size_t)> progress;
};

/// Throws MeshError when the estimate or the reference is empty, or the reference has no
/// triangle of non-zero area (and no points).
CompareResult compare_by_region(const SurfaceRegions& estimate, const SurfaceRegions& reference,
                                const CompareSettings& settings = {},
                                const RegionComparisonSettings& regions = {});

}  // namespace featsense::mesh
