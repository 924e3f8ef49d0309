#pragma once
// Which sensor recorded a cloud that does not say: from its ring count, from the elevations
// its points lie on, or measured from an organized cloud's rows.

#include <optional>
#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/point_cloud.hpp"

namespace featsense::slam::cloud {

/// Every built-in preset, parsed once.
const std::vector<config::SensorModel>& builtin_presets();

/// The smallest of vlp16 (16), hdl32 (32), hdl64 (64), os1-128 (128) with at least `rings`
/// beams, or nullopt beyond 128.
std::optional<std::string> preset_for_rings(int rings);

/// The preset with exactly `beams` beams among those four, or nullopt.
std::optional<std::string> preset_with_beams(int beams);

/// The preset with one beam per row whose elevations every measured row (row 0 highest)
/// matches within a quarter of its smallest beam spacing, or nullopt.
std::optional<std::string> preset_fitting_rows(const std::vector<std::optional<double>>& rows);

/// Every preset on whose beam elevations (seen from its beam origin) at least 90 % of the
/// cloud's points lie, with points on at least half of its beams, by name.
std::vector<std::string> presets_fitting_elevations(const PointCloud& cloud);

/// The preset on whose beam elevations at least 90 % of the cloud's points lie (within a
/// quarter of its smallest beam spacing), with points on at least half of its beams; nullopt
/// when no preset or more than one fits that well. Real sensors with per-unit calibrations
/// often fit none, which is the safe answer: the caller then asks the user.
std::optional<std::string> preset_from_elevations(const PointCloud& cloud);

/// A sensor model measured from an unorganized cloud's points, for a sensor no preset fits:
/// the beams are the elevations the points gather on (points at least 2 m away, seen from the
/// lidar origin, split where two neighbouring elevations lie more than 0.06 degrees apart),
/// each at its points' median; the columns from the median azimuth step along each beam.
/// Nullopt unless 90 % of those points lie on 8 to 256 such beams: a sensor with per-laser
/// height offsets (an HDL-64E) smears its beams and is not measured this way.
std::optional<config::SensorModel> sensor_from_elevations(const PointCloud& cloud);

/// What the points of a cloud without rings say about its sensor.
struct SensorFromPoints {
  std::optional<std::string> preset;            ///< the one preset whose beams they lie on
  std::optional<config::SensorModel> measured;  ///< else a model measured from them
  std::string why;                              ///< which, and why, for info and the report
};

/// preset_from_elevations, else sensor_from_elevations; nullopt where neither tells.
std::optional<SensorFromPoints> sensor_from_points(const PointCloud& cloud);

/// The elevation of each row of an organized cloud (row 0 first), radians: the median over
/// the row's points; nullopt for rows without any.
std::vector<std::optional<double>> row_elevations(const PointCloud& cloud, int width, int height);

/// Whether the first row with points lies lower than the last one (the file lists the lowest
/// beam first, where Scan wants the highest).
bool lowest_row_first(const std::vector<std::optional<double>>& elevation_rad);
/// The same for an organized cloud, measuring only those two rows.
bool lowest_row_first(const PointCloud& cloud, int width, int height);

/// A sensor model measured from row elevations (row 0 highest): rows without points are
/// interpolated, and the list is made non-increasing. Needs two measured rows.
std::optional<config::SensorModel> sensor_from_rows(
    const std::vector<std::optional<double>>& elevation_rad, int columns);

}  // namespace featsense::slam::cloud
