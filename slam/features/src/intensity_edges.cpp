#include "featsense/slam/features/intensity_edges.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace featsense::slam::features {
namespace {

/// The value at `percent` of the sorted values (nearest rank); `values` is reordered.
float percentile(std::vector<float>& values, double percent) {
  const double position = percent / 100.0 * static_cast<double>(values.size() - 1);
  const auto k = static_cast<std::ptrdiff_t>(std::lround(position));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<size_t>(k)];
}

}  // namespace

std::optional<std::vector<uint8_t>> intensity_image(const Scan& scan,
                                                    const FeatureSettings& settings) {
  const ScanChannel* channel = scan.intensity();
  if (channel == nullptr || scan.size() == 0 || channel->values.size() != scan.size() ||
      scan.valid.size() != scan.size()) {
    return std::nullopt;
  }
  std::vector<float> values;
  values.reserve(scan.size());
  for (size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i] && std::isfinite(channel->values[i])) values.push_back(channel->values[i]);
  }
  if (values.empty()) return std::nullopt;
  const float low = percentile(values, settings.intensity_percentile);
  const float high = std::max(percentile(values, 100.0 - settings.intensity_percentile), low);
  // One value throughout (a driver that fills the field with zeros): the channel tells
  // nothing, and taken as an image without edges it would drop every geometric edge.
  if (!(high > low)) return std::nullopt;
  const float scale = 255.0f / (high - low);

  std::vector<uint8_t> grey(scan.size(), 0);
  for (int row = 0; row < scan.rows; ++row) {
    const size_t start = scan.index(row, 0);
    int last = -1;  // the last valid grey level on this row
    int first_valid_col = -1;
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = start + static_cast<size_t>(col);
      const float v = channel->values[i];
      if (scan.valid[i] && std::isfinite(v)) {
        last = static_cast<int>(std::lround(std::clamp((v - low) * scale, 0.0f, 255.0f)));
        if (first_valid_col < 0) first_valid_col = col;
      }
      grey[i] = static_cast<uint8_t>(std::max(last, 0));
    }
    // The row's leading invalid cells take its first valid value.
    for (int col = 0; col < first_valid_col; ++col) {
      grey[start + static_cast<size_t>(col)] = grey[start + static_cast<size_t>(first_valid_col)];
    }
  }
  return grey;
}

std::vector<uint8_t> edge_image(const std::vector<uint8_t>& grey, int rows, int cols,
                                const FeatureSettings& settings) {
  std::vector<uint8_t> edges(grey.size(), 0);
  if (rows <= 0 || cols <= 0 || grey.size() != static_cast<size_t>(rows) * cols) return edges;
  cv::Mat image(rows, cols, CV_8UC1);
  std::copy(grey.begin(), grey.end(), image.ptr<uint8_t>());
  if (settings.intensity_blur_sigma > 0.0) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), settings.intensity_blur_sigma);
  }
  cv::equalizeHist(image, image);
  if (settings.intensity_bilateral_sigma_color > 0.0 &&
      settings.intensity_bilateral_sigma_space > 0.0) {
    cv::Mat filtered;
    cv::bilateralFilter(image, filtered, -1, settings.intensity_bilateral_sigma_color,
                        settings.intensity_bilateral_sigma_space);
    image = filtered;
  }
  cv::Mat dx;
  cv::Mat dy;
  cv::Sobel(image, dx, CV_32F, 1, 0, 3);
  cv::Sobel(image, dy, CV_32F, 0, 1, 3);
  cv::Mat magnitude;
  cv::magnitude(dx, dy, magnitude);
  CV_Assert(magnitude.isContinuous());

  const float* m = magnitude.ptr<float>();
  std::vector<float> sorted(m, m + grey.size());
  double max_value = 0.0;
  cv::minMaxLoc(magnitude, nullptr, &max_value);
  const auto largest = static_cast<float>(max_value);
  if (!(largest > 0.0f)) return edges;
  const float median = percentile(sorted, 50.0);
  const float threshold = std::max(static_cast<float>(settings.intensity_edge_fraction) * largest,
                                   static_cast<float>(settings.intensity_noise_factor) * median);
  for (size_t i = 0; i < grey.size(); ++i) edges[i] = m[i] > threshold;
  return edges;
}

std::optional<std::vector<uint8_t>> intensity_edges(const Scan& scan,
                                                    const FeatureSettings& settings) {
  auto grey = intensity_image(scan, settings);
  if (!grey) return std::nullopt;
  return edge_image(*grey, scan.rows, scan.cols, settings);
}

bool near_edge(const std::vector<uint8_t>& edges, int rows, int cols, int row, int col,
               int tolerance) {
  for (int r = std::max(0, row - tolerance); r <= std::min(rows - 1, row + tolerance); ++r) {
    for (int c = std::max(0, col - tolerance); c <= std::min(cols - 1, col + tolerance); ++c) {
      if (edges[static_cast<size_t>(r) * cols + static_cast<size_t>(c)]) return true;
    }
  }
  return false;
}

}  // namespace featsense::slam::features
