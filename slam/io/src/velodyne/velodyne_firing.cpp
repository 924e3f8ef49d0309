#include "velodyne/velodyne_firing.hpp"

namespace featsense::slam {

VelodyneFiring velodyne_firing(VelodyneModel model, size_t block, size_t slot, bool dual) {
  VelodyneFiring firing;
  const size_t step = dual ? 2 : 1;
  const double firing_index = static_cast<double>(block / step);
  firing.next_block = step;
  switch (model) {
    case VelodyneModel::kVlp16: {
      constexpr double kLaserUs = 2.304;
      constexpr double kSequenceUs = 55.296;
      const double sequence = static_cast<double>(slot / 16);
      const double in_sequence = static_cast<double>(slot % 16) * kLaserUs;
      firing.time_us = (2.0 * firing_index + sequence) * kSequenceUs + in_sequence;
      firing.azimuth_fraction = (sequence * kSequenceUs + in_sequence) / (2.0 * kSequenceUs);
      firing.sequence_fraction = sequence / 2.0;
      break;
    }
    case VelodyneModel::kVlp32c: {
      constexpr double kPairUs = 2.304;
      constexpr double kSequenceUs = 55.296;
      firing.time_us = firing_index * kSequenceUs + static_cast<double>(slot / 2) * kPairUs;
      // The azimuth advances by the slot's index times 2.304 us, as the reference decoder
      // (tier4/nebula) computes it and as the expected clouds of the tests were made; the
      // pairs' timing would give half of that. Kept so that both decoders agree.
      firing.azimuth_fraction = static_cast<double>(slot) * kPairUs / kSequenceUs;
      break;
    }
    case VelodyneModel::kHdl32e: {
      constexpr double kLaserUs = 1.152;
      constexpr double kBlockUs = 46.08;
      firing.time_us = firing_index * kBlockUs + static_cast<double>(slot) * kLaserUs;
      firing.azimuth_fraction = static_cast<double>(slot) * kLaserUs / kBlockUs;
      break;
    }
    case VelodyneModel::kVls128: {
      constexpr double kGroupUs = 2.665;
      constexpr double kSequenceUs = 53.3;
      const size_t bank = block % 4;
      const double group = static_cast<double>((bank * 32 + slot) / 8);
      firing.time_us = static_cast<double>(block / 4) * kSequenceUs + group * kGroupUs;
      firing.azimuth_fraction = group * kGroupUs / kSequenceUs;
      firing.next_block = 4;
      break;
    }
    case VelodyneModel::kHdl64e:
      firing.next_block = 2;  // upper and lower block of one firing share the azimuth
      break;
  }
  return firing;
}

}  // namespace featsense::slam
