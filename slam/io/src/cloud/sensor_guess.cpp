#include "cloud/sensor_guess.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "beam_origin.hpp"
#include "featsense/slam/upper_median.hpp"
#include "point_validity.hpp"

namespace featsense::slam::cloud {
namespace {

struct RingPreset {
  int beams;
  const char* name;
};
/// Spinning sensors by beam count; 64 beams are taken for an HDL-64 (KITTI) rather than an
/// OS1-64, the more common source of unorganized 64-beam clouds.
constexpr RingPreset kRingPresets[] = {
    {16, "vlp16"}, {32, "hdl32"}, {64, "hdl64"}, {128, "os1-128"}};

constexpr size_t kMaxSampledPoints = 20000;
constexpr double kMinFitFraction = 0.9;
constexpr double kMinBeamsHitFraction = 0.5;

/// The elevation of `p` seen from the beam origin (beam_origin.hpp).
double elevation_of(const Eigen::Vector3f& p, double beam_origin_offset_m = 0.0) {
  const Eigen::Vector3d q = p.cast<double>();
  return std::atan2(q.z(), horizontal_from_beam_origin(q.x(), q.y(), beam_origin_offset_m));
}

double smallest_spacing(const std::vector<double>& elevation_rad) {
  double smallest = M_PI;
  for (size_t i = 1; i < elevation_rad.size(); ++i) {
    const double gap = std::abs(elevation_rad[i - 1] - elevation_rad[i]);
    if (gap > 0.0) smallest = std::min(smallest, gap);
  }
  return smallest;
}

}  // namespace

const std::vector<config::SensorModel>& builtin_presets() {
  static const std::vector<config::SensorModel> presets = [] {
    std::vector<config::SensorModel> out;
    for (const std::string& name : config::sensor_preset_names()) {
      out.push_back(config::sensor_preset(name));
    }
    return out;
  }();
  return presets;
}

std::optional<std::string> preset_for_rings(int rings) {
  for (const RingPreset& p : kRingPresets) {
    if (rings <= p.beams) return std::string(p.name);
  }
  return std::nullopt;
}

std::optional<std::string> preset_with_beams(int beams) {
  for (const RingPreset& p : kRingPresets) {
    if (beams == p.beams) return std::string(p.name);
  }
  return std::nullopt;
}

std::optional<std::string> preset_fitting_rows(const std::vector<std::optional<double>>& rows) {
  for (const config::SensorModel& preset : builtin_presets()) {
    if (static_cast<size_t>(preset.beams) != rows.size()) continue;
    const double tolerance = 0.25 * smallest_spacing(preset.elevation_rad);
    bool fits = true;
    for (size_t r = 0; r < rows.size() && fits; ++r) {
      fits = !rows[r] || std::abs(*rows[r] - preset.elevation_rad[r]) <= tolerance;
    }
    if (fits) return preset.name;
  }
  return std::nullopt;
}

std::vector<std::string> presets_fitting_elevations(const PointCloud& cloud) {
  std::vector<const Eigen::Vector3f*> sample;
  size_t data_points = 0;
  for (const Eigen::Vector3f& p : cloud.xyz) data_points += is_return(p) ? 1 : 0;
  const size_t step = std::max<size_t>(1, data_points / kMaxSampledPoints);
  size_t seen = 0;
  for (const Eigen::Vector3f& p : cloud.xyz) {
    if (is_return(p) && seen++ % step == 0) sample.push_back(&p);
  }
  std::vector<std::string> fitting;
  if (sample.empty()) return fitting;
  std::vector<double> elevations;
  for (const config::SensorModel& preset : builtin_presets()) {
    const std::vector<double>& beams = preset.elevation_rad;
    if (beams.empty()) continue;
    elevations.clear();
    for (const Eigen::Vector3f* p : sample)
      elevations.push_back(elevation_of(*p, preset.beam_origin_offset_m));
    const double tolerance = 0.25 * smallest_spacing(beams);
    std::vector<char> hit(beams.size(), 0);
    size_t on_beam = 0;
    for (double e : elevations) {
      // Beams are listed from the highest down.
      const auto below = std::lower_bound(beams.begin(), beams.end(), e, std::greater<double>());
      for (auto it : {below, below == beams.begin() ? below : below - 1}) {
        if (it != beams.end() && std::abs(*it - e) <= tolerance) {
          ++on_beam;
          hit[static_cast<size_t>(it - beams.begin())] = 1;
          break;
        }
      }
    }
    const double fit = static_cast<double>(on_beam) / static_cast<double>(elevations.size());
    const double beams_hit = static_cast<double>(std::count(hit.begin(), hit.end(), 1)) /
                             static_cast<double>(beams.size());
    if (fit >= kMinFitFraction && beams_hit >= kMinBeamsHitFraction) fitting.push_back(preset.name);
  }
  return fitting;
}

std::optional<std::string> preset_from_elevations(const PointCloud& cloud) {
  const std::vector<std::string> fitting = presets_fitting_elevations(cloud);
  if (fitting.size() != 1) return std::nullopt;
  return fitting.front();
}

namespace {

/// Median elevation of the points of one row, nullopt when it has none.
std::optional<double> row_elevation(const PointCloud& cloud, int width, int row,
                                    std::vector<double>& scratch) {
  scratch.clear();
  const size_t start = static_cast<size_t>(row) * static_cast<size_t>(width);
  for (size_t i = start; i < start + static_cast<size_t>(width) && i < cloud.xyz.size(); ++i) {
    if (is_return(cloud.xyz[i])) scratch.push_back(elevation_of(cloud.xyz[i]));
  }
  if (scratch.empty()) return std::nullopt;
  return upper_median(scratch);
}

bool row_has_data(const PointCloud& cloud, int width, int row) {
  const size_t start = static_cast<size_t>(row) * static_cast<size_t>(width);
  for (size_t i = start; i < start + static_cast<size_t>(width) && i < cloud.xyz.size(); ++i) {
    if (is_return(cloud.xyz[i])) return true;
  }
  return false;
}

}  // namespace

std::vector<std::optional<double>> row_elevations(const PointCloud& cloud, int width, int height) {
  std::vector<std::optional<double>> rows;
  std::vector<double> scratch;
  for (int r = 0; r < height; ++r) rows.push_back(row_elevation(cloud, width, r, scratch));
  return rows;
}

bool lowest_row_first(const PointCloud& cloud, int width, int height) {
  int first = 0, last = height - 1;
  while (first < height && !row_has_data(cloud, width, first)) ++first;
  while (last > first && !row_has_data(cloud, width, last)) --last;
  if (last <= first) return false;
  std::vector<double> scratch;
  return *row_elevation(cloud, width, first, scratch) < *row_elevation(cloud, width, last, scratch);
}

bool lowest_row_first(const std::vector<std::optional<double>>& elevation_rad) {
  const auto first = std::find_if(elevation_rad.begin(), elevation_rad.end(),
                                  [](const std::optional<double>& e) { return e.has_value(); });
  const auto last = std::find_if(elevation_rad.rbegin(), elevation_rad.rend(),
                                 [](const std::optional<double>& e) { return e.has_value(); });
  return first != elevation_rad.end() && **first < **last;
}

std::optional<config::SensorModel> sensor_from_rows(
    const std::vector<std::optional<double>>& elevation_rad, int columns) {
  std::vector<size_t> measured;
  for (size_t r = 0; r < elevation_rad.size(); ++r) {
    if (elevation_rad[r]) measured.push_back(r);
  }
  if (measured.size() < 2) return std::nullopt;
  config::SensorModel model;
  model.name = "measured-" + std::to_string(elevation_rad.size()) + "x" + std::to_string(columns);
  model.beams = static_cast<int>(elevation_rad.size());
  model.columns = columns;
  model.min_range_m = 0.0;
  model.max_range_m = 1000.0;
  // Linear through the two nearest measured rows (extrapolated at the ends).
  for (size_t r = 0; r < elevation_rad.size(); ++r) {
    if (elevation_rad[r]) {
      model.elevation_rad.push_back(*elevation_rad[r]);
      continue;
    }
    auto after = std::lower_bound(measured.begin(), measured.end(), r);
    if (after == measured.end()) --after;
    if (after == measured.begin()) ++after;
    const size_t r0 = *(after - 1), r1 = *after;
    const double e0 = *elevation_rad[r0], e1 = *elevation_rad[r1];
    const double t = (static_cast<double>(r) - static_cast<double>(r0)) /
                     (static_cast<double>(r1) - static_cast<double>(r0));
    model.elevation_rad.push_back(e0 + t * (e1 - e0));
  }
  for (size_t r = 0; r < model.elevation_rad.size(); ++r) {
    double& e = model.elevation_rad[r];
    e = std::clamp(e, -M_PI / 2, M_PI / 2);
    if (r > 0) e = std::min(e, model.elevation_rad[r - 1]);
  }
  model.azimuth_offset_rad.assign(elevation_rad.size(), 0.0);
  try {
    model.validate();
  } catch (const std::exception&) {
    return std::nullopt;  // too many rows or columns for a sensor
  }
  return model;
}

namespace {

constexpr double kMinMeasuredRangeM = 2.0;
constexpr double kBeamGapRad = 0.06 * M_PI / 180.0;
constexpr int kMinMeasuredBeams = 8;
constexpr int kMaxMeasuredBeams = 256;

struct PolarPoint {
  double elevation_rad;
  double azimuth_rad;
};

/// Every return at least kMinMeasuredRangeM away, as elevation and azimuth.
std::vector<PolarPoint> polar_sample(const PointCloud& cloud) {
  std::vector<PolarPoint> points;
  for (const Eigen::Vector3f& p : cloud.xyz) {
    if (!is_return(p)) continue;
    const double horizontal = std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()));
    if (std::hypot(horizontal, static_cast<double>(p.z())) < kMinMeasuredRangeM) continue;
    points.push_back(
        {elevation_of(p), std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x()))});
  }
  return points;
}

