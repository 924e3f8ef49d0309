#pragma once
/// Turns PointCloud2 messages whose layout is readable (layout_problem() said nothing) into
/// scan data. Fields are found by name and converted to float from any datatype:
/// - x, y, z: metres, sensor frame. A point with a non-finite coordinate or at (0, 0, 0) is
///   no return (invalid).
/// - channels, kept under the Scan names: intensity, reflectivity, signal, ambient, and nir
///   (also from `near_ir`); values as the driver wrote them.
/// - ring index: `ring` (Ouster, Velodyne), else `channel` (some Velodyne drivers).
/// - range (organized clouds only): `range`, millimetres when an integer type (Ouster's
///   u32), metres when a float type; else |xyz|.
/// - per-point time, from the first of `t`, `time`, `timestamp`, `time_stamp`,
///   `offset_time`. Integer datatypes count nanoseconds after the message stamp (Ouster's
///   `t`: u32 ns since the start of the frame; Livox `offset_time`). Float datatypes count
///   seconds: values above 1e6 s are absolute epoch times (drivers that write float64
///   `timestamp`) and become seconds after the stamp; smaller ones are already relative to
///   the stamp (Velodyne's float32 `time`, which may be negative where the stamp is the end
///   of the sweep). Times that are not finite or lie more than an hour from the stamp are 0.
///   Where the earliest point lies before the stamp, the scan's stamp moves to it, so that
///   offsets are never negative and absolute point times are kept.
/// The scan stamp is the header stamp, or `fallback_stamp_ns` (the bag's receive time)
/// where a driver left the header stamp at 0.

#include <cstdint>
#include <optional>

#include "featsense/slam/point_cloud.hpp"
#include "featsense/slam/scan.hpp"
#include "rosbag/pointcloud2.hpp"

namespace featsense::slam {

/// An organized cloud as a Scan of height x width, its rows as stored.
Scan organized_cloud_to_scan(const PointCloud2View& cloud, int64_t fallback_stamp_ns);

/// Any cloud as a flat point list for organize() (every point, invalid ones included, which
/// organize() drops). `ring` is filled where the cloud has a ring field (-1 for values that
/// are no ring index); `ring_counts_up` is told by the data: whether the highest ring index
/// has the higher mean elevation.
PointCloud cloud_to_points(const PointCloud2View& cloud, int64_t fallback_stamp_ns);

/// The field the per-point times are read from (the first of the names above), or nullptr
/// where the cloud has none.
const PointFieldDesc* time_field(const PointCloud2View& cloud);

/// Largest ring index + 1 in the cloud, or 0 where it has no ring field.
int ring_count(const PointCloud2View& cloud);

/// Whether a scan's rows run from the lowest beam up, judged by the mean elevation of the
/// valid points of its first and last rows that have any; nullopt where fewer than two
/// rows hold points.
std::optional<bool> rows_lowest_first(const Scan& scan);

/// Reverses the order of the rows (all per-point arrays and channels).
void flip_rows(Scan& scan);

/// Mean elevation (radians above the horizontal) of the valid points of each row; nullopt
/// for a row without any.
std::vector<std::optional<double>> row_elevations(const Scan& scan);

}  // namespace featsense::slam
