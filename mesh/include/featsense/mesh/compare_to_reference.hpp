#pragma once
/// Compares an estimated mesh with a surveyed reference (a mesh or a point cloud).
///
/// Accuracy, from the estimate's vertices to the reference, as CloudCompare's cloud-to-mesh
/// distance (C2M) does: for a mesh reference the exact distance to the nearest triangle; its
/// sign is that of (p - closest) . n, n the nearest triangle's normal (from its winding), so
/// points in front of the surface are positive. For a point-cloud reference the distance to the
/// nearest reference point, signed by that point's normal where the cloud has normals, else
/// unsigned (signed = unsigned).
/// Completeness, from the reference to the estimate: the share of reference samples within
/// each threshold of the estimate (the estimate's triangles, or its points if it has none).
/// A mesh reference is sampled area-uniformly (density below, fixed seed); its vertices alone
/// would over-weight finely tessellated parts. A point-cloud reference uses its points.
/// Precision at a threshold is the share of the estimate's vertices within it of the reference;
/// the F-score is 2 P C / (P + C).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh {

struct CompareSettings {
  /// Estimate points farther than this from the reference are left out of the accuracy
  /// statistics (counted in `beyond_max_dist`), metres; <= 0: no limit.
  double max_dist_m = 0.0;
  std::vector<double> thresholds_m = {0.02, 0.05, 0.10};
  /// Reference samples per square metre for completeness (1 cm mean spacing).
  double samples_per_m2 = 10000.0;
  /// At most this many samples; the density is lowered to fit (reported).
  size_t max_samples = 2000000;
  uint64_t seed = 1;
  size_t histogram_bins = 20;
};

struct DistanceStatistics {
  double mean_abs = 0.0;
  double mean_signed = 0.0;
  double std_signed = 0.0;  ///< population standard deviation of the signed distances
  double std_abs = 0.0;
  double rmse = 0.0;
  double median = 0.0;  ///< of |d|
  double p95 = 0.0;     ///< of |d|, nearest-rank
  double max = 0.0;     ///< of |d|
  size_t count = 0;
};

struct ThresholdScores {
  double threshold_m = 0.0;
  double precision = 0.0;
  double completeness = 0.0;
  double fscore = 0.0;
};

struct CompareResult {
  std::vector<float> unsigned_distance_m;  ///< per estimate vertex
  std::vector<float> signed_distance_m;    ///< per estimate vertex
  DistanceStatistics accuracy;             ///< over points within max_dist
  std::vector<ThresholdScores> scores;     ///< per threshold, in the settings' order
  size_t points = 0;                       ///< estimate vertices compared
  size_t beyond_max_dist = 0;
  size_t reference_samples = 0;
  double samples_per_m2 = 0.0;  ///< density used (0 for a point-cloud reference)
  bool reference_is_mesh = false;
  bool signed_distances = false;          ///< false where the reference gives no sign
  std::vector<double> histogram_edges_m;  ///< of |d|, bins+1 edges
  std::vector<size_t> histogram_counts;
};

/// Throws MeshError for an empty estimate, an empty reference, or a reference mesh whose
/// triangles all have zero area.
CompareResult compare_to_reference(const TriangleMesh& estimate, const TriangleMesh& reference,
                                   const CompareSettings& settings = {});

/// Statistics of distances (signed; |d| for the unsigned figures).
DistanceStatistics distance_statistics(const std::vector<float>& signed_distance_m);

}  // namespace featsense::mesh
