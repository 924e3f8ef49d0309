// decode_kitti_bin(): KITTI Velodyne scans, float32 x y z reflectance per point, no header.

#include "cloud/cloud_limits.hpp"
#include "cloud/scalar_type.hpp"
#include "featsense/slam/io/cloud_files.hpp"

namespace featsense::slam {

DecodedCloud decode_kitti_bin(std::string_view bytes, const std::string& origin) {
  constexpr size_t kPointBytes = 16;
  if (bytes.size() % kPointBytes != 0) {
    throw InputError(origin + ": " + std::to_string(bytes.size()) +
                     " bytes is not a multiple of 16 (float32 x y z reflectance per point)");
  }
  const size_t points = bytes.size() / kPointBytes;
  if (points > cloud::kMaxPoints) throw InputError(origin + ": too many points for one scan");
  DecodedCloud decoded;
  decoded.format = "kitti-bin";
  decoded.width = static_cast<int>(points);
  decoded.fields = {"x", "y", "z", "reflectance"};
  PointCloud& cloud = decoded.cloud;
  cloud.xyz.resize(points);
  ScanChannel intensity{"intensity", std::vector<float>(points)};
  const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
  auto load = [](const uint8_t* at) {
    return static_cast<float>(
        cloud::load_scalar(at, cloud::ScalarType::kF32, cloud::ByteOrder::kLittle));
  };
  for (size_t i = 0; i < points; ++i, p += kPointBytes) {
    cloud.xyz[i] = Eigen::Vector3f(load(p), load(p + 4), load(p + 8));
    intensity.values[i] = load(p + 12);
  }
  cloud.channels.push_back(std::move(intensity));
  return decoded;
}

}  // namespace featsense::slam
