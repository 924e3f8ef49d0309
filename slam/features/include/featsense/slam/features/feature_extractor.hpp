#pragma once
/// The features of an organized scan: edge and surface points along each scan line (paper
/// eq. 1, LOAM's selection and filters), edges optionally confirmed by the intensity image.

#include "featsense/config/config.hpp"
#include "featsense/slam/feature_set.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam::features {

namespace detail {
/// The feature and odometry settings of config/default.yaml, where FeatureSettings' defaults
/// come from.
inline constexpr config::FeaturesConfig kDefaultFeatures{};
inline constexpr config::OdometryConfig kDefaultOdometry{};
}  // namespace detail

/// What the extraction needs: config::FeaturesConfig (the defaults and their reasons live
/// there and in config/default.yaml) and odometry.intensity_fusion. Default-constructed: the
/// default configuration's (a test keeps from_config(Config{}) equal to it).
struct FeatureSettings {
  int neighbours = detail::kDefaultFeatures.neighbours;  ///< N: curvature from +/- N points
  int sectors = detail::kDefaultFeatures.sectors;        ///< sub-regions per line
  int max_edges_per_sector = detail::kDefaultFeatures.max_edges_per_sector;
  int max_surfaces_per_sector = detail::kDefaultFeatures.max_surfaces_per_sector;
  /// Normalised curvature (curvature.hpp), dimensionless.
  double edge_threshold = detail::kDefaultFeatures.edge_threshold;
  /// Above: an unstable natural edge, no feature.
  double max_edge_threshold = detail::kDefaultFeatures.max_edge_threshold;
  double surface_threshold = detail::kDefaultFeatures.surface_threshold;
  double min_range_m = detail::kDefaultFeatures.min_range_m;
  double max_range_m = detail::kDefaultFeatures.max_range_m;
  double occlusion_jump_m = detail::kDefaultFeatures.occlusion_jump_m;
  /// In column spacings (range * 2 pi / cols).
  double parallel_gap_ratio = detail::kDefaultFeatures.parallel_gap_ratio;
  bool intensity_fusion = detail::kDefaultOdometry.intensity_fusion;
  double intensity_percentile = detail::kDefaultFeatures.intensity_percentile;
  double intensity_blur_sigma = detail::kDefaultFeatures.intensity_blur_sigma;
  double intensity_bilateral_sigma_color = detail::kDefaultFeatures.intensity_bilateral_sigma_color;
  double intensity_bilateral_sigma_space = detail::kDefaultFeatures.intensity_bilateral_sigma_space;
  double intensity_edge_fraction = detail::kDefaultFeatures.intensity_edge_fraction;
  double intensity_noise_factor = detail::kDefaultFeatures.intensity_noise_factor;
  int intensity_tolerance_px = detail::kDefaultFeatures.intensity_tolerance_px;
};

FeatureSettings from_config(const config::Config& config);

struct FeatureStats {
  size_t edges_geometric = 0;  ///< edge points before the intensity fusion
  size_t edges = 0;            ///< after it
  size_t surfaces = 0;
  bool intensity_confirmed = false;
  double curvature_ms = 0.0;  ///< curvature and the filters
  double selection_ms = 0.0;
  double intensity_ms = 0.0;  ///< the intensity image (made beside the curvature and selection)
  double total_ms = 0.0;
};

/// The scan's features. An empty scan or one without valid points gives an empty set.
FeatureSet extract_features(const Scan& scan, const FeatureSettings& settings,
                            FeatureStats* stats = nullptr);

}  // namespace featsense::slam::features
