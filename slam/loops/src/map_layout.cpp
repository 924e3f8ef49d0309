#include "featsense/slam/loops/map_layout.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace featsense::slam::loops {
namespace {

/// Map points farther than this from their keyframe are too sparse to say a column is upright
/// or free; a scan's columns reach scan_range_m from a sensor that may stand tens of metres
/// from the nearest keyframe.
constexpr double kMapPointRangeM = 80.0;

/// The most cells a layout holds: 11 bytes each while it is made, 7 kept (the levels), for a
/// map of up to 8 km by 8 km at metre cells. A larger map is searched by its descriptors alone.
constexpr size_t kMaxCells = size_t{64} << 20;

constexpr int8_t kUpright = 2;
constexpr int8_t kNextToUpright = 1;

/// Whether a column's occupied height bins hold a run of `run` bins one above the other: a
/// wall, a post or a car does; the ground with a stray point above it (a wire, a branch, a
/// point mixed between a facade and the sky) does not.
bool upright(uint64_t bins, int run) {
  uint64_t together = bins;
  for (int k = 1; k < run; ++k) together &= bins >> static_cast<unsigned>(k);
  return together != 0;
}

/// The columns one scan's points fall in (cells of a grid the caller owns), each judged
/// upright or not from that scan's points alone, by height bins from the column's lowest
/// point: a scan of the map and the scan searched for are judged alike (a column that
/// gathers the points of a thousand keyframes gathers strays enough to look upright).
class ColumnScratch {
 public:
  explicit ColumnScratch(size_t cells)
      : low_(cells, std::numeric_limits<float>::infinity()), bins_(cells, 0) {}

  /// `visit(cell, upright)` once for each cell of `points` (cell, height); then forgets them.
  template <class Visit>
  void classify(const std::vector<std::pair<size_t, float>>& points,
                const MapLayoutSettings& settings, Visit visit) {
    for (const auto& [cell, z] : points) {
      if (low_[cell] == std::numeric_limits<float>::infinity()) touched_.push_back(cell);
      low_[cell] = std::min(low_[cell], z);
    }
    for (const auto& [cell, z] : points) {
      const auto bin = static_cast<int64_t>(std::floor((z - low_[cell]) / settings.height_bin_m));
      if (bin < 64) bins_[cell] |= uint64_t{1} << static_cast<unsigned>(bin);
    }
    for (const size_t cell : touched_) {
      visit(cell, upright(bins_[cell], settings.min_upright_bins));
      low_[cell] = std::numeric_limits<float>::infinity();
      bins_[cell] = 0;
    }
    touched_.clear();
  }

 private:
  std::vector<float> low_;
  std::vector<uint64_t> bins_;
  std::vector<size_t> touched_;
};

/// The upright columns of points in a frame with z up, within `range` of the origin: their
/// centres, in order along y, then x.
std::vector<Eigen::Vector2d> upright_columns(const std::vector<Eigen::Vector3d>& points,
                                             double range, const MapLayoutSettings& settings) {
  const int half = static_cast<int>(std::ceil(range / settings.cell_m)) + 1;
  const int side = 2 * half + 1;
  std::vector<std::pair<size_t, float>> cells;
  cells.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const int x = static_cast<int>(std::lround(p.x() / settings.cell_m)) + half;
    const int y = static_cast<int>(std::lround(p.y() / settings.cell_m)) + half;
    if (x < 0 || y < 0 || x >= side || y >= side) continue;
    cells.emplace_back(static_cast<size_t>(y) * static_cast<size_t>(side) + static_cast<size_t>(x),
                       static_cast<float>(p.z()));
  }
  std::vector<size_t> found;
  ColumnScratch scratch(static_cast<size_t>(side) * static_cast<size_t>(side));
  scratch.classify(cells, settings, [&](size_t cell, bool is_upright) {
    if (is_upright) found.push_back(cell);
  });
  std::sort(found.begin(), found.end());
  std::vector<Eigen::Vector2d> out;
  for (const size_t cell : found) {
    const int x = static_cast<int>(cell % static_cast<size_t>(side));
    const int y = static_cast<int>(cell / static_cast<size_t>(side));
    out.emplace_back((x - half) * settings.cell_m, (y - half) * settings.cell_m);
  }
  return out;
}

struct Node {
  int heading = 0;
  int x = 0;
  int y = 0;
  int level = 0;
  double share = 0.0;
};

struct Leaf {
  int heading = 0;
  int x = 0;
  int y = 0;
  double share = 0.0;
};

}  // namespace

