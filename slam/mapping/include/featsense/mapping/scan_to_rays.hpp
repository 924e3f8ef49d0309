#pragma once
// A placed scan as TSDF rays in the map frame: each point moved by the sensor's pose when
// its column was measured (deskewing, where the placement carries the motion over the scan)
// and its ray starting where the sensor was then. Which rays interpolate and which carve
// near the sensor are the TSDF's rules (tsdf/scan_rays.hpp).

#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::mapping {

/// Every valid point of `scan` as a ray in the map frame, row by row.
tsdf::RayBatch scan_to_rays(const slam::Scan& scan, const slam::ScanPlacement& placement);

}  // namespace featsense::mapping
