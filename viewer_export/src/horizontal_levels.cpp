#include "internal/horizontal_levels.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace featsense::viewer_export {
namespace {

constexpr double kBinM = 0.1;
constexpr double kHorizontal = 0.9;       // |n.z| of a face that counts as floor or ceiling
constexpr double kMinStoreyM = 1.8;       // a ceiling lower than this above the floor is furniture
constexpr double kMinCeilingShare = 0.1;  // of the floor's area

/// Per height bin the area and its area-weighted height; a map, so that a mesh kilometres high
/// costs no more than a flat one.
struct Bin {
  double area = 0.0;
  double z_area = 0.0;
};
using Histogram = std::map<long, Bin>;

long bin_of(double z) { return std::lround(std::floor(z / kBinM)); }
void add(Histogram& histogram, double z, double area) {
  Bin& bin = histogram[bin_of(z)];
  bin.area += area;
  bin.z_area += z * area;
}

/// The most area within a bin and its two neighbours (a floor at a bin's edge counts whole),
/// among bins from `first_bin` up, and its mean height (nullopt: none).
std::optional<double> strongest(const Histogram& histogram, long first_bin, double* area) {
  std::optional<double> best;
  *area = 0.0;
  for (auto it = histogram.lower_bound(first_bin); it != histogram.end(); ++it) {
    Bin around;
    for (long k = it->first - 1; k <= it->first + 1; ++k) {
      const auto neighbour = histogram.find(k);
      if (neighbour == histogram.end()) continue;
      around.area += neighbour->second.area;
      around.z_area += neighbour->second.z_area;
    }
    if (around.area > *area) {
      *area = around.area;
      best = around.z_area / around.area;
    }
  }
  return best;
}

}  // namespace

HorizontalLevels find_horizontal_levels(const mesh::TriangleMesh& mesh) {
  Histogram up;
  Histogram down;
  const bool smooth = mesh.has_normals();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3f& b = mesh.vertices[static_cast<size_t>(t[1])];
    const Eigen::Vector3f& c = mesh.vertices[static_cast<size_t>(t[2])];
    const Eigen::Vector3f face = (b - a).cross(c - a);
    const double area = 0.5 * face.norm();
    if (!(area > 0.0)) continue;
    Eigen::Vector3f facing = face;
    if (smooth) {
      facing = mesh.normals[static_cast<size_t>(t[0])] + mesh.normals[static_cast<size_t>(t[1])] +
               mesh.normals[static_cast<size_t>(t[2])];
    }
    const double nz = facing.z() / std::max(facing.norm(), 1e-12f);
    const double z = (a.z() + b.z() + c.z()) / 3.0;
    if (nz > kHorizontal) add(up, z, area);
    if (nz < -kHorizontal) add(down, z, area);
  }
  HorizontalLevels levels;
  double floor_area = 0.0;
  levels.floor_m = strongest(up, std::numeric_limits<long>::min(), &floor_area);
  if (!levels.floor_m) return levels;
  double ceiling_area = 0.0;
  const std::optional<double> ceiling =
      strongest(down, bin_of(*levels.floor_m + kMinStoreyM), &ceiling_area);
  if (ceiling && ceiling_area >= kMinCeilingShare * floor_area) levels.ceiling_m = ceiling;
  return levels;
}

}  // namespace featsense::viewer_export