/// The median of the positive steps between the sorted azimuths: the column spacing.
std::optional<double> azimuth_step(std::vector<double> azimuth_rad) {
  if (azimuth_rad.size() < 16) return std::nullopt;
  std::sort(azimuth_rad.begin(), azimuth_rad.end());
  std::vector<double> steps;
  for (size_t k = 1; k < azimuth_rad.size(); ++k) {
    const double step = azimuth_rad[k] - azimuth_rad[k - 1];
    if (step > 1e-6) steps.push_back(step);
  }
  if (steps.empty()) return std::nullopt;
  return upper_median(steps);
}

}  // namespace

std::optional<SensorFromPoints> sensor_from_points(const PointCloud& cloud) {
  if (std::optional<std::string> preset = preset_from_elevations(cloud))
    return SensorFromPoints{preset, std::nullopt,
                            "preset " + *preset + " (points lie on its beam elevations)"};
  if (std::optional<config::SensorModel> measured = sensor_from_elevations(cloud)) {
    std::string why = std::to_string(measured->beams) + " beams and " +
                      std::to_string(measured->columns) +
                      " columns measured from the points (no preset fits them)";
    return SensorFromPoints{std::nullopt, std::move(measured), std::move(why)};
  }
  return std::nullopt;
}

std::optional<config::SensorModel> sensor_from_elevations(const PointCloud& cloud) {
  std::vector<PolarPoint> points = polar_sample(cloud);
  if (points.size() < 1000) return std::nullopt;
  std::sort(points.begin(), points.end(), [](const PolarPoint& a, const PolarPoint& b) {
    return a.elevation_rad > b.elevation_rad;  // the highest beam first, as SensorModel
  });
  // Runs of elevations without a gap: the candidate beams.
  std::vector<std::pair<size_t, size_t>> runs;  // [first, last)
  size_t first = 0;
  for (size_t k = 1; k <= points.size(); ++k) {
    if (k == points.size() || points[k - 1].elevation_rad - points[k].elevation_rad > kBeamGapRad) {
      runs.emplace_back(first, k);
      first = k;
    }
  }
  // A beam holds at least a fifth of the points of a typical one; fewer are strays between
  // beams (mixed pixels, noise).
  std::vector<size_t> sizes;
  for (const auto& [a, b] : runs) sizes.push_back(b - a);
  const size_t min_points = std::max<size_t>(8, upper_median(sizes) / 5);
  std::vector<std::optional<double>> elevation_rad;
  std::vector<double> columns;
  size_t on_beams = 0;
  for (const auto& [a, b] : runs) {
    if (b - a < min_points) continue;
    on_beams += b - a;
    elevation_rad.push_back(points[a + (b - a) / 2].elevation_rad);
    std::vector<double> azimuths;
    for (size_t k = a; k < b; ++k) azimuths.push_back(points[k].azimuth_rad);
    if (const std::optional<double> step = azimuth_step(std::move(azimuths)))
      columns.push_back(2.0 * M_PI / *step);
  }
  const int beams = static_cast<int>(elevation_rad.size());
  if (beams < kMinMeasuredBeams || beams > kMaxMeasuredBeams || columns.empty() ||
      static_cast<double>(on_beams) < kMinFitFraction * static_cast<double>(points.size()))
    return std::nullopt;
  std::optional<config::SensorModel> model =
      sensor_from_rows(elevation_rad, static_cast<int>(std::lround(upper_median(columns))));
  if (model) model->name = "measured-" + std::to_string(beams) + "-beams";
  return model;
}

}  // namespace featsense::slam::cloud
