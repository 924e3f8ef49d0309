#pragma once
// sequence.yaml: the index of a folder of scans written by `featsense simulate` (format in
// slam/io/src/cloud/SEQUENCE_FORMAT.md):
//
//   format: featsense-sequence
//   version: 1
//   sensor: os1-128              # a preset name, or a mapping in the preset format
//   rate_hz: 10                  # optional; the sensor's rate when absent
//   frames:
//     - {file: frame_000000.pcd, stamp_ns: 1700000000000000000}
//     - {file: frame_000001.pcd, stamp_ns: 1700000000100000000}

#include <cstdint>
#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"

namespace featsense::slam::cloud {

struct SequenceFrame {
  std::string file;  ///< relative to the folder holding sequence.yaml
  int64_t stamp_ns = 0;
};

struct SequenceFile {
  config::SensorModel sensor;
  bool sensor_is_preset = false;  ///< written as a preset name rather than inline
  double rate_hz = 10.0;
  std::vector<SequenceFrame> frames;
};

/// Parses sequence.yaml text; throws InputError naming `origin` and the key at fault.
SequenceFile parse_sequence_yaml(const std::string& text, const std::string& origin);

/// The sequence.yaml text for `sequence` (the sensor by name when sensor_is_preset, else
/// inline with every beam's elevation).
std::string format_sequence_yaml(const SequenceFile& sequence);

}  // namespace featsense::slam::cloud
