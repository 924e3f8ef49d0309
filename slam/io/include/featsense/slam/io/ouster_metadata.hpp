#pragma once
/// The sensor metadata JSON that Ouster sensors publish (both the older flat layout and the
/// newer nested one; slam/io/src/ouster/PACKET_FORMAT.md lists the keys).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"

namespace featsense::slam {

enum class OusterProfile { kLegacy, kRng19Rfl8Sig16Nir16, kRng15Rfl8Nir8 };

struct OusterMetadata {
  std::string prod_line;   ///< e.g. "OS-1-128"
  std::string lidar_mode;  ///< e.g. "1024x10"
  OusterProfile profile = OusterProfile::kLegacy;
  int pixels_per_column = 0;
  int columns_per_packet = 0;
  int columns_per_frame = 0;
  std::array<int, 2> column_window = {0, 0};  ///< first and last lit measurement id
  std::vector<int> pixel_shift_by_row;        ///< destaggering shift per row
  std::vector<double> beam_altitude_deg;      ///< per row
  std::vector<double> beam_azimuth_deg;       ///< per row
  double lidar_origin_to_beam_origin_mm = 0.0;
  std::array<double, 16> beam_to_lidar = {};    ///< row-major 4x4, translation in mm
  std::array<double, 16> lidar_to_sensor = {};  ///< row-major 4x4, translation in mm
  /// Row-major 4x4, translation in mm; identity where the metadata has none.
  std::array<double, 16> imu_to_sensor = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  /// Who the metadata is of, where it says (the packets' headers carry both, not the legacy
  /// format's): the unit's serial number, and the id of its last initialization.
  std::optional<uint64_t> serial;
  std::optional<uint64_t> initialization_id;
  int udp_port_lidar = 7502;  ///< the sensor's defaults where the metadata names none
  int udp_port_imu = 7503;
  double rate_hz = 10.0;  ///< from lidar_mode

  /// Bytes of one lidar packet of this profile and geometry.
  size_t packet_size() const;
  /// The sensor model of this unit (per-beam angles from the metadata).
  config::SensorModel sensor_model() const;
};

/// Parses metadata JSON text; `origin` names the file in errors. Throws InputError naming
/// the missing or malformed key.
OusterMetadata parse_ouster_metadata(const std::string& json_text, const std::string& origin);

std::string to_string(OusterProfile profile);

}  // namespace featsense::slam
