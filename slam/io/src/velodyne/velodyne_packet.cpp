#include "velodyne/velodyne_packet.hpp"

#include <array>
#include <cmath>

#include "velodyne/velodyne_firing.hpp"

namespace featsense::slam {
namespace {

constexpr double kFullTurnCentideg = 36000.0;
/// A larger change between two firings is no turn but a gap (a sensor that fires over a
/// sector only); the previous change stands in for it.
constexpr int kMaxTurnCentideg = 1000;

/// Block flags (the bytes FF EE, FF DD, FF CC, FF BB read as little-endian u16): the bank of
/// 32 lasers a block belongs to.
constexpr uint16_t kBankFlags[4] = {0xEEFF, 0xDDFF, 0xCCFF, 0xBBFF};

uint16_t u16_at(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }

}  // namespace

VelodynePacketDecoder::VelodynePacketDecoder(VelodyneModel model, VelodyneCalibration calibration)
    : model_(model), distance_unit_m_(velodyne_distance_unit_m(model)) {
  for (const VelodyneLaser& laser : calibration.lasers) {
    Laser out;
    out.cos_vert = std::cos(laser.vert_rad);
    out.sin_vert = std::sin(laser.vert_rad);
    out.rot_centideg = laser.rot_rad * 18000.0 / M_PI;
    out.dist_correction_m = laser.dist_correction_m;
    out.vert_offset_m = laser.vert_offset_m;
    out.horiz_offset_m = laser.horiz_offset_m;
    lasers_.push_back(out);
  }
}

bool VelodynePacketDecoder::dual_return(const uint8_t* packet) {
  return packet[kVelodyneReturnModeByte] == 0x39;
}

int VelodynePacketDecoder::laser_of(uint16_t flag, size_t slot) const {
  const int banks = model_ == VelodyneModel::kVls128 ? 4 : model_ == VelodyneModel::kHdl64e ? 2 : 1;
  for (int bank = 0; bank < banks; ++bank) {
    if (flag != kBankFlags[bank]) continue;
    if (model_ == VelodyneModel::kVlp16) return static_cast<int>(slot % 16);
    return bank * 32 + static_cast<int>(slot);
  }
  return -1;
}

std::array<double, kVelodyneBlocks> VelodynePacketDecoder::block_turns(const uint8_t* packet,
                                                                       bool dual) {
  std::array<double, kVelodyneBlocks> turns{};
  std::array<double, kVelodyneBlocks> shifts{};
  for (size_t block = 0; block < kVelodyneBlocks; ++block) {
    const uint16_t azimuth = u16_at(packet + block * kVelodyneBlockBytes + 2);
    const size_t next = block + velodyne_firing(model_, block, 0, dual).next_block;
    double turn = last_turn_;
    if (next < kVelodyneBlocks) {
      const uint16_t next_azimuth = u16_at(packet + next * kVelodyneBlockBytes + 2);
      const int change = (next_azimuth + 36000 - azimuth) % 36000;
      if (change <= kMaxTurnCentideg) {
        turn = change;
        last_turn_ = change;
      } else if (last_turn_ > 0.0 && next_azimuth < kFullTurnCentideg) {
        // A sensor that fires over a sector only skips the rest of the turn within a
        // packet: the firings after the gap came that much later.
        const double firing_us = velodyne_firing(model_, next, 0, dual).time_us -
                                 velodyne_firing(model_, block, 0, dual).time_us;
        const double gap_us = (change / last_turn_ - 1.0) * firing_us;
        for (size_t later = next; later < kVelodyneBlocks; ++later) shifts[later] += gap_us;
      }
    } else if (model_ == VelodyneModel::kVlp32c) {
      turn = 0.0;  // as the reference decoder does for the last firing (velodyne_firing.hpp)
    }
    turns[block] = turn;
  }
  gap_shift_us_ = shifts;
  return turns;
}

void VelodynePacketDecoder::decode(const uint8_t* packet, std::vector<VelodyneReturn>& out) {
  const bool dual = dual_return(packet);
  const std::array<double, kVelodyneBlocks> turns = block_turns(packet, dual);
  for (size_t block = 0; block < kVelodyneBlocks; ++block) {
    const uint8_t* data = packet + block * kVelodyneBlockBytes;
    const uint16_t flag = u16_at(data);
    const uint16_t azimuth = u16_at(data + 2);
    if (laser_of(flag, 0) < 0 || azimuth >= kFullTurnCentideg) {
      ++bad_blocks_;
      continue;
    }
    const double turn = turns[block];
    for (size_t slot = 0; slot < kVelodyneSlots; ++slot) {
      const uint8_t* ret = data + 4 + slot * 3;
      const uint16_t raw = u16_at(ret);
      if (raw == 0) continue;
      const int laser_index = laser_of(flag, slot);
      if (laser_index < 0 || static_cast<size_t>(laser_index) >= lasers_.size()) continue;
      const Laser& laser = lasers_[static_cast<size_t>(laser_index)];
      const VelodyneFiring firing = velodyne_firing(model_, block, slot, dual);
      double corrected = azimuth + turn * firing.azimuth_fraction - laser.rot_centideg;
      corrected = std::fmod(corrected, kFullTurnCentideg);
      if (corrected < 0.0) corrected += kFullTurnCentideg;
      corrected = std::round(corrected);
      const double a = corrected * M_PI / 18000.0;
      const double distance = raw * distance_unit_m_ + laser.dist_correction_m;
      // The manuals' geometry, in Velodyne's axes (y forward, x right), then ROS axes.
      const double xy = distance * laser.cos_vert - laser.vert_offset_m * laser.sin_vert;
      const double x_velodyne = xy * std::sin(a) - laser.horiz_offset_m * std::cos(a);
      const double y_velodyne = xy * std::cos(a) + laser.horiz_offset_m * std::sin(a);
      const double z = distance * laser.sin_vert + laser.vert_offset_m * laser.cos_vert;
      VelodyneReturn r;
      r.xyz = Eigen::Vector3f(static_cast<float>(y_velodyne), static_cast<float>(-x_velodyne),
                              static_cast<float>(z));
      r.distance_m = static_cast<float>(distance);
      r.time_offset_s = static_cast<float>((firing.time_us + gap_shift_us_[block]) * 1e-6);
      r.laser = static_cast<uint16_t>(laser_index);
      r.block_azimuth = azimuth;
      r.firing_azimuth =
          static_cast<float>(std::fmod(azimuth + turn * firing.sequence_fraction, 36000.0));
      r.reflectivity = ret[2];
      r.block = static_cast<uint8_t>(block);
      r.slot = static_cast<uint8_t>(slot);
      out.push_back(r);
    }
  }
}

}  // namespace featsense::slam
