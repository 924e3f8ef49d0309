// Fuzzes the Velodyne decoding: packets of every model (the first byte of the input picks
// the model and the cut angle), decoded and assembled into scans, over arbitrary bytes cut
// into 1206-byte packets. A sanitizer report, an exception, or a hang is a bug.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_scan_assembler.hpp"

using namespace featsense::slam;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const VelodyneModel models[] = {VelodyneModel::kVlp16, VelodyneModel::kVlp32c,
                                  VelodyneModel::kHdl32e, VelodyneModel::kHdl64e,
                                  VelodyneModel::kVls128};
  const VelodyneModel model = models[data[0] % 5];
  VelodyneCalibration calibration;
  if (model == VelodyneModel::kHdl64e) {
    // No built-in table: a flat one with offsets, so that their code runs too.
    for (int laser = 0; laser < 64; ++laser) {
      VelodyneLaser l;
      l.vert_rad = -0.4 + 0.01 * laser;
      l.rot_rad = 0.001 * laser;
      l.dist_correction_m = 1.0;
      l.vert_offset_m = 0.2;
      l.horiz_offset_m = 0.03;
      calibration.lasers.push_back(l);
    }
  } else {
    calibration = builtin_velodyne_calibration(model);
  }
  VelodyneScanSettings settings;
  settings.cut_angle_rad = (data[0] / 5) * 0.1;
  settings.columns = 64;  // small scans: the cut and the cells are what is tested
  VelodyneScanAssembler assembler(VelodynePacketDecoder(model, calibration), calibration, settings);
  std::vector<uint8_t> packet(kVelodynePacketBytes, 0);
  int64_t stamp_ns = 1000000000;
  for (size_t at = 1; at < size; at += kVelodynePacketBytes) {
    const size_t n = std::min(kVelodynePacketBytes, size - at);
    std::copy(data + at, data + at + n, packet.begin());
    std::fill(packet.begin() + static_cast<std::ptrdiff_t>(n), packet.end(), 0);
    assembler.add_packet(packet.data(), stamp_ns);
    stamp_ns += 1000000;
    while (assembler.take()) {
    }
  }
  assembler.flush();
  while (assembler.take()) {
  }
  return 0;
}
