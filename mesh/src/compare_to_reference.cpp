// Accuracy (estimate -> reference), completeness (reference -> estimate) and F-scores.

#include "featsense/mesh/compare_to_reference.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "internal/closest_point_query.hpp"
#include "internal/comparison_figures.hpp"
#include "internal/distance_accumulator.hpp"
#include "internal/surface_sampling.hpp"

namespace featsense::mesh {
namespace {

std::vector<float> distances_to(const internal::ClosestPointQuery& query,
                                const std::vector<Eigen::Vector3d>& points) {
  std::vector<float> distances(points.size());
  tbb::parallel_for(size_t{0}, points.size(), [&](size_t i) {
    distances[i] = static_cast<float>(query.closest(points[i]).distance_m);
  });
  return distances;
}

double fraction(size_t part, size_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

}  // namespace

namespace internal {

void fill_scores(const CompareSettings& settings, const std::vector<size_t>& points_within,
                 const std::vector<size_t>& samples_within, CompareResult* result) {
  result->scores.clear();
  for (size_t k = 0; k < settings.thresholds_m.size(); ++k) {
    ThresholdScores s;
    s.threshold_m = settings.thresholds_m[k];
    s.precision = fraction(points_within[k], result->points);
    s.completeness = fraction(samples_within[k], result->reference_samples);
    const double sum = s.precision + s.completeness;
    s.fscore = sum > 0.0 ? 2.0 * s.precision * s.completeness / sum : 0.0;
    result->scores.push_back(s);
  }
}

}  // namespace internal

DistanceStatistics distance_statistics(const std::vector<float>& signed_distance_m) {
  CompareSettings settings;
  settings.histogram_bins = 0;
  internal::DistanceAccumulator distances(settings);
  for (const float d : signed_distance_m) distances.add(std::abs(d), d);
  CompareResult result;
  distances.fill(&result);
  return result.accuracy;
}

CompareResult compare_to_reference(const TriangleMesh& estimate, const TriangleMesh& reference,
                                   const CompareSettings& settings) {
  validate(estimate, "the estimate");
  validate(reference, "the reference");
  if (estimate.vertices.empty()) throw MeshError("the estimate has no vertices");
  if (reference.vertices.empty()) throw MeshError("the reference has no vertices");

  CompareResult result;
  result.reference_is_mesh = !reference.is_point_cloud();
  const internal::ClosestPointQuery to_reference(reference);
  result.signed_distances = to_reference.has_normals();

  // Accuracy: every estimate vertex to the reference.
  const size_t n = estimate.vertices.size();
  result.unsigned_distance_m.resize(n);
  result.signed_distance_m.resize(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const Eigen::Vector3d p = estimate.vertices[i].cast<double>();
    const internal::ClosestPoint c = to_reference.closest(p);
    const double side = (p - c.point).dot(c.normal);
    const double sign = side > 0.0 ? 1.0 : (side < 0.0 ? -1.0 : 0.0);
    result.unsigned_distance_m[i] = static_cast<float>(c.distance_m);
    result.signed_distance_m[i] =
        static_cast<float>(result.signed_distances ? sign * c.distance_m : c.distance_m);
  });
  internal::DistanceAccumulator distances(settings);
  for (size_t i = 0; i < n; ++i) {
    distances.add(result.unsigned_distance_m[i], result.signed_distance_m[i]);
  }
  distances.fill(&result);

  // Completeness: reference samples (or points) to the estimate.
  std::vector<Eigen::Vector3d> samples;
  if (result.reference_is_mesh) {
    const double area = surface_area_m2(reference);
    result.samples_per_m2 = settings.samples_per_m2;
    if (area * result.samples_per_m2 > static_cast<double>(settings.max_samples)) {
      result.samples_per_m2 = static_cast<double>(settings.max_samples) / area;
    }
    samples = internal::sample_surface(reference, result.samples_per_m2, settings.seed);
    // A tiny reference may draw no sample at this density: its vertices stand in.
    if (samples.empty()) {
      for (const auto& v : reference.vertices) samples.push_back(v.cast<double>());
    }
  } else {
    for (const auto& v : reference.vertices) samples.push_back(v.cast<double>());
  }
  result.reference_samples = samples.size();
  const internal::ClosestPointQuery to_estimate(estimate);
  const std::vector<float> back = distances_to(to_estimate, samples);

  std::vector<size_t> within;
  for (double t : settings.thresholds_m) {
    within.push_back(static_cast<size_t>(
        std::count_if(back.begin(), back.end(), [t](float d) { return d <= t; })));
  }
  internal::fill_scores(settings, distances.within(), within, &result);
  return result;
}

}  // namespace featsense::mesh
