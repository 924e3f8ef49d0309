#pragma once
/// The edges of the scan's intensity image (FeatSense): 8-bit image, Gaussian blur, histogram
/// equalisation, bilateral filter, Sobel gradient magnitude, binarisation.

#include <cstdint>
#include <optional>
#include <vector>

#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {

/// The intensity channel (Scan::intensity()) as rows * cols grey levels: linear between its
/// intensity_percentile and 100 - intensity_percentile percentiles over the valid cells
/// (robust to a few specular outliers), clamped to 0 .. 255; an invalid cell takes the value
/// of the nearest valid cell before it on its row (after it at the row's start), so the
/// holes of a scan do not draw edges. nullopt without a channel or without valid cells.
std::optional<std::vector<uint8_t>> intensity_image(const Scan& scan,
                                                    const FeatureSettings& settings);

/// The binary edge image (rows * cols, 1: edge) of an 8-bit image: Gaussian blur,
/// equalisation, bilateral filter, Sobel x and y, magnitude. A pixel is an edge when its
/// magnitude exceeds both intensity_edge_fraction of the largest magnitude (the strongest
/// contrasts of this image, whatever its overall contrast) and intensity_noise_factor times
/// the median magnitude (an image of noise or texture alone has a large median, so only few
/// of its pixels pass); a uniform image has none.
std::vector<uint8_t> edge_image(const std::vector<uint8_t>& grey, int rows, int cols,
                                const FeatureSettings& settings);

/// edge_image(intensity_image(scan)); nullopt where intensity_image is.
std::optional<std::vector<uint8_t>> intensity_edges(const Scan& scan,
                                                    const FeatureSettings& settings);

/// Whether an edge lies within `tolerance` pixels (rows and columns) of (row, col).
bool near_edge(const std::vector<uint8_t>& edges, int rows, int cols, int row, int col,
               int tolerance);

}  // namespace featsense::slam::features
