#pragma once
/// The Velodyne sensors whose 1206-byte data packets the reader decodes, and what tells
/// them apart. Facts from the makers' user manuals (VLP-16 63-9243, VLP-32C 63-9325,
/// HDL-32E 63-9113, HDL-64E S3 63-HDL64ES3, VLS-128 63-9480): 12 blocks of 100 bytes (flag
/// u16, azimuth u16 in 0.01 deg, 32 x (distance u16, reflectivity u8)), a u32 time stamp in
/// microseconds past the hour, the return-mode byte (0x37 strongest, 0x38 last, 0x39 dual)
/// and the product-id byte.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace featsense::slam {

enum class VelodyneModel { kVlp16, kVlp32c, kHdl32e, kHdl64e, kVls128 };

inline constexpr size_t kVelodynePacketBytes = 1206;
inline constexpr size_t kVelodyneBlocks = 12;
inline constexpr size_t kVelodyneBlockBytes = 100;
inline constexpr size_t kVelodyneSlots = 32;  ///< returns per block
inline constexpr size_t kVelodyneReturnModeByte = 1204;
inline constexpr size_t kVelodyneProductIdByte = 1205;

/// The model of a product id (byte 1205): 0x21 HDL-32E, 0x22 VLP-16, 0x23 Puck LITE and
/// 0x24 Puck Hi-Res (VLP-16 packets), 0x28 VLP-32C, 0xA1 VLS-128. HDL-64E packets carry
/// no product id; nullopt for those and unknown values.
std::optional<VelodyneModel> velodyne_model_from_product_id(uint8_t id);

/// The product id a model's packets carry (the VLP-16's own, 0x22; nullopt for the
/// HDL-64E, whose packets carry none): velodyne_model_from_product_id's inverse.
std::optional<uint8_t> velodyne_product_id(VelodyneModel model);

/// The model of a sensor preset name (vlp16, vlp32c, hdl32, hdl64, vls128), or nullopt.
std::optional<VelodyneModel> velodyne_model_from_preset(const std::string& preset);

/// The preset of a model (config/presets/<name>.yaml) and its name for humans.
std::string velodyne_preset(VelodyneModel model);
std::string velodyne_name(VelodyneModel model);

/// Lasers of the model (16, 32, 32, 64, 128).
int velodyne_lasers(VelodyneModel model);

/// Metres per distance unit: 2 mm, but 4 mm on the VLP-32C and VLS-128.
double velodyne_distance_unit_m(VelodyneModel model);

}  // namespace featsense::slam
