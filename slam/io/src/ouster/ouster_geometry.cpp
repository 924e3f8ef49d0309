#include "ouster/ouster_geometry.hpp"

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
  // Only the z offset of beam_to_lidar_transform enters PACKET_FORMAT.md's formula; its x
  // translation is n again.
  const double beam_z = metadata.beam_to_lidar[11] * kMmToM;
  const double w = static_cast<double>(columns_);

  // Trigonometry once per column and once per row; the sums of angles follow from those.
  std::vector<double> cos_e(static_cast<size_t>(columns_));
  std::vector<double> sin_e(static_cast<size_t>(columns_));
  for (int m = 0; m < columns_; ++m) {
    const double theta_e = 2.0 * M_PI * (1.0 - m / w);
    cos_e[static_cast<size_t>(m)] = std::cos(theta_e);
    sin_e[static_cast<size_t>(m)] = std::sin(theta_e);
  }
  for (int row = 0; row < rows; ++row) {
    const size_t r = static_cast<size_t>(row);
    const double theta_a = -2.0 * M_PI * metadata.beam_azimuth_deg[r] / 360.0;
    const double phi = 2.0 * M_PI * metadata.beam_altitude_deg[r] / 360.0;
    const double cos_a = std::cos(theta_a);
    const double sin_a = std::sin(theta_a);
    const double cos_phi = std::cos(phi);
    const double sin_phi = std::sin(phi);
    for (int m = 0; m < columns_; ++m) {
      const double ce = cos_e[static_cast<size_t>(m)];
      const double se = sin_e[static_cast<size_t>(m)];
      // The beam leaves its origin, n out along the encoder direction e, towards u:
      // p = (r - n) u + n e + z_beam = r u + (n e - n u + z_beam).
      const Eigen::Vector3d u((ce * cos_a - se * sin_a) * cos_phi,
                              (se * cos_a + ce * sin_a) * cos_phi, sin_phi);
      const Eigen::Vector3d beam_origin(n * ce, n * se, beam_z);
      const Eigen::Vector3d offset_lidar = beam_origin - n * u;
      const size_t i = index(row, m);
      directions_[i] = (lidar_to_sensor.linear() * u).cast<float>();
      offsets_[i] = (lidar_to_sensor * offset_lidar).cast<float>();
    }
  }
}

}  // namespace featsense::slam::detail
