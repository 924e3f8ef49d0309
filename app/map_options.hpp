#pragma once
// The options of `featsense map` that are parsed from text: --start / --end and
// --initial-pose. Bad text is a ConfigError naming the option.

#include <Eigen/Geometry>

#include <string>

#include "featsense/mapping/map_pipeline.hpp"
#include "map_job.hpp"

namespace featsense::app {

/// --start / --end as the scans to map.
mapping::FrameRange frame_range(const MapOptions& options);

/// --initial-pose "x,y,z,yaw_deg" as a pose (map <- the recording's first scan).
Eigen::Isometry3d parse_initial_pose(const std::string& text);

}  // namespace featsense::app
