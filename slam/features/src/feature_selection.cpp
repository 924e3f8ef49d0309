#include "featsense/slam/features/feature_selection.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam::features {

LinePicks select_line_features(const float* curvature, const uint8_t* excluded, int cols,
                               const FeatureSettings& settings) {
  LinePicks picks;
  const int n = settings.neighbours;
  const int first = n;
  const int span = cols - 2 * n;  // columns that can have a curvature
  if (span <= 0 || settings.sectors < 1) return picks;
  std::vector<uint8_t> taken(excluded, excluded + cols);
  auto take = [&](int col) {
    for (int k = std::max(0, col - n); k <= std::min(cols - 1, col + n); ++k) taken[k] = 1;
  };
  std::vector<int> order;
  for (int s = 0; s < settings.sectors; ++s) {
    const int begin = first + static_cast<int>(static_cast<long>(span) * s / settings.sectors);
    const int end = first + static_cast<int>(static_cast<long>(span) * (s + 1) / settings.sectors);
    order.clear();
    for (int col = begin; col < end; ++col) {
      if (!std::isnan(curvature[col])) order.push_back(col);
    }
    // Highest curvature first; ties by column, so the result does not depend on the sort.
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return curvature[a] != curvature[b] ? curvature[a] > curvature[b] : a < b;
    });
    int edges = 0;
    for (int col : order) {
      if (edges >= settings.max_edges_per_sector) break;
      const double c = curvature[col];
      if (c <= settings.edge_threshold) break;
      if (taken[col] || c >= settings.max_edge_threshold) continue;
      picks.edges.push_back(col);
      take(col);
      ++edges;
    }
    int surfaces = 0;
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
      if (surfaces >= settings.max_surfaces_per_sector) break;
      const int col = *it;
      if (curvature[col] >= settings.surface_threshold) break;
      if (taken[col]) continue;
      picks.surfaces.push_back(col);
      take(col);
      ++surfaces;
    }
  }
  return picks;
}

}  // namespace featsense::slam::features
