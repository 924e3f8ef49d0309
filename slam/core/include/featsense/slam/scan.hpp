#pragma once
/// The organized scan every reader yields and every consumer (features, TSDF) reads.

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam {

/// A per-point channel of a scan by name: "intensity", "reflectivity", "signal", "nir",
/// "ambient", ... (values as the sensor reports them, unscaled).
struct ScanChannel {
  std::string name;
  std::vector<float> values;  ///< rows * cols, row-major like the scan
};

/// One revolution of a spinning LiDAR as an organized range image of rows x cols.
///
/// Layout: index = row * cols + col. Row 0 is the highest beam (largest elevation), rows go
/// down. Columns follow the sensor's firing order (clockwise seen from above, as Ouster and
/// Velodyne sensors spin), so time grows with the column from the one where the sweep began,
/// round past the last column to the first. Unorganized input is organized into this layout
/// by ring or elevation (organize.hpp).
///
/// Times: stamp_ns is the scan's reference instant and time_offset_s counts from it. Readers
/// make it the instant the sweep began (offsets >= 0), except where a file's own time field
/// counts from another instant (kept as it is), and in KITTI sequences stamped by times.txt:
/// there it is the instant the laser faced +x, mid-sweep, and offsets run from about minus to
/// plus half a revolution (slam/io azimuth_times.hpp, SweepReference). Consumers take
/// negative offsets as times before the stamp.
///
/// Invalid cells (no return, NaN, out of the range limits) have valid = 0, xyz = 0 and
/// range_m = 0; they are not data.
struct Scan {
  int rows = 0;
  int cols = 0;
  int64_t stamp_ns = 0;              ///< the scan's reference instant (see Times above), ns
  uint64_t sequence = 0;             ///< 0-based index of the scan in its recording
  std::vector<Eigen::Vector3f> xyz;  ///< sensor frame, metres
  /// The range the sensor reported, metres (Ouster: along the beam from the lidar origin,
  /// beam origin offset included); |xyz| where the source has no range of its own.
  std::vector<float> range_m;
  /// Per point, seconds after stamp_ns (negative before it), for deskewing; all 0 where the
  /// source tells no times.
  std::vector<float> time_offset_s;
  std::vector<uint8_t> valid;  ///< 1 where the cell holds a return
  std::vector<ScanChannel> channels;
  /// The IMU's samples taken during this sweep, in the sensor frame and time order; empty
  /// where the source has no IMU.
  std::vector<ImuSample> imu;

  /// A scan of rows x cols with every cell invalid and no channels.
  static Scan allocate(int rows, int cols);

  size_t size() const { return static_cast<size_t>(rows) * static_cast<size_t>(cols); }
  size_t index(int row, int col) const {
    return static_cast<size_t>(row) * static_cast<size_t>(cols) + static_cast<size_t>(col);
  }
  size_t valid_count() const;
  /// When each column was measured, seconds after stamp_ns (negative before it): the time of
  /// its first valid point (sources with per-point times are honoured per column); nullopt
  /// for a column without a valid point or a scan without times.
  std::vector<std::optional<float>> column_time_offsets_s() const;

  /// The channel of that name, or nullptr.
  const ScanChannel* channel(std::string_view name) const;
  ScanChannel* channel(std::string_view name);
  /// Adds a zero-filled channel of that name (or returns the existing one).
  ScanChannel& add_channel(std::string_view name);
  /// The channel used as intensity: reflectivity, else intensity, else signal; nullptr if
  /// the scan has none of them.
  const ScanChannel* intensity() const;

  /// Marks a cell invalid and zeroes its geometry.
  void invalidate(size_t i);
};

}  // namespace featsense::slam
