#include "featsense/slam/features/feature_extractor.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <chrono>
#include <cstdint>
#include <optional>

#include "featsense/slam/features/curvature.hpp"
#include "featsense/slam/features/feature_filters.hpp"
#include "featsense/slam/features/feature_selection.hpp"
#include "featsense/slam/features/intensity_edges.hpp"

namespace featsense::slam::features {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

FeatureSettings from_config(const config::Config& config) {
  const config::FeaturesConfig& f = config.features;
  FeatureSettings s;
  s.neighbours = f.neighbours;
  s.sectors = f.sectors;
  s.max_edges_per_sector = f.max_edges_per_sector;
  s.max_surfaces_per_sector = f.max_surfaces_per_sector;
  s.edge_threshold = f.edge_threshold;
  s.max_edge_threshold = f.max_edge_threshold;
  s.surface_threshold = f.surface_threshold;
  s.min_range_m = f.min_range_m;
  s.max_range_m = f.max_range_m;
  s.occlusion_jump_m = f.occlusion_jump_m;
  s.parallel_gap_ratio = f.parallel_gap_ratio;
  s.intensity_fusion = config.odometry.intensity_fusion;
  s.intensity_percentile = f.intensity_percentile;
  s.intensity_blur_sigma = f.intensity_blur_sigma;
  s.intensity_bilateral_sigma_color = f.intensity_bilateral_sigma_color;
  s.intensity_bilateral_sigma_space = f.intensity_bilateral_sigma_space;
  s.intensity_edge_fraction = f.intensity_edge_fraction;
  s.intensity_noise_factor = f.intensity_noise_factor;
  s.intensity_tolerance_px = f.intensity_tolerance_px;
  return s;
}

FeatureSet extract_features(const Scan& scan, const FeatureSettings& settings,
                            FeatureStats* stats) {
  const auto start = Clock::now();
  FeatureStats local;
  FeatureSet set;
  set.sequence = scan.sequence;
  set.stamp_ns = scan.stamp_ns;
  if (!well_formed(scan)) {
    if (stats) *stats = local;
    return set;
  }

  // The intensity image does not depend on the geometry until the fusion: the two are made
  // side by side (the curvature and the selection are parallel over rows themselves).
  std::optional<std::vector<uint8_t>> image_edges;
  std::vector<LinePicks> lines(static_cast<size_t>(scan.rows));
  std::vector<int8_t> boundaries;
  tbb::parallel_invoke(
      [&] {
        const auto stage = Clock::now();
        if (settings.intensity_fusion) image_edges = intensity_edges(scan, settings);
        local.intensity_ms = ms_since(stage);
      },
      [&] {
        auto stage = Clock::now();
        std::vector<float> curvature = curvature_image(scan, settings.neighbours);
        std::vector<uint8_t> excluded = excluded_cells(scan, settings);
        boundaries = occluding_boundaries(scan, settings);
        // An occluding boundary is an edge whatever its curvature says (which counts the far
        // side's points): it competes with the others as a corner between the thresholds.
        const float boundary_curvature =
            static_cast<float>(0.5 * (settings.edge_threshold + settings.max_edge_threshold));
        for (size_t i = 0; i < boundaries.size(); ++i) {
          if (boundaries[i] == 0) continue;
          curvature[i] = boundary_curvature;
          excluded[i] = 0;
        }
        local.curvature_ms = ms_since(stage);
        stage = Clock::now();
        tbb::parallel_for(0, scan.rows, [&](int row) {
          const size_t at = scan.index(row, 0);
          lines[static_cast<size_t>(row)] = select_line_features(
              curvature.data() + at, excluded.data() + at, scan.cols, settings);
        });
        local.selection_ms = ms_since(stage);
      });
  set.intensity_confirmed = image_edges.has_value();
  const bool has_times = scan.time_offset_s.size() == scan.size();
  auto time_of = [&](size_t i) { return has_times ? scan.time_offset_s[i] : 0.0f; };
  for (int row = 0; row < scan.rows; ++row) {
    const LinePicks& picks = lines[static_cast<size_t>(row)];
    local.edges_geometric += picks.edges.size();
    for (int col : picks.edges) {
      if (image_edges && !near_edge(*image_edges, scan.rows, scan.cols, row, col,
                                    settings.intensity_tolerance_px)) {
        continue;
      }
      const size_t i = scan.index(row, col);
      set.edges.push_back(boundaries[i] == 0
                              ? scan.xyz[i]
                              : boundary_point(scan, row, col, boundaries[i], settings.neighbours));
      set.edge_time_s.push_back(time_of(i));
    }
    for (int col : picks.surfaces) {
      const size_t i = scan.index(row, col);
      set.surfaces.push_back(scan.xyz[i]);
      set.surface_time_s.push_back(time_of(i));
    }
  }

  local.edges = set.edges.size();
  local.surfaces = set.surfaces.size();
  local.intensity_confirmed = set.intensity_confirmed;
  local.total_ms = ms_since(start);
  if (stats) *stats = local;
  return set;
}

}  // namespace featsense::slam::features