MapLayout::MapLayout(const std::vector<MapKeyframe>& keyframes, const MapLayoutSettings& settings)
    : settings_(settings) {
  const size_t count = keyframes.size();
  counts_.keyframes = count;
  if (count == 0 || !(settings_.cell_m > 0.0) || !(settings_.height_bin_m > 0.0)) return;
  std::vector<Eigen::Isometry3d> poses;
  for (const MapKeyframe& keyframe : keyframes) {
    if (!keyframe.T_map_sensor.matrix().allFinite()) return;
    poses.push_back(keyframe.T_map_sensor);
  }
  const double cell = settings_.cell_m;
  // The grid: every keyframe's points' reach, with room around it for every scan column and
  // every square of places.
  Eigen::Vector2d low = poses[0].translation().head<2>();
  Eigen::Vector2d high = low;
  for (size_t k = 0; k < count; ++k) {
    keyframe_positions_.push_back(poses[k].translation());
    low = low.cwiseMin(poses[k].translation().head<2>());
    high = high.cwiseMax(poses[k].translation().head<2>());
  }
  const Eigen::Vector2i lo = ((low.array() - kMapPointRangeM) / cell).floor().cast<int>();
  const Eigen::Vector2i hi = ((high.array() + kMapPointRangeM) / cell).floor().cast<int>();
  pad_ = static_cast<int>(std::ceil(settings_.scan_range_m / cell)) + 2 + (1 << settings_.levels);
  if (static_cast<double>(hi.x() - lo.x() + 1 + 2 * pad_) *
          static_cast<double>(hi.y() - lo.y() + 1 + 2 * pad_) >
      static_cast<double>(kMaxCells)) {
    counts_.too_large = true;
    return;
  }
  width_ = hi.x() - lo.x() + 1 + 2 * pad_;
  height_ = hi.y() - lo.y() + 1 + 2 * pad_;
  origin_ = Eigen::Vector2d((lo.x() - pad_) * cell, (lo.y() - pad_) * cell);
  const auto index = [&](int gx, int gy) {
    return static_cast<size_t>(gy) * static_cast<size_t>(width_) + static_cast<size_t>(gx);
  };
  // Each keyframe's columns judged from its own points; a column is upright where at least
  // a quarter of the keyframes that saw it saw it upright (a parked car seen from one side, a
  // wall seen from far off by some of them).
  const size_t cells = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  std::vector<uint16_t> seen_by(cells, 0);
  std::vector<uint16_t> upright_by(cells, 0);
  // A keyframe's points lie within kMapPointRangeM of it: its columns are judged on a grid
  // of that reach around it.
  const int reach = static_cast<int>(std::ceil(kMapPointRangeM / cell)) + 1;
  const int side = 2 * reach + 1;
  ColumnScratch scratch(static_cast<size_t>(side) * static_cast<size_t>(side));
  std::vector<std::pair<size_t, float>> points;
  for (size_t k = 0; k < count; ++k) {
    const Eigen::Isometry3f T = poses[k].cast<float>();
    // The grid's cell of the keyframe's lower corner of reach.
    const int corner_x =
        static_cast<int>(std::floor(poses[k].translation().x() / cell)) - lo.x() + pad_ - reach;
    const int corner_y =
        static_cast<int>(std::floor(poses[k].translation().y() / cell)) - lo.y() + pad_ - reach;
    points.clear();
    for (const Eigen::Vector3f& p : keyframes[k].cloud.points()) {
      if (p.head<2>().norm() > kMapPointRangeM) continue;
      const Eigen::Vector3f q = T * p;
      if (!q.allFinite()) continue;
      const int x = static_cast<int>(std::floor(q.x() / cell)) - lo.x() + pad_ - corner_x;
      const int y = static_cast<int>(std::floor(q.y() / cell)) - lo.y() + pad_ - corner_y;
      if (x < 0 || y < 0 || x >= side || y >= side) continue;
      points.emplace_back(
          static_cast<size_t>(y) * static_cast<size_t>(side) + static_cast<size_t>(x), q.z());
    }
    scratch.classify(points, settings_, [&](size_t local, bool is_upright) {
      const size_t c = index(corner_x + static_cast<int>(local % static_cast<size_t>(side)),
                             corner_y + static_cast<int>(local / static_cast<size_t>(side)));
      if (seen_by[c] < std::numeric_limits<uint16_t>::max()) {
        ++seen_by[c];
        upright_by[c] = static_cast<uint16_t>(upright_by[c] + (is_upright ? 1 : 0));
      }
    });
  }
  // The places searched: the box of the columns observed.
  search_lo_ = Eigen::Vector2i(width_, height_);
  search_hi_ = Eigen::Vector2i(0, 0);
  std::vector<int8_t> is_upright(cells, 0);
  for (int gy = 0; gy < height_; ++gy) {
    for (int gx = 0; gx < width_; ++gx) {
      const size_t c = index(gx, gy);
      if (seen_by[c] == 0) continue;
      ++counts_.observed_cells;
      search_lo_ = search_lo_.cwiseMin(Eigen::Vector2i(gx, gy));
      search_hi_ = search_hi_.cwiseMax(Eigen::Vector2i(gx + 1, gy + 1));
      if (4 * upright_by[c] >= seen_by[c] && upright_by[c] > 0) {
        is_upright[c] = 1;
        ++counts_.upright_cells;
      }
    }
  }
  if (counts_.observed_cells == 0) return;
  const auto free_value = static_cast<int8_t>(-std::lround(2.0 * settings_.free_cost));
  std::vector<int8_t> values(is_upright.size(), 0);
  for (int gy = 1; gy + 1 < height_; ++gy) {
    for (int gx = 1; gx + 1 < width_; ++gx) {
      if (is_upright[index(gx, gy)]) {
        values[index(gx, gy)] = kUpright;
        continue;
      }
      bool next_to = false;
      for (int dy = -1; dy <= 1 && !next_to; ++dy)
        for (int dx = -1; dx <= 1 && !next_to; ++dx) next_to = is_upright[index(gx + dx, gy + dy)];
      if (next_to)
        values[index(gx, gy)] = kNextToUpright;
      else if (seen_by[index(gx, gy)] != 0)
        values[index(gx, gy)] = free_value;
    }
  }
  levels_.push_back(std::move(values));
  for (int h = 1; h <= settings_.levels; ++h) {
    const std::vector<int8_t>& below = levels_.back();
    const int step = 1 << (h - 1);
    std::vector<int8_t> level(below.size(), 0);
    // Beyond the grid the map is unknown: 0.
    const auto at = [&](int x, int y) -> int8_t {
      return x < width_ && y < height_ ? below[index(x, y)] : int8_t{0};
    };
    for (int gy = 0; gy < height_; ++gy)
      for (int gx = 0; gx < width_; ++gx)
        level[index(gx, gy)] = std::max(
            {below[index(gx, gy)], at(gx + step, gy), at(gx, gy + step), at(gx + step, gy + step)});
    levels_.push_back(std::move(level));
  }
  counts_.width = static_cast<size_t>(width_);
  counts_.height = static_cast<size_t>(height_);
  counts_.bytes = levels_.size() * levels_.front().size();
}

