#pragma once
/// The TSDF's rules for the rays of one organized scan (beams x columns): which rays may fill
/// the gap to the neighbouring beams (vertical interpolation, paper eqs. 7-8), and which of
/// them carve free space near the sensor (the lattice of sparse carving). Where the rays go
/// is the front end's answer; these rules only need the scan's own geometry.

#include <cstdint>
#include <vector>

namespace featsense::tsdf {

/// An organized scan in the sensor frame, row-major (row = beam, column = firing), as plain
/// arrays: `xyz_m` holds three floats per cell (metres), `valid` one byte per cell.
struct OrganizedScanView {
  int rows = 0;
  int cols = 0;
  const float* xyz_m = nullptr;
  const uint8_t* valid = nullptr;
};

/// Per cell, 1 where the ray may interpolate vertically, 0 where it must not. The band of
/// interpolation runs perpendicular to the ray towards the neighbouring beams: that fills
/// the gap between scan lines on a surface facing the sensor, but crosses a surface seen at a
/// grazing angle (the ground far away) and a depth edge, and gives cells on the far side the
/// wrong sign. So a ray whose beam above or below disagrees in range by more than a surface
/// facing the sensor at >= ~27 degrees explains (2 x range x the angle between the two
/// beams) does not interpolate. Invalid cells get 1 (they make no ray).
std::vector<uint8_t> vertical_interpolation_flags(const OrganizedScanView& scan);

/// The ray's place in the lattice of sparse carving (TsdfSettings::dense_range_m): the largest
/// L with both its beam and its column multiples of 2^L, at most kFullCarvingLevel.
uint8_t carving_level(int row, int col);

}  // namespace featsense::tsdf
