#include "place_correlation.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace featsense::mapping {
namespace {

int cell_of(double metres, double cell_m) { return static_cast<int>(std::lround(metres / cell_m)); }

Eigen::Matrix3d turned(double turn_rad, const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(turn_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

/// The map seen from above around `origin`, cells `cell_m` across, `half` each way: 1 on the
/// upright surface, 0.5 next to it (the shifts are whole cells and the turns some way apart,
/// so the true place falls up to half a cell off), -free_cost where the map saw through the
/// column and no upright surface is in or next to it, 0 where it never looked.
class MapImage {
 public:
  MapImage(const std::vector<Eigen::Vector2f>& upright,
           const std::vector<Eigen::Vector2f>& observed, const Eigen::Vector2d& origin,
           double cell_m, int half, double free_cost)
      : half_(half), side_(2 * half + 1), values_(static_cast<size_t>(side_) * side_, 0.0f) {
    // 1: upright surface; 2: observed, no upright surface.
    std::vector<unsigned char> kind(values_.size(), 0);
    const auto mark = [&](const std::vector<Eigen::Vector2f>& points, unsigned char value) {
      for (const Eigen::Vector2f& p : points) {
        const int x = cell_of(p.x() - origin.x(), cell_m);
        const int y = cell_of(p.y() - origin.y(), cell_m);
        if (std::abs(x) <= half && std::abs(y) <= half) kind[index(x, y)] = value;
      }
    };
    mark(observed, 2);
    mark(upright, 1);
    for (int y = -half; y <= half; ++y) {
      for (int x = -half; x <= half; ++x) {
        const unsigned char here = kind[index(x, y)];
        float& value = values_[index(x, y)];
        if (here == 1) {
          value = 1.0f;
          continue;
        }
        bool beside = false;
        for (int v = std::max(-half, y - 1); v <= std::min(half, y + 1) && !beside; ++v)
          for (int u = std::max(-half, x - 1); u <= std::min(half, x + 1) && !beside; ++u)
            beside = kind[index(u, v)] == 1;
        if (beside)
          value = 0.5f;
        else if (here == 2)
          value = static_cast<float>(-free_cost);
      }
    }
  }

  size_t index(int x, int y) const {
    return static_cast<size_t>(y + half_) * static_cast<size_t>(side_) +
           static_cast<size_t>(x + half_);
  }
  const float* at(int x, int y) const { return &values_[index(x, y)]; }

 private:
  int half_;
  int side_;
  std::vector<float> values_;
};

struct Shift {
  double score = 0.0;
  double turn_rad = 0.0;  ///< about the base rotation
  int dx = 0;
  int dy = 0;
};

/// Every shift within `reach` cells and every turn of `turns_rad` of the scan's upright
/// points (sensor frame, within `range_m`) turned by turn * R_base, scored on `image` (cells
/// of `cell_m` about the base position). Nothing where the scan has no cell.
std::vector<Shift> scored_shifts(const MapImage& image, double cell_m, int reach,
                                 const std::vector<Eigen::Vector3d>& scan, double range_m,
                                 const Eigen::Matrix3d& R_base,
                                 const std::vector<double>& turns_rad) {
  std::vector<Shift> out;
  const int side = 2 * reach + 1;
  std::vector<float> scores(static_cast<size_t>(side) * side);
  std::vector<std::pair<int, int>> cells;
  const double range2 = range_m * range_m;
  for (const double turn_rad : turns_rad) {
    const Eigen::Matrix3d R = turned(turn_rad, R_base);
    // The scan's cells, each once: a tall wall is one cell seen from above.
    cells.clear();
    for (const Eigen::Vector3d& p : scan) {
      if (p.head<2>().squaredNorm() > range2) continue;
      const Eigen::Vector3d q = R * p;
      cells.emplace_back(cell_of(q.x(), cell_m), cell_of(q.y(), cell_m));
    }
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    if (cells.empty()) return {};
    // Each scan cell adds the image under it at every shift, a row of shifts at a time.
    std::fill(scores.begin(), scores.end(), 0.0f);
    for (const auto& [cx, cy] : cells) {
      for (int dy = -reach; dy <= reach; ++dy) {
        const float* row = image.at(cx - reach, cy + dy);
        float* sum = &scores[static_cast<size_t>(dy + reach) * side];
        for (int k = 0; k < side; ++k) sum[k] += row[k];
      }
    }
    const double count = static_cast<double>(cells.size());
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        out.push_back({scores[static_cast<size_t>(dy + reach) * side + (dx + reach)] / count,
                       turn_rad, dx, dy});
  }
  // Best first; of equal scores the nearer the base.
  std::sort(out.begin(), out.end(), [](const Shift& a, const Shift& b) {
    if (a.score != b.score) return a.score > b.score;
    return a.dx * a.dx + a.dy * a.dy < b.dx * b.dx + b.dy * b.dy;
  });
  return out;
}

PlacePeak place_of(const Shift& s, const Eigen::Isometry3d& base, double cell_m) {
  PlacePeak peak;
  peak.T_map_query.linear() = turned(s.turn_rad, base.linear());
  peak.T_map_query.translation() =
      base.translation() + Eigen::Vector3d(s.dx * cell_m, s.dy * cell_m, 0.0);
  peak.score = s.score;
  return peak;
}

double heading_difference_rad(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const Eigen::Matrix3d R = a.transpose() * b;
  return std::abs(std::atan2(R(1, 0), R(0, 0)));
}

/// Adds `place` to `taken` (at most `count`) unless one there lies within `separation_m` of it
/// facing alike: fed best first, `taken` keeps the best distinct places.
void take_if_separated(std::vector<PlacePeak>& taken, const PlacePeak& place, double separation_m,
                       size_t count) {
  if (taken.size() >= count) return;
  const bool near_taken = std::any_of(taken.begin(), taken.end(), [&](const PlacePeak& t) {
    return heading_difference_rad(t.T_map_query.linear(), place.T_map_query.linear()) <
               M_PI / 2.0 &&
           (t.T_map_query.translation() - place.T_map_query.translation()).head<2>().norm() <
               separation_m;
  });
  if (!near_taken) taken.push_back(place);
}

std::vector<double> radians(const std::vector<double>& degrees) {
  std::vector<double> out;
  for (const double d : degrees) out.push_back(d * M_PI / 180.0);
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> upright_points(const slam::refine::GaussianCloud& cloud,
                                            const Eigen::Matrix3d& R_map_sensor,
                                            double max_normal_z) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(cloud.size());
  // The map's vertical in the sensor's frame.
  const Eigen::Vector3d up = R_map_sensor.row(2).transpose();
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (slam::refine::normal_alignment(cloud.covariances[i], up) <= max_normal_z)
      out.push_back(cloud.points[i]);
  }
  return out;
}

std::vector<PlacePeak> correlate_place(const std::vector<Eigen::Vector2f>& map_upright,
                                       const std::vector<Eigen::Vector2f>& map_observed,
                                       const std::vector<Eigen::Vector3d>& scan_upright,
                                       const Eigen::Isometry3d& guess,
                                       const PlaceCorrelationSettings& settings) {
  // Coarse: every shift within reach, each way round.
  const double cell = settings.cell_m;
  const int reach = std::max(0, static_cast<int>(std::ceil(settings.reach_m / cell)));
  const int scan_cells = static_cast<int>(std::ceil(settings.scan_range_m / cell));
  const MapImage coarse(map_upright, map_observed, guess.translation().head<2>(), cell,
                        reach + scan_cells + 1, settings.free_cost);
  std::vector<double> turns = radians(settings.turns_deg);
  if (settings.both_ways)
    for (size_t i = 0, n = turns.size(); i < n; ++i) turns.push_back(turns[i] + M_PI);
  const std::vector<Shift> shifts = scored_shifts(coarse, cell, reach, scan_upright,
                                                  settings.scan_range_m, guess.linear(), turns);
  if (shifts.empty()) return {};
  // The places are made from the best shifts only, as many as are taken.
  const size_t refined_count = std::max(settings.refined, settings.peaks);
  std::vector<PlacePeak> best;
  for (size_t i = 0; i < shifts.size() && best.size() < refined_count; ++i)
    take_if_separated(best, place_of(shifts[i], guess, cell), settings.peak_separation_m,
                      refined_count);
  if (!(settings.fine_cell_m > 0.0) || settings.fine_cell_m >= cell) {
    best.resize(std::min(best.size(), settings.peaks));
    return best;
  }

  // Fine: within a coarse cell of each, with finer turns about its heading.
  const double fine = settings.fine_cell_m;
  const int fine_reach = static_cast<int>(std::ceil(cell / fine));
  const int fine_scan_cells = static_cast<int>(std::ceil(settings.scan_range_m / fine));
  const std::vector<double> fine_turns = radians(settings.fine_turns_deg);
  std::vector<PlacePeak> fine_places;
  for (const PlacePeak& place : best) {
    const MapImage image(map_upright, map_observed, place.T_map_query.translation().head<2>(), fine,
                         fine_reach + fine_scan_cells + 1, settings.free_cost);
    const std::vector<Shift> around =
        scored_shifts(image, fine, fine_reach, scan_upright, settings.scan_range_m,
                      place.T_map_query.linear(), fine_turns);
    if (!around.empty()) fine_places.push_back(place_of(around.front(), place.T_map_query, fine));
  }
  std::stable_sort(fine_places.begin(), fine_places.end(),
                   [](const PlacePeak& a, const PlacePeak& b) { return a.score > b.score; });
  std::vector<PlacePeak> out;
  for (const PlacePeak& place : fine_places)
    take_if_separated(out, place, settings.peak_separation_m, settings.peaks);
  return out;
}

}  // namespace featsense::mapping
