// organize(): unorganized points into the rows x cols range image of scan.hpp.

#include "featsense/slam/io/organize.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "beam_origin.hpp"
#include "point_validity.hpp"

namespace featsense::slam {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

/// Half the gap to the neighbouring beam beyond which a point at the edge of the fan is
/// taken as outside it; a single-beam sensor gets half a degree.
double half_spacing_at(const std::vector<double>& elevation_rad, size_t beam) {
  if (elevation_rad.size() < 2) return 0.5 * M_PI / 180.0;
  const size_t other = beam == 0 ? 1 : beam - 1;
  return 0.5 * std::abs(elevation_rad[beam] - elevation_rad[other]);
}

/// The beam nearest to a point's elevation, found by slope z / horizontal distance (which
/// grows with the elevation, so no arctangent per point): the beam boundaries are the
/// slopes of the elevations halfway between neighbouring beams. The horizontal distance is
/// counted from the beam origin (beam_origin.hpp).
class BeamLookup {
 public:
  /// `elevation_rad` from the highest beam to the lowest (SensorModel's order).
  BeamLookup(const std::vector<double>& elevation_rad, double beam_origin_offset_m)
      : offset_m_(beam_origin_offset_m) {
    const size_t beams = elevation_rad.size();
    if (beams == 0) return;
    top_ = slope(elevation_rad.front() + half_spacing_at(elevation_rad, 0));
    bottom_ = slope(elevation_rad.back() - half_spacing_at(elevation_rad, beams - 1));
    for (size_t i = 0; i + 1 < beams; ++i) {
      boundaries_.push_back(slope(0.5 * (elevation_rad[i] + elevation_rad[i + 1])));
    }
  }

  /// The row of the beam nearest to the point, or -1 when it lies more than half a beam
  /// spacing above the highest or below the lowest beam.
  int row_of(const Eigen::Vector3f& p) const {
    const double horizontal = horizontal_from_beam_origin(static_cast<double>(p.x()),
                                                          static_cast<double>(p.y()), offset_m_);
    const double s = static_cast<double>(p.z()) / horizontal;  // +-inf straight up / down
    if (!(s <= top_ && s >= bottom_)) return -1;
    // Boundaries descend; the number of them above the point is its row (a point exactly
    // halfway goes to the upper beam).
    const auto below =
        std::lower_bound(boundaries_.begin(), boundaries_.end(), s, std::greater<double>());
    return static_cast<int>(below - boundaries_.begin());
  }

 private:
  static double slope(double elevation_rad) {
    if (elevation_rad >= M_PI / 2) return std::numeric_limits<double>::infinity();
    if (elevation_rad <= -M_PI / 2) return -std::numeric_limits<double>::infinity();
    return std::tan(elevation_rad);
  }

  double offset_m_ = 0.0;
  std::vector<double> boundaries_;
  double top_ = 0.0;
  double bottom_ = 0.0;
};

void check_sizes(const PointCloud& cloud) {
  const size_t n = cloud.size();
  auto check = [n](size_t size, const std::string& what) {
    if (size != 0 && size != n) {
      throw std::invalid_argument("organize: " + what + " has " + std::to_string(size) +
                                  " values for " + std::to_string(n) + " points");
    }
  };
  check(cloud.ring.size(), "ring");
  check(cloud.time_offset_s.size(), "time_offset_s");
  check(cloud.range_m.size(), "range_m");
  for (const ScanChannel& c : cloud.channels) check(c.values.size(), "channel " + c.name);
}

}  // namespace

int column_of(const Eigen::Vector3f& xyz, int columns) {
  if (columns <= 0) return 0;
  // Clockwise from +x seen from above (+z): the negated mathematical azimuth. Column c is
  // centred on c * 2 pi / columns, as Ouster's measurement ids are.
  double clockwise = -std::atan2(static_cast<double>(xyz.y()), static_cast<double>(xyz.x()));
  if (!std::isfinite(clockwise)) return 0;
  if (clockwise < 0.0) clockwise += kTwoPi;
  const long column = std::lround(clockwise / kTwoPi * columns);
  return static_cast<int>(column % columns);
}

Scan organize(const PointCloud& cloud, const config::SensorModel& sensor, OrganizeStats* stats) {
  check_sizes(cloud);
  if (sensor.beams < 1 || sensor.columns < 1) {
    throw std::invalid_argument("organize: sensor '" + sensor.name + "' has no beams or columns");
  }
  const bool by_ring = !cloud.ring.empty();
  if (!by_ring && static_cast<int>(sensor.elevation_rad.size()) != sensor.beams) {
    throw std::invalid_argument("organize: sensor '" + sensor.name + "' lacks beam elevations");
  }
  OrganizeStats counts;
  counts.input_points = cloud.size();
  const BeamLookup beams(by_ring ? std::vector<double>() : sensor.elevation_rad,
                         sensor.beam_origin_offset_m);

  Scan scan = Scan::allocate(sensor.beams, sensor.columns);
  std::vector<ScanChannel*> channels;
  for (const ScanChannel& c : cloud.channels) scan.add_channel(c.name);
  // Pointers only after every add_channel: adding moves the vector's elements.
  for (const ScanChannel& c : cloud.channels) channels.push_back(scan.channel(c.name));

  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.xyz[i];
    if (!is_return(p)) {
      ++counts.dropped_invalid;
      continue;
    }
    int row = -1;
    if (by_ring) {
      const int ring = cloud.ring[i];
      if (ring >= 0 && ring < sensor.beams) {
        row = cloud.ring_counts_up ? sensor.beams - 1 - ring : ring;
      }
    } else {
      row = beams.row_of(p);
    }
    if (row < 0) {
      ++counts.dropped_outside;
      continue;
    }
    const size_t cell = scan.index(row, column_of(p, sensor.columns));
    const float range =
        !cloud.range_m.empty() && std::isfinite(cloud.range_m[i]) && cloud.range_m[i] > 0.0f
            ? cloud.range_m[i]
            : return_range(p);
    if (scan.valid[cell]) {
      ++counts.dropped_collisions;
      if (scan.range_m[cell] <= range) continue;
    }
    scan.valid[cell] = 1;
    scan.xyz[cell] = p;
    scan.range_m[cell] = range;
    scan.time_offset_s[cell] = cloud.time_offset_s.empty() ? 0.0f : cloud.time_offset_s[i];
    for (size_t c = 0; c < channels.size(); ++c) {
      channels[c]->values[cell] = cloud.channels[c].values[i];
    }
  }
  scan.stamp_ns = cloud.stamp_ns;
  if (stats) *stats = counts;
  return scan;
}

}  // namespace featsense::slam
