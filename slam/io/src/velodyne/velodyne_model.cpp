#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {

std::optional<VelodyneModel> velodyne_model_from_product_id(uint8_t id) {
  switch (id) {
    case 0x21:
      return VelodyneModel::kHdl32e;
    case 0x22:
    case 0x23:
    case 0x24:
      return VelodyneModel::kVlp16;
    case 0x28:
      return VelodyneModel::kVlp32c;
    case 0xA1:
      return VelodyneModel::kVls128;
    default:
      return std::nullopt;
  }
}

std::optional<uint8_t> velodyne_product_id(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kHdl32e:
      return 0x21;
    case VelodyneModel::kVlp16:
      return 0x22;
    case VelodyneModel::kVlp32c:
      return 0x28;
    case VelodyneModel::kVls128:
      return 0xA1;
    case VelodyneModel::kHdl64e:
      break;
  }
  return std::nullopt;
}

std::optional<VelodyneModel> velodyne_model_from_preset(const std::string& preset) {
  if (preset == "vlp16") return VelodyneModel::kVlp16;
  if (preset == "vlp32c") return VelodyneModel::kVlp32c;
  if (preset == "hdl32") return VelodyneModel::kHdl32e;
  if (preset == "hdl64") return VelodyneModel::kHdl64e;
  if (preset == "vls128") return VelodyneModel::kVls128;
  return std::nullopt;
}

std::string velodyne_preset(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16:
      return "vlp16";
    case VelodyneModel::kVlp32c:
      return "vlp32c";
    case VelodyneModel::kHdl32e:
      return "hdl32";
    case VelodyneModel::kHdl64e:
      return "hdl64";
    case VelodyneModel::kVls128:
      return "vls128";
  }
  return "";
}

std::string velodyne_name(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16:
      return "VLP-16";
    case VelodyneModel::kVlp32c:
      return "VLP-32C";
    case VelodyneModel::kHdl32e:
      return "HDL-32E";
    case VelodyneModel::kHdl64e:
      return "HDL-64E";
    case VelodyneModel::kVls128:
      return "VLS-128";
  }
  return "";
}

int velodyne_lasers(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16:
      return 16;
    case VelodyneModel::kVlp32c:
    case VelodyneModel::kHdl32e:
      return 32;
    case VelodyneModel::kHdl64e:
      return 64;
    case VelodyneModel::kVls128:
      return 128;
  }
  return 0;
}

double velodyne_distance_unit_m(VelodyneModel model) {
  return model == VelodyneModel::kVlp32c || model == VelodyneModel::kVls128 ? 0.004 : 0.002;
}

}  // namespace featsense::slam
