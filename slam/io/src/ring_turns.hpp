#pragma once
// Where each ring begins in a cloud stored ring by ring (KITTI .bin, organized images row by
// row): the part of azimuth_times() that splits the file order into the rings' turns.

#include <cstddef>
#include <vector>

namespace featsense::slam {

/// The index of each ring's first return, after the first ring's (which begins the file).
/// `turned`: per return in file order, the clockwise angle turned since the seam, each step
/// from one return to the next taken the shorter way round (radians; about 2 pi per ring);
/// `elevation_rad`: per return, above the horizontal.
///
/// A ring begins near the point where the turn passes the next whole turn past the seam;
/// within 45 deg of the seam, where its first points and the last of the ring before can lie
/// at the same azimuths (beams' azimuth offsets, returns missing where the first ring
/// began), the change of elevation from one ring to the next tells where; where it cannot
/// (rings at the same elevation, too few points beside the seam), the seam does.
std::vector<size_t> ring_starts(const std::vector<double>& turned,
                                const std::vector<double>& elevation_rad);

}  // namespace featsense::slam
