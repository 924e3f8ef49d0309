// Accuracy (estimate -> reference), completeness (reference -> estimate) and F-scores.

#include "featsense/mesh/compare_to_reference.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "internal/closest_point_query.hpp"
#include "internal/comparison_figures.hpp"
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

void fill_histogram(const std::vector<float>& magnitudes, double top, size_t bins,
                    CompareResult* result) {
  if (bins == 0) return;
  if (!(top > 0.0)) top = 1e-3;  // every point on the surface: one narrow bin holds them all
  for (size_t b = 0; b <= bins; ++b) {
    result->histogram_edges_m.push_back(top * static_cast<double>(b) / static_cast<double>(bins));
  }
  result->histogram_counts.assign(bins, 0);
  for (float d : magnitudes) {
    const auto bin = static_cast<size_t>(static_cast<double>(d) / top * static_cast<double>(bins));
    ++result->histogram_counts[std::min(bin, bins - 1)];
  }
}

}  // namespace

namespace internal {

void fill_accuracy_figures(const CompareSettings& settings, CompareResult* result) {
  result->points = result->unsigned_distance_m.size();
  result->beyond_max_dist = 0;
  std::vector<float> kept;
  std::vector<float> kept_magnitudes;
  for (size_t i = 0; i < result->points; ++i) {
    if (settings.max_dist_m > 0.0 && result->unsigned_distance_m[i] > settings.max_dist_m) {
      ++result->beyond_max_dist;
      continue;
    }
    kept.push_back(result->signed_distance_m[i]);
    kept_magnitudes.push_back(result->unsigned_distance_m[i]);
  }
  result->accuracy = distance_statistics(kept);
  fill_histogram(kept_magnitudes,
                 settings.max_dist_m > 0.0 ? settings.max_dist_m : result->accuracy.max,
                 settings.histogram_bins, result);
}

void fill_scores(const CompareSettings& settings, const std::vector<size_t>& samples_within,
                 CompareResult* result) {
  result->scores.clear();
  for (size_t k = 0; k < settings.thresholds_m.size(); ++k) {
    const double t = settings.thresholds_m[k];
    ThresholdScores s;
    s.threshold_m = t;
    s.precision = fraction(static_cast<size_t>(std::count_if(result->unsigned_distance_m.begin(),
                                                             result->unsigned_distance_m.end(),
                                                             [t](float d) { return d <= t; })),
                           result->points);
    s.completeness = fraction(samples_within[k], result->reference_samples);
    const double sum = s.precision + s.completeness;
    s.fscore = sum > 0.0 ? 2.0 * s.precision * s.completeness / sum : 0.0;
    result->scores.push_back(s);
  }
}

}  // namespace internal

DistanceStatistics distance_statistics(const std::vector<float>& signed_distance_m) {
  DistanceStatistics s;
  if (signed_distance_m.empty()) return s;
  s.count = signed_distance_m.size();
  const double n = static_cast<double>(s.count);
  std::vector<double> magnitudes;
  magnitudes.reserve(s.count);
  double sum_signed = 0.0;
  double sum_abs = 0.0;
  double sum_squares = 0.0;
  for (float value : signed_distance_m) {
    const double d = value;
    sum_signed += d;
    sum_abs += std::abs(d);
    sum_squares += d * d;
    magnitudes.push_back(std::abs(d));
  }
  s.mean_signed = sum_signed / n;
  s.mean_abs = sum_abs / n;
  s.rmse = std::sqrt(sum_squares / n);
  double dev_signed = 0.0;
  double dev_abs = 0.0;
  for (float value : signed_distance_m) {
    dev_signed += (value - s.mean_signed) * (value - s.mean_signed);
    dev_abs += (std::abs(value) - s.mean_abs) * (std::abs(value) - s.mean_abs);
  }
  s.std_signed = std::sqrt(dev_signed / n);
  s.std_abs = std::sqrt(dev_abs / n);
  std::sort(magnitudes.begin(), magnitudes.end());
  const size_t half = s.count / 2;
  s.median = s.count % 2 == 1 ? magnitudes[half] : 0.5 * (magnitudes[half - 1] + magnitudes[half]);
  const auto rank = static_cast<size_t>(std::ceil(0.95 * n));  // nearest rank, 1-based
  s.p95 = magnitudes[std::max<size_t>(rank, 1) - 1];
  s.max = magnitudes.back();
  return s;
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
  internal::fill_accuracy_figures(settings, &result);

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
  internal::fill_scores(settings, within, &result);
  return result;
}

}  // namespace featsense::mesh
