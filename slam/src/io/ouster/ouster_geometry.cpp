#include "io/ouster/ouster_geometry.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace featsense::slam::detail {
namespace {

constexpr double kMmToM = 1.0e-3;

/// The rotation and translation (metres) of a row-major 4x4 whose translation is in mm.
Eigen::Isometry3d to_isometry(const std::array<double, 16>& m) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) t.linear()(r, c) = m[static_cast<size_t>(4 * r + c)];
    t.translation()[r] = m[static_cast<size_t>(4 * r + 3)] * kMmToM;
  }
  return t;
}

}  // namespace

OusterPixelGeometry::OusterPixelGeometry(const OusterMetadata& metadata)
    : columns_(metadata.columns_per_frame) {
  const int rows = metadata.pixels_per_column;
  const size_t size = static_cast<size_t>(rows) * static_cast<size_t>(columns_);
  directions_.resize(size);
  offsets_.resize(size);

  const Eigen::Isometry3d lidar_to_sensor = to_isometry(metadata.lidar_to_sensor);
  const double n = metadata.lidar_origin_to_beam_origin_mm * kMmToM;
  // Only the z offset of beam_to_lidar_transform enters FORMATS.md's formula; its x
  // translation is n again.
  const double beam_z = metadata.beam_to_lidar[11] * kMmToM;
  const double w = static_cast<double>(columns_);

  for (int row = 0; row < rows; ++row) {
    const double theta_a =
        -2.0 * M_PI * metadata.beam_azimuth_deg[static_cast<size_t>(row)] / 360.0;
    const double phi = 2.0 * M_PI * metadata.beam_altitude_deg[static_cast<size_t>(row)] / 360.0;
    for (int m = 0; m < columns_; ++m) {
      const double theta_e = 2.0 * M_PI * (1.0 - m / w);
      // The beam leaves its origin, n out along the encoder direction, towards u:
      // p = (r - n) u + n e + z_beam = r u + (n e - n u + z_beam).
      const Eigen::Vector3d u(std::cos(theta_e + theta_a) * std::cos(phi),
                              std::sin(theta_e + theta_a) * std::cos(phi), std::sin(phi));
      const Eigen::Vector3d beam_origin(n * std::cos(theta_e), n * std::sin(theta_e), beam_z);
      const Eigen::Vector3d offset_lidar = beam_origin - n * u;
      const size_t i = index(row, m);
      directions_[i] = (lidar_to_sensor.linear() * u).cast<float>();
      offsets_[i] = (lidar_to_sensor * offset_lidar).cast<float>();
    }
  }
}

}  // namespace featsense::slam::detail
