#pragma once
/// The layout of a saved map seen from above, for finding a scan anywhere in it: the map's
/// keyframe points put into columns of a metre, each column upright (points over a metre or
/// more of height without a gap: a wall, a post, a car), observed and free of upright structure
/// (ground alone), or unknown. A scan's upright columns are laid over it at every heading and every
/// place the map covers; the places where they fall most on the map's upright columns and
/// least where the map saw ground alone are candidates for where the scan was taken.
///
/// A place descriptor of a keyframe proposes the map's keyframes only: a sensor on a street
/// the map saw from a crossing, or tens of metres along a straight street from the nearest
/// keyframe, is proposed nothing near it. The layout is matched wherever the map saw anything.
///
/// The search is branch and bound over the places (Olson, "Real-time correlative scan
/// matching", ICRA 2009; as in Hess et al., "Real-time loop closure in 2D LIDAR SLAM", ICRA
/// 2016): for each heading, the places are taken in squares of 2^h cells, each bounded by the
/// scan laid on the map's best column within reach of every cell (a precomputed maximum over
/// 2^h x 2^h), and a square is only split where its bound beats the best places found so far.
/// The result is what trying every place at every heading would give.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/slam/loops/map_keyframe.hpp"

namespace featsense::slam::loops {

struct MapLayoutSettings {
  double cell_m = 1.0;
  /// A column is upright where its points fill at least this many height bins one above the
  /// other.
  double height_bin_m = 0.4;
  int min_upright_bins = 3;
  /// The scan's columns used: within this horizontal distance of the sensor, beyond the
  /// vehicle or person carrying it. Headings are tried in steps that move the farthest column
  /// by at most a cell.
  double scan_range_m = 40.0;
  double scan_min_range_m = 2.0;
  /// What a scan's upright column costs where the map saw ground alone (in or next to it: an
  /// upright map column next to it gains half), against one on the map's upright columns,
  /// which gains 1.
  double free_cost = 0.5;
  /// Places kept, best first, at least this far apart (or facing more than 90 degrees apart),
  /// and the least share of the scan's upright columns matched that is worth keeping.
  size_t peaks = 4;
  double peak_separation_m = 8.0;
  double min_score = 0.3;
  /// The coarsest squares of places tried: 2^levels cells on a side.
  int levels = 6;
  /// The scan needs this many upright columns to be laid anywhere (fewer match everywhere).
  size_t min_scan_columns = 20;
  /// Every place at every heading, without bounds: the reference the bounded search is
  /// tested against (the same result, far slower).
  bool exhaustive = false;
};

struct LayoutPeak {
  /// The scan's sensor in the map: at the matched column's centre, at the height of the map's
  /// keyframe nearest it, facing the matched heading, levelled as the query was.
  Eigen::Isometry3d T_map_query = Eigen::Isometry3d::Identity();
  /// The share of the scan's upright columns on the map's (next to one: half), less
  /// free_cost for each on ground alone; at most 1.
  double score = 0.0;
};

struct MapLayoutCounts {
  size_t keyframes = 0;
  size_t width = 0;
  size_t height = 0;
  size_t upright_cells = 0;
  size_t observed_cells = 0;
  size_t bytes = 0;
  /// The map is too wide for a layout at its cells (none was made).
  bool too_large = false;
};

class MapLayout {
 public:
  /// The layout of `keyframes`' points, each at its T_map_sensor.
  explicit MapLayout(const std::vector<MapKeyframe>& keyframes,
                     const MapLayoutSettings& settings = {});

  /// The best places for a scan whose points (sensor frame) are `points`, turned upright by
  /// `levelling` (the sensor's roll and pitch; its heading is searched): best first, at most
  /// settings.peaks, none under settings.min_score; empty where the scan has too few upright
  /// columns in range.
  std::vector<LayoutPeak> search(const std::vector<Eigen::Vector3f>& points,
                                 const Eigen::Matrix3d& levelling) const;

  const MapLayoutCounts& counts() const { return counts_; }

 private:
  struct Heading {
    double yaw_rad = 0.0;
    std::vector<int32_t> offsets;  ///< the scan's columns as linear offsets in the grid
  };
  std::vector<Heading> headings(const std::vector<Eigen::Vector2d>& columns) const;

  MapLayoutSettings settings_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int width_ = 0;
  int height_ = 0;
  /// Columns a sensor may stand in: the cells the map observed, as a box [lo, hi).
  Eigen::Vector2i search_lo_ = Eigen::Vector2i::Zero();
  Eigen::Vector2i search_hi_ = Eigen::Vector2i::Zero();
  int pad_ = 0;
  /// levels_[h]: the best column value over the 2^h x 2^h cells from each cell up; levels_[0]
  /// the columns' own (2 upright, 1 next to upright, -1 observed free of upright, 0 unknown),
  /// row major from origin_.
  std::vector<std::vector<int8_t>> levels_;
  /// The keyframes' positions, for a found place's height.
  std::vector<Eigen::Vector3d> keyframe_positions_;
  MapLayoutCounts counts_;
};

}  // namespace featsense::slam::loops
