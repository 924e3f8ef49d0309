#pragma once
/// When each return of a Velodyne packet was fired, from the firing timing of the makers'
/// user manuals, and how far its azimuth lies past its block's.

#include <cstddef>

#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {

/// The firing of one slot of one block.
struct VelodyneFiring {
  double time_us = 0.0;  ///< after the packet's first firing
  /// Fraction of the block's azimuth change that the laser fires after the block's azimuth.
  double azimuth_fraction = 0.0;
  /// The same for the start of the laser's firing sequence (one column of a scan): 0, but
  /// 0.5 for the VLP-16's second sequence in a block.
  double sequence_fraction = 0.0;
  /// Blocks to the next firing of the same return (for the azimuth change): 1, 2 in dual
  /// mode, 4 on the VLS-128 (one block per bank of 32 lasers).
  size_t next_block = 1;
};

/// Timing (manuals): VLP-16 fires one laser every 2.304 us and repeats every 55.296 us, two
/// firing sequences per block; the VLP-32C fires its lasers in pairs 2.304 us apart, one
/// 55.296 us sequence per block; the HDL-32E fires a laser every 1.152 us, 46.08 us per
/// block; the VLS-128 fires groups of 8 lasers 2.665 us apart, 53.3 us per sequence of four
/// blocks. HDL-64E returns get the packet's time (its timing is not modelled). In dual
/// mode two blocks hold the two returns of one firing.
VelodyneFiring velodyne_firing(VelodyneModel model, size_t block, size_t slot, bool dual);

}  // namespace featsense::slam
