#include "localization_files.hpp"

#include <Eigen/Geometry>

#include <cstdio>
#include <stdexcept>

#include "featsense/slam/trajectory/trajectory_io.hpp"

namespace featsense::app {
namespace {

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw std::runtime_error("cannot write " + path.string());
  return file;
}

/// The scan's line of localization.csv.
std::string csv_line(const mapping::LocalizedScan& scan) {
  char text[400];
  const double t = 1e-9 * static_cast<double>(scan.stamp_ns);
  std::string line;
  if (scan.T_map_sensor) {
    const Eigen::Vector3d p = scan.T_map_sensor->translation();
    const Eigen::Quaterniond q(scan.T_map_sensor->rotation());
    std::snprintf(text, sizeof text, "%.9f,%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,", t,
                  mapping::to_string(scan.status), p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
  } else {
    std::snprintf(text, sizeof text, "%.9f,%s,,,,,,,,", t, mapping::to_string(scan.status));
  }
  line += text;
  if (scan.registered) {
    std::snprintf(text, sizeof text, "%.6f,%.4f,%.4f,%.6f,%.4f,%.6f,%.4f,", scan.fitness_m,
                  scan.inlier_fraction, scan.coverage, scan.position_sigma_m,
                  scan.rotation_sigma_deg, scan.surface_position_m, scan.surface_rotation_deg);
    line += text;
  } else {
    line += ",,,,,,,";
  }
  std::snprintf(text, sizeof text, "%.2f\n", scan.ms);
  return line + text;
}

}  // namespace

LocalizationFiles::LocalizationFiles(const std::filesystem::path& folder)
    : tum_path_(folder / "trajectory.tum"),
      csv_path_(folder / "localization.csv"),
      tum_(open_for_writing(tum_path_)),
      csv_(open_for_writing(csv_path_)) {
  tum_ << slam::kTumHeader << std::flush;
  csv_ << "stamp_s,status,x,y,z,qx,qy,qz,qw,fitness_m,inlier_fraction,coverage,position_sigma_m,"
          "rotation_sigma_deg,surface_position_m,surface_rotation_deg,ms\n"
       << std::flush;
  if (!tum_) throw std::runtime_error("cannot write " + tum_path_.string());
  if (!csv_) throw std::runtime_error("cannot write " + csv_path_.string());
}

void LocalizationFiles::add(const mapping::LocalizedScan& scan) {
  csv_ << csv_line(scan) << std::flush;
  if (!csv_) throw std::runtime_error("cannot write " + csv_path_.string());
  if (!scan.T_map_sensor) return;
  tum_ << slam::tum_line(scan.stamp_ns, *scan.T_map_sensor) << std::flush;
  if (!tum_) throw std::runtime_error("cannot write " + tum_path_.string());
}

}  // namespace featsense::app
