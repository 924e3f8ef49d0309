#include "featsense/slam/sim/lidar_simulator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace featsense::slam {
namespace {

// What each hashed draw of a cell is for (so that switching one effect off leaves the
// draws of the others unchanged).
enum Purpose : uint32_t { kNoise = 1, kDropout = 2, kMixedChoice = 3, kMixedFraction = 4 };

}  // namespace

void beam_geometry(const config::SensorModel& sensor, int row, int col, Eigen::Vector3d* origin,
                   Eigen::Vector3d* direction) {
  const double encoder = -2.0 * M_PI * col / sensor.columns;  // clockwise from +x
  const double azimuth = encoder + sensor.azimuth_offset_rad[static_cast<size_t>(row)];
  const double elevation = sensor.elevation_rad[static_cast<size_t>(row)];
  *direction = Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                               std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  *origin = sensor.beam_origin_offset_m * Eigen::Vector3d(std::cos(encoder), std::sin(encoder), 0);
}

LidarSimulator::LidarSimulator(const mesh::TriangleMesh& mesh, const RayCaster& caster,
                               const PoseCurve& trajectory, SimulationSettings settings)
    : mesh_(mesh), caster_(caster), trajectory_(trajectory), settings_(std::move(settings)) {
  settings_.sensor.validate();
  const config::SensorModel& s = settings_.sensor;
  const size_t cells = static_cast<size_t>(s.beams) * static_cast<size_t>(s.columns);
  local_origin_.resize(cells);
  local_direction_.resize(cells);
  for (int row = 0; row < s.beams; ++row) {
    for (int col = 0; col < s.columns; ++col) {
      const size_t i =
          static_cast<size_t>(row) * static_cast<size_t>(s.columns) + static_cast<size_t>(col);
      beam_geometry(s, row, col, &local_origin_[i], &local_direction_[i]);
    }
  }
}

uint64_t LidarSimulator::frames_available() const {
  // A frame needs its last column's time; a microsecond of slack absorbs rounding.
  const double frames = trajectory_.duration_s() * settings_.sensor.rate_hz + 1e-6;
  return frames < 1.0 ? 0 : static_cast<uint64_t>(std::floor(frames));
}

