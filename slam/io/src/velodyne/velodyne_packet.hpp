#pragma once
/// Decoding one Velodyne data packet into returns with coordinates, laser and firing time.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {

/// One return of a packet.
struct VelodyneReturn {
  Eigen::Vector3f xyz;  ///< sensor frame, ROS axes (x forward, y left, z up), metres
  float distance_m = 0.0f;
  float time_offset_s = 0.0f;  ///< after the packet's first firing
  uint16_t laser = 0;          ///< laser number in the packet (calibration index)
  uint16_t block_azimuth = 0;  ///< the block's azimuth as the packet says, 0.01 deg
  /// Where the return's firing sequence began, 0.01 deg: the block's azimuth, or past it
  /// for the second of the VLP-16's two sequences in a block.
  float firing_azimuth = 0.0f;
  uint8_t reflectivity = 0;
  uint8_t block = 0;
  uint8_t slot = 0;
};

class VelodynePacketDecoder {
 public:
  /// `calibration` must hold one laser per laser of the model.
  VelodynePacketDecoder(VelodyneModel model, VelodyneCalibration calibration);

  /// Appends the returns of non-zero distance of one packet of kVelodynePacketBytes, in
  /// packet order (block, then slot). Blocks whose flag is not one of the model's are
  /// skipped and counted in bad_blocks().
  ///
  /// Each return's azimuth is its block's plus the turn since the firing began (the block's
  /// azimuth change, times the slot's firing time over the firing's duration), less the
  /// laser's rot_correction, rounded to the 0.01 deg of the packet's own azimuths.
  void decode(const uint8_t* packet, std::vector<VelodyneReturn>& out);

  /// True for packets in dual-return mode (byte 1204 = 0x39): blocks come in pairs of one
  /// firing.
  static bool dual_return(const uint8_t* packet);

  uint64_t bad_blocks() const { return bad_blocks_; }
  VelodyneModel model() const { return model_; }

 private:
  struct Laser {
    double cos_vert = 1.0;
    double sin_vert = 0.0;
    double rot_centideg = 0.0;
    double dist_correction_m = 0.0;
    double vert_offset_m = 0.0;
    double horiz_offset_m = 0.0;
  };
  /// Each block's azimuth change to the next firing (0.01 deg); also fills gap_shift_us_.
  std::array<double, kVelodyneBlocks> block_turns(const uint8_t* packet, bool dual);
  /// Laser number of a block's slot, or -1 for a block flag the model does not use.
  int laser_of(uint16_t flag, size_t slot) const;

  VelodyneModel model_;
  std::vector<Laser> lasers_;
  double distance_unit_m_;
  uint64_t bad_blocks_ = 0;
  double last_turn_ = 0.0;  ///< azimuth change of the last regular firing, 0.01 deg
  /// Per block of the current packet: time of the turn the sensor skipped before it, us.
  std::array<double, kVelodyneBlocks> gap_shift_us_{};
};

}  // namespace featsense::slam
