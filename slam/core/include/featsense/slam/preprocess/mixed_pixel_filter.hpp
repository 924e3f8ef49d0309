#pragma once
/// Mixed pixels (veil points): where a beam's footprint straddles a foreground edge and a
/// surface behind it, the sensor merges both echoes into one range in between, a point in
/// mid-air that a map would turn into a phantom surface trailing every edge.
///
/// Along a row (one beam, neighbouring azimuths) such a point sits between two neighbours
/// whose ranges jump, with each neighbour on a locally even surface of its own:
///   |r[c-1] - r[c+1]| = jump > min_jump_m,
///   |r[c-2] - r[c-1]| and |r[c+2] - r[c+1]| below `flat_fraction` * jump (two separate
///     surfaces, not one surface seen at a grazing angle, whose range changes evenly),
///   r[c] between r[c-1] and r[c+1] and farther than max(margin_m, margin_fraction * jump)
///     from both (on neither surface).
/// Such points are dropped. Points right at an edge stay, so edges keep their shape.

#include <cstddef>

#include "featsense/slam/scan.hpp"

namespace featsense::slam {

struct MixedPixelSettings {
  double min_jump_m = 0.3;
  double flat_fraction = 0.25;
  double margin_m = 0.1;
  double margin_fraction = 0.1;
};

/// Invalidates the mixed pixels of `scan`; returns how many.
size_t drop_mixed_pixels(Scan& scan, const MixedPixelSettings& settings = {});

}  // namespace featsense::slam