SimulatedFrame LidarSimulator::simulate(uint64_t index) const {
  const config::SensorModel& s = settings_.sensor;
  const MeasurementSettings& m = settings_.measurement;
  const double period_s = 1.0 / s.rate_hz;
  const size_t rows = static_cast<size_t>(s.beams);
  const size_t cols = static_cast<size_t>(s.columns);
  SimulatedFrame frame;
  frame.start_s = static_cast<double>(index) * period_s;
  Scan& scan = frame.scan;
  scan = Scan::allocate(s.beams, s.columns);
  scan.sequence = index;
  scan.stamp_ns =
      settings_.start_stamp_ns + static_cast<int64_t>(std::llround(frame.start_s * 1e9));
  scan.imu = simulate_imu(trajectory_, settings_.imu, m.seed, frame.start_s,
                          frame.start_s + period_s, settings_.start_stamp_ns);

  // Rays in the map frame, each column from the pose at its own firing time.
  std::vector<Ray> rays(rows * cols);
  const std::vector<Eigen::Vector3d>& local_origin = local_origin_;
  const std::vector<Eigen::Vector3d>& local_direction = local_direction_;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, cols, 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t col = range.begin(); col != range.end(); ++col) {
          const Eigen::Isometry3d T =
              trajectory_.pose(frame.start_s + period_s * static_cast<double>(col) / s.columns);
          for (size_t row = 0; row < rows; ++row) {
            const size_t i = row * cols + col;
            rays[i].origin = (T * local_origin[i]).cast<float>();
            rays[i].direction = (T.linear() * local_direction[i]).cast<float>();
            rays[i].max_distance_m = static_cast<float>(s.max_range_m - s.beam_origin_offset_m);
          }
        }
      });
  std::vector<RayHit> hits;
  caster_.intersect(rays, &hits);

  // Geometric range from the lidar origin (Ouster: beam origin offset included).
  std::vector<double> geometric(rows * cols, 0.0);
  for (size_t i = 0; i < hits.size(); ++i) {
    if (hits[i].hit()) geometric[i] = hits[i].distance_m + s.beam_origin_offset_m;
  }

  scan.add_channel("reflectivity");
  scan.add_channel("intensity");  // may move the first channel: take references after both
  ScanChannel& reflectivity = *scan.channel("reflectivity");
  ScanChannel& intensity = *scan.channel("intensity");
  // Rows in parallel: every draw is keyed by its cell, so the order does not matter.
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, rows, 1), [&](const tbb::blocked_range<size_t>& row_range) {
        for (size_t row = row_range.begin(); row != row_range.end(); ++row) {
          for (size_t col = 0; col < cols; ++col) {
            const size_t i = row * cols + col;
            const RayHit& hit = hits[i];
            if (!hit.hit()) continue;  // nothing within max range
            HitGeometry g;
            g.range_m = geometric[i];
            if (g.range_m < s.min_range_m || g.range_m > s.max_range_m) continue;
            g.cos_incidence = std::abs(static_cast<double>(hit.normal.dot(rays[i].direction)));
            g.reflectance = mesh_.reflectance(static_cast<size_t>(hit.triangle));
            g.max_range_m = s.max_range_m;
            const uint32_t r32 = static_cast<uint32_t>(row);
            const uint32_t c32 = static_cast<uint32_t>(col);
            if (m.dropouts && drops_out(g, m, hashed_uniform(m.seed, index, r32, c32, kDropout)))
              continue;
            double range = g.range_m;
            if (m.mixed_pixels) {
              // The beam's footprint straddles this surface and one behind it in a neighbouring
              // column: the echo merges both, at a range in between. A surface behind is one
              // off this triangle's plane (a wall seen at a grazing angle jumps in range too,
              // but it is one surface).
              double behind = 0.0;
              const Eigen::Vector3f here = rays[i].origin + hit.distance_m * rays[i].direction;
              for (size_t n : {(col + cols - 1) % cols, (col + 1) % cols}) {
                const size_t j = row * cols + n;
                const double other = geometric[j];
                if (!(other - range > m.mixed_min_jump_m)) continue;
                const Eigen::Vector3f there =
                    rays[j].origin + hits[j].distance_m * rays[j].direction;
                if (std::abs(hit.normal.dot(there - here)) > 0.5 * m.mixed_min_jump_m)
                  behind = std::max(behind, other);
              }
              if (behind > 0.0 &&
                  hashed_uniform(m.seed, index, r32, c32, kMixedChoice) < m.mixed_probability) {
                range += hashed_uniform(m.seed, index, r32, c32, kMixedFraction) * (behind - range);
              }
            }
            if (m.range_noise) {
              const double z =
                  std::clamp(hashed_normal(m.seed, index, r32, c32, kNoise), -3.0, 3.0);
              range += z * range_sigma_m(g, m);
            }
            const Eigen::Vector3d p =
                local_origin[i] + (range - s.beam_origin_offset_m) * local_direction[i];
            scan.xyz[i] = p.cast<float>();
            scan.range_m[i] = static_cast<float>(range);
            scan.time_offset_s[i] =
                static_cast<float>(period_s * static_cast<double>(col) / s.columns);
            scan.valid[i] = 1;
            reflectivity.values[i] = static_cast<float>(100.0 * g.reflectance);
            intensity.values[i] = m.intensity ? intensity_of(g) : reflectivity.values[i];
          }
        }
      });
  for (size_t i = 0; i < hits.size(); ++i) {
    if (scan.valid[i])
      frame.surface_points_m.push_back(rays[i].origin + hits[i].distance_m * rays[i].direction);
  }
  return frame;
}

void check_trajectory_inside(const PoseCurve& trajectory, const mesh::TriangleMesh& mesh,
                             double end_s, double step_s, double margin_m) {
  Eigen::Vector3f lo, hi;
  mesh.bounds(&lo, &hi);
  const Eigen::Vector3d lo_m = lo.cast<double>() - Eigen::Vector3d::Constant(margin_m);
  const Eigen::Vector3d hi_m = hi.cast<double>() + Eigen::Vector3d::Constant(margin_m);
  const size_t steps = static_cast<size_t>(std::ceil(end_s / step_s));
  for (size_t k = 0; k <= steps; ++k) {
    const double t = std::min(static_cast<double>(k) * step_s, end_s);
    const Eigen::Vector3d p = trajectory.pose(t).translation();
    if ((p.array() < lo_m.array()).any() || (p.array() > hi_m.array()).any()) {
      char message[320];
      std::snprintf(message, sizeof message,
                    "the path leaves the scene at t = %.3f s: sensor at (%.2f, %.2f, %.2f) m, "
                    "scene bounds (%.2f, %.2f, %.2f) to (%.2f, %.2f, %.2f) m",
                    t, p.x(), p.y(), p.z(), lo_m.x(), lo_m.y(), lo_m.z(), hi_m.x(), hi_m.y(),
                    hi_m.z());
      throw std::invalid_argument(message);
    }
  }
}

}  // namespace featsense::slam
