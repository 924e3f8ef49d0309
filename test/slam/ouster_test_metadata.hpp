#pragma once
// Small Ouster metadata documents for the tests, in both JSON layouts of PACKET_FORMAT.md.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace featsense::test {

/// A made-up sensor in the flat layout: `beams` beams spread evenly from +15 to -15 degrees,
/// beam azimuths alternating +2 / -2 degrees, destaggering shifts alternating 3 / 0 columns,
/// the OS1's lidar_to_sensor_transform (x and y flipped, z lifted 36.18 mm).
inline nlohmann::json tiny_flat_metadata(const std::string& profile, int beams = 16,
                                         int columns = 64, int columns_per_packet = 16) {
  nlohmann::json doc;
  std::vector<double> altitude;
  std::vector<double> azimuth;
  std::vector<int> shift;
  for (int i = 0; i < beams; ++i) {
    altitude.push_back(beams > 1 ? 15.0 - 30.0 * i / (beams - 1) : 0.0);
    azimuth.push_back(i % 2 == 0 ? 2.0 : -2.0);
    shift.push_back(i % 2 == 0 ? 3 : 0);
  }
  doc["beam_altitude_angles"] = altitude;
  doc["beam_azimuth_angles"] = azimuth;
  doc["lidar_origin_to_beam_origin_mm"] = 15.806;
  doc["lidar_to_sensor_transform"] = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
  doc["lidar_mode"] = std::to_string(columns) + "x10";
  doc["prod_line"] = "OS-1-16";
  doc["data_format"] = {{"pixels_per_column", beams},
                        {"columns_per_packet", columns_per_packet},
                        {"columns_per_frame", columns},
                        {"pixel_shift_by_row", shift},
                        {"column_window", {0, columns - 1}}};
  if (!profile.empty()) doc["data_format"]["udp_profile_lidar"] = profile;
  return doc;
}

/// The same metadata in the newer nested layout (beam_intrinsics, lidar_intrinsics,
/// lidar_data_format, config_params, sensor_info).
inline nlohmann::json to_nested_layout(const nlohmann::json& flat) {
  nlohmann::json doc;
  const double n = flat["lidar_origin_to_beam_origin_mm"].get<double>();
  doc["beam_intrinsics"] = {
      {"beam_altitude_angles", flat["beam_altitude_angles"]},
      {"beam_azimuth_angles", flat["beam_azimuth_angles"]},
      {"lidar_origin_to_beam_origin_mm", n},
      {"beam_to_lidar_transform", {1, 0, 0, n, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  doc["lidar_intrinsics"] = {{"lidar_to_sensor_transform", flat["lidar_to_sensor_transform"]}};
  doc["lidar_data_format"] = flat["data_format"];
  doc["config_params"] = {{"lidar_mode", flat["lidar_mode"]}, {"udp_port_lidar", 7502}};
  if (flat["data_format"].contains("udp_profile_lidar")) {
    doc["config_params"]["udp_profile_lidar"] = flat["data_format"]["udp_profile_lidar"];
  }
  doc["sensor_info"] = {{"prod_line", flat["prod_line"]}};
  for (const char* key : {"prod_sn", "initialization_id"}) {
    if (flat.contains(key)) doc["sensor_info"][key] = flat[key];
  }
  return doc;
}

}  // namespace featsense::test
