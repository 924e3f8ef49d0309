#pragma once
/// Writes single scans to files that other tools open (`featsense convert`).

#include <stdexcept>
#include <string>

#include "featsense/slam/scan.hpp"

namespace featsense::slam {

/// Thrown by the writers below when the file cannot be written (missing folder, no
/// permission, disk full); the message names the path.
class WriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Binary PCD v0.7, organized (WIDTH = cols, HEIGHT = rows) with every cell, invalid ones as
/// NaN; fields x y z range t (time offset, s) ring, then every channel by name. Readable by
/// PCL and CloudCompare, and read back by this project as the same scan.
void write_scan_pcd(const Scan& scan, const std::string& path);
/// Binary little-endian PLY of the valid points with the same fields as the PCD.
void write_scan_ply(const Scan& scan, const std::string& path);
/// KITTI .bin: float32 x y z intensity of the valid points (intensity scaled to 0..1 by the
/// largest value of the channel, as KITTI's reflectance is), in firing order: column by
/// column from the one measured first, each from the highest beam down. The format has no
/// times; a reader takes them from the azimuth in that order.
void write_scan_kitti_bin(const Scan& scan, const std::string& path);

}  // namespace featsense::slam
