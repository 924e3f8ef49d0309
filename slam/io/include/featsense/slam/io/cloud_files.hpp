#pragma once
/// Point-cloud files (PCD, PLY, KITTI .bin) decoded from memory, and decoded clouds turned
/// into Scans. open_pcd_file(), open_ply_file() and open_scan_folder() are built on these;
/// tests and fuzzers feed bytes to them directly.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/azimuth_times.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/io/organize.hpp"
#include "featsense/slam/point_cloud.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

/// A cloud as one file stores it.
struct DecodedCloud {
  std::string format;  ///< "pcd", "ply" or "kitti-bin"
  /// The points in file order. Organized files (height > 1) keep every cell, row-major,
  /// empty cells as the file has them (NaN or zero). ring_counts_up is measured from the
  /// data: true when higher ring numbers have higher elevations (Velodyne).
  PointCloud cloud;
  int width = 0;                    ///< points per row
  int height = 1;                   ///< rows; more than 1 means an organized range image
  std::vector<std::string> fields;  ///< every field / property name the file lists
  /// From the file itself: a `featsense stamp_ns` comment, else absolute point times.
  std::optional<int64_t> stamp_ns;
  std::vector<std::string> warnings;  ///< things ignored on the way (non-identity VIEWPOINT ...)

  bool organized() const { return height > 1; }
};

/// PCD v0.7 (or the older header without VERSION), DATA ascii / binary / binary_compressed.
/// Throws InputError naming `origin` and the problem for any header that lies about the data.
DecodedCloud decode_pcd(std::string_view bytes, const std::string& origin);
/// PLY, ascii or binary little / big endian; the points of the `vertex` element.
DecodedCloud decode_ply(std::string_view bytes, const std::string& origin);
/// KITTI .bin: float32 x y z reflectance per point (channel "intensity"); the size must be a
/// multiple of 16 bytes.
DecodedCloud decode_kitti_bin(std::string_view bytes, const std::string& origin);

/// The sensor model for a decoded cloud (`why` says how it was chosen):
/// - options.sensor_preset when it is not "auto" (an organized cloud's height must equal its
///   beams);
/// - organized clouds: the preset whose beams the rows lie on, else beam elevations measured
///   from the rows (at least half of them with points), else the preset with `height` beams;
///   columns = width either way;
/// - a ring field: the smallest of vlp16 / hdl32 / hdl64 / os1-128 with beams > the largest
///   ring;
/// - else the preset on whose beam elevations nearly all points lie (seen from its beam
///   origin; exact for simulated or nominally calibrated data), else a model measured from
///   the points where they lie on 8 to 256 clean beams, else `unmatched_preset` where
///   one is given (a KITTI .bin folder: hdl64, whose per-unit calibration fits no preset
///   exactly), else InputError asking for `--set sensor.preset=NAME`.
config::SensorModel choose_sensor(const DecodedCloud& decoded, const SourceOptions& options,
                                  const std::string& origin, std::string* why = nullptr,
                                  const std::string& unmatched_preset = "");

/// How cloud_to_scan() times the points of a cloud without a per-point time field.
struct CloudTiming {
  /// Times from the azimuth (azimuth_times.hpp); else none. Config key
  /// sensor.times_from_azimuth.
  bool from_azimuth = config::SensorConfig{}.times_from_azimuth;
  /// What the scan's stamp will stand for, the zero of the derived times.
  SweepReference reference = SweepReference::kSweepStart;
};

/// The cloud as a Scan of `sensor`. Organized clouds map cell by cell (rows flipped when the
/// file lists the lowest beam first); others go through organize(). Per-point times that
/// cannot be times within the revolution (a span far shorter than a revolution over most of
/// the azimuth, as per-packet times are) are set to 0 with a warning. A cloud without a time
/// field gets times from its points' azimuths as `timing` says; where their order tells none,
/// they stay 0 with a warning. `times` (optional) tells where the times came from, for
/// reports: "per-point field 't'", "from the azimuth (...)" or "none: why". Throws
/// InputError when an organized cloud's height differs from sensor.beams.
Scan cloud_to_scan(const DecodedCloud& decoded, const config::SensorModel& sensor,
                   const std::string& origin, OrganizeStats* stats = nullptr,
                   std::vector<std::string>* warnings = nullptr, const CloudTiming& timing = {},
                   std::string* times = nullptr);

}  // namespace featsense::slam
