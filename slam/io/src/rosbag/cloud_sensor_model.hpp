#pragma once
/// The sensor model of a bag of point clouds, which carries no sensor metadata: a preset
/// chosen by the number of beams, or one estimated from an organized cloud.

#include <optional>
#include <string>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam {

/// The preset for `rings` beams when sensor.preset is "auto": vlp16 for 16, hdl32 for 32,
/// os1-64 for 64, os1-128 for 128 (Velodyne for the counts only Velodyne makes, Ouster for
/// those both make). With `round_up`, the smallest of these with at least `rings` beams, for
/// an unorganized cloud whose highest ring indices may have had no return. Nullopt where
/// none fits.
std::optional<std::string> preset_for_rings(int rings, bool round_up);

/// A model estimated from one organized scan whose row 0 is the highest beam: beams = rows,
/// columns = cols, each beam's elevation the mean elevation of its row's points (rows
/// without points interpolated from their neighbours). Range limits are left wide
/// (0 .. 1000 m) since nothing is known about them. Nullopt where fewer than two rows hold
/// points.
std::optional<config::SensorModel> sensor_model_from_scan(const Scan& scan);

}  // namespace featsense::slam
