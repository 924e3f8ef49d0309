#include "featsense/slam/sim/simulation_writer.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/imu_csv.hpp"
#include "featsense/slam/io/scan_writers.hpp"
#include "featsense/slam/io/sequence_file.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"

namespace featsense::slam {
namespace {

std::ofstream open_for_writing(const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw WriteError(path + ": cannot open for writing");
  return out;
}

void close_checked(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw WriteError(path + ": writing failed (disk full?)");
}

/// Float32 values appended little-endian (the hosts this builds for are little-endian).
void put_floats(std::string& out, const Eigen::Vector3f& v) {
  out.append(reinterpret_cast<const char*>(v.data()), 3 * sizeof(float));
}

/// True when `sensor` is a preset unchanged (the rate aside, which sequence.yaml states), so
/// that sequence.yaml may name it; a changed sensor is written out in full.
bool is_unchanged_preset(const config::SensorModel& sensor) {
  try {
    const config::SensorModel p = config::sensor_preset(sensor.name);
    return p.beams == sensor.beams && p.columns == sensor.columns &&
           p.elevation_rad == sensor.elevation_rad &&
           p.azimuth_offset_rad == sensor.azimuth_offset_rad &&
           p.beam_origin_offset_m == sensor.beam_origin_offset_m &&
           p.min_range_m == sensor.min_range_m && p.max_range_m == sensor.max_range_m;
  } catch (const config::ConfigError&) {
    return false;
  }
}

std::filesystem::path created_folder(const std::string& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw WriteError(folder + ": cannot create the folder: " + ec.message());
  return folder;
}

mesh::TiledPointSettings truth_point_settings(double voxel_size_m) {
  mesh::TiledPointSettings settings;
  settings.voxel_size_m = voxel_size_m;
  // A tile is at most 65535 voxels wide (the writer's keys).
  settings.tile_size_m = std::min(settings.tile_size_m, 60000.0 * voxel_size_m);
  return settings;
}

}  // namespace

void write_mesh_ply(const mesh::TriangleMesh& mesh, const std::string& path) {
  std::ofstream out = open_for_writing(path);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << mesh.vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
      << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string data;
  data.reserve(mesh.vertices.size() * 12 + mesh.triangles.size() * 13);
  for (const Eigen::Vector3f& v : mesh.vertices) put_floats(data, v);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    data.push_back(3);
    data.append(reinterpret_cast<const char*>(t.data()), 3 * sizeof(int));
  }
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  close_checked(out, path);
}

SimulationWriter::SimulationWriter(std::string folder, config::SensorModel sensor,
                                   double voxel_size_m, bool write_frames)
    : folder_(std::move(folder)),
      sensor_(std::move(sensor)),
      write_frames_(write_frames),
      points_(created_folder(folder_) / "gt_points.ply", truth_point_settings(voxel_size_m)) {}

void SimulationWriter::add(const SimulatedFrame& frame, const Eigen::Isometry3d& T_map_sensor) {
  if (write_frames_) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06zu.pcd", files_.size());
    write_scan_pcd(frame.scan, (std::filesystem::path(folder_) / name).string());
    files_.push_back(name);
    stamps_ns_.push_back(frame.scan.stamp_ns);
    for (const ImuSample& sample : frame.scan.imu) {
      // A sample at the very instant where one sweep ends and the next begins may come with
      // both frames (their bounds are sums of floating-point seconds): written once.
      if (imu_written_ && sample.stamp_ns <= last_imu_stamp_ns_) continue;
      append_imu_csv_line(sample, &imu_csv_);
      imu_written_ = true;
      last_imu_stamp_ns_ = sample.stamp_ns;
    }
  }
  trajectory_.push_back(frame.scan.stamp_ns, T_map_sensor);
  for (const Eigen::Vector3f& p : frame.surface_points_m) points_.add(p);
}

void SimulationWriter::finish(const mesh::TriangleMesh& mesh) {
  const std::filesystem::path dir(folder_);
  write_tum(trajectory_, (dir / "gt_trajectory.tum").string());
  write_mesh_ply(mesh, (dir / "gt_mesh.ply").string());
  try {
    points_.finish();
  } catch (const mesh::MeshError& e) {
    throw WriteError(e.what());
  }
  if (!write_frames_) return;
  cloud::SequenceFile sequence;
  sequence.sensor = sensor_;
  sequence.sensor_is_preset = is_unchanged_preset(sensor_);
  sequence.rate_hz = sensor_.rate_hz;
  for (size_t i = 0; i < files_.size(); ++i) sequence.frames.push_back({files_[i], stamps_ns_[i]});
  const std::string yaml_path = (dir / "sequence.yaml").string();
  std::ofstream yaml = open_for_writing(yaml_path);
  yaml << cloud::format_sequence_yaml(sequence);
  close_checked(yaml, yaml_path);
  if (imu_csv_.empty()) return;
  const std::string imu_path = (dir / "imu.csv").string();
  std::ofstream imu = open_for_writing(imu_path);
  imu << kImuCsvHeader << '\n' << imu_csv_;
  close_checked(imu, imu_path);
}

}  // namespace featsense::slam