std::vector<MapLayout::Heading> MapLayout::headings(
    const std::vector<Eigen::Vector2d>& columns) const {
  const double cell = settings_.cell_m;
  const double range = std::max(settings_.scan_range_m, cell);
  // The farthest column moves by at most a cell from one heading to the next.
  const double step = std::acos(1.0 - cell * cell / (2.0 * range * range));
  const int count = static_cast<int>(std::ceil(2.0 * M_PI / step));
  std::vector<Heading> out(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    Heading& heading = out[static_cast<size_t>(k)];
    heading.yaw_rad = 2.0 * M_PI * k / count;
    const Eigen::Rotation2Dd turn(heading.yaw_rad);
    for (const Eigen::Vector2d& c : columns) {
      const Eigen::Vector2d p = turn * c;
      const auto dx = static_cast<int32_t>(std::lround(p.x() / cell));
      const auto dy = static_cast<int32_t>(std::lround(p.y() / cell));
      heading.offsets.push_back(dy * width_ + dx);
    }
    std::sort(heading.offsets.begin(), heading.offsets.end());
    heading.offsets.erase(std::unique(heading.offsets.begin(), heading.offsets.end()),
                          heading.offsets.end());
  }
  return out;
}

std::vector<LayoutPeak> MapLayout::search(const std::vector<Eigen::Vector3f>& points,
                                          const Eigen::Matrix3d& levelling) const {
  if (levels_.empty()) return {};
  std::vector<Eigen::Vector3d> levelled;
  levelled.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const Eigen::Vector3d q = levelling * p.cast<double>();
    const double r = q.head<2>().norm();
    if (r >= settings_.scan_min_range_m && r <= settings_.scan_range_m) levelled.push_back(q);
  }
  const std::vector<Eigen::Vector2d> columns =
      upright_columns(levelled, settings_.scan_range_m, settings_);
  if (columns.size() < settings_.min_scan_columns) return {};
  const std::vector<Heading> turned = headings(columns);

  const auto share = [&](int heading, int x, int y, int level) {
    const Heading& h = turned[static_cast<size_t>(heading)];
    const std::vector<int8_t>& values = levels_[static_cast<size_t>(level)];
    const int64_t base = static_cast<int64_t>(y) * width_ + x;
    int64_t sum = 0;
    for (const int32_t offset : h.offsets) sum += values[static_cast<size_t>(base + offset)];
    return static_cast<double>(sum) / (2.0 * static_cast<double>(h.offsets.size()));
  };
  std::vector<Leaf> best;
  const double separation_cells = settings_.peak_separation_m / settings_.cell_m;
  const int half_turn = static_cast<int>(turned.size()) / 2;
  const auto threshold = [&] {
    return best.size() < settings_.peaks ? settings_.min_score : best.back().share;
  };
  const auto offer = [&](const Leaf& leaf) {
    const auto same_place = [&](const Leaf& other) {
      int turn = std::abs(other.heading - leaf.heading);
      turn = std::min(turn, static_cast<int>(turned.size()) - turn);
      return std::hypot(other.x - leaf.x, other.y - leaf.y) < separation_cells &&
             turn < half_turn / 2;
    };
    for (const Leaf& other : best)
      if (same_place(other) && other.share >= leaf.share) return;
    best.erase(std::remove_if(best.begin(), best.end(), same_place), best.end());
    best.insert(std::upper_bound(best.begin(), best.end(), leaf,
                                 [](const Leaf& a, const Leaf& b) { return a.share > b.share; }),
                leaf);
    if (best.size() > settings_.peaks) best.resize(settings_.peaks);
  };
  const auto by_share = [](const Node& a, const Node& b) { return a.share > b.share; };

  // Depth first from the best bound down; a square only splits while it may beat the
  // places kept.
  const auto branch = [&](const Node& root, auto& self) -> void {
    if (root.share <= threshold()) return;
    if (root.level == 0) {
      offer({root.heading, root.x, root.y, root.share});
      return;
    }
    const int level = root.level - 1;
    const int step = 1 << level;
    std::vector<Node> children;
    for (int dy = 0; dy <= step; dy += step) {
      for (int dx = 0; dx <= step; dx += step) {
        const int x = root.x + dx;
        const int y = root.y + dy;
        if (x >= search_hi_.x() || y >= search_hi_.y()) continue;
        children.push_back({root.heading, x, y, level, share(root.heading, x, y, level)});
      }
    }
    std::sort(children.begin(), children.end(), by_share);
    for (const Node& child : children) self(child, self);
  };
  if (settings_.exhaustive) {
    for (int k = 0; k < static_cast<int>(turned.size()); ++k)
      for (int y = search_lo_.y(); y < search_hi_.y(); ++y)
        for (int x = search_lo_.x(); x < search_hi_.x(); ++x) {
          const double s = share(k, x, y, 0);
          if (s > threshold()) offer({k, x, y, s});
        }
  }
  const int top = settings_.exhaustive ? -1 : settings_.levels;
  const int step = 1 << std::max(top, 0);
  std::vector<Node> roots;
  for (int k = 0; top >= 0 && k < static_cast<int>(turned.size()); ++k)
    for (int y = search_lo_.y(); y < search_hi_.y(); y += step)
      for (int x = search_lo_.x(); x < search_hi_.x(); x += step)
        roots.push_back({k, x, y, top, share(k, x, y, top)});
  std::stable_sort(roots.begin(), roots.end(), by_share);
  for (const Node& root : roots) {
    if (root.share <= threshold()) break;
    branch(root, branch);
  }

  std::vector<LayoutPeak> out;
  for (const Leaf& leaf : best) {
    const Eigen::Vector2d position =
        origin_ + settings_.cell_m * Eigen::Vector2d(leaf.x + 0.5, leaf.y + 0.5);
    double z = 0.0;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& k : keyframe_positions_) {
      const double d = (k.head<2>() - position).squaredNorm();
      if (d < nearest) {
        nearest = d;
        z = k.z();
      }
    }
    LayoutPeak peak;
    peak.T_map_query.linear() = Eigen::AngleAxisd(turned[static_cast<size_t>(leaf.heading)].yaw_rad,
                                                  Eigen::Vector3d::UnitZ())
                                    .toRotationMatrix() *
                                levelling;
    peak.T_map_query.translation() = Eigen::Vector3d(position.x(), position.y(), z);
    peak.score = leaf.share;
    out.push_back(peak);
  }
  return out;
}

}  // namespace featsense::slam::loops
