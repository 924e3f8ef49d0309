#pragma once
/// Per-point times for the cloud of a spinning LiDAR that stores none (KITTI .bin, PCD / PLY
/// / PointCloud2 without a time field): each point's azimuth, read in the order the file
/// lists the points, tells when the sensor faced it.

#include <Eigen/Core>

#include <string>
#include <vector>

namespace featsense::slam {

/// The instant a scan's stamp stands for: the zero of the times derived here. The one rule:
/// a KITTI sequence's times.txt gives kFacingForward (KITTI triggers its cameras when the
/// laser faces forward, +x, mid-sweep, and its poses are at those instants); every other
/// stamp (the file's own, a time in the file name, a bag message's header, sequence.yaml,
/// the frame's index over the rate) is the sweep's start: kSweepStart.
enum class SweepReference {
  kSweepStart,     ///< times from 0 to a revolution
  kFacingForward,  ///< times around 0: negative before the sensor faced +x, positive after
};

/// What azimuth_times() found.
struct AzimuthTimes {
  /// Seconds after the reference instant, one per input point (0 for points that are no
  /// return); empty when the order of the points tells no times (`problem` says why).
  std::vector<float> offset_s;
  double seam_rad = 0.0;  ///< where the sweep began: clockwise from +x seen from above, [0, 2 pi)
  int sweeps = 0;         ///< turns in the file order: 1 in firing order, one per ring by ring
  SweepReference reference = SweepReference::kSweepStart;
  std::string problem;  ///< why there are no times, for reports

  bool found() const { return !offset_s.empty(); }
};

/// Times from the azimuth of `xyz` (sensor frame, in the order the file stores them; points
/// that are no return are skipped) for a sensor that turns clockwise seen from above, once
/// every 1 / rate_hz seconds, as Ouster and Velodyne sensors do and as scan columns run:
/// - the sweep began where the file's first points lie (the earliest azimuth of the cluster
///   that most of the first 16 returns form: a firing's beams, or the start of a ring; else
///   the first return's);
/// - the file must list the points in the order they were measured: in firing order (one
///   turn), or ring by ring with every ring restarting at that seam (KITTI, organized images
///   row by row; where the rings begin is told by the seam and, beside it, by the change of
///   elevation from ring to ring, and the seam moves to where most rings begin when the
///   first ring's first returns are missing); else (sorted or shuffled points, or points
///   running counterclockwise) there are no times, and `problem` says why;
/// - a point's time is the clockwise angle from the seam, counted along its turn (points a
///   little past the seam at the end of a turn are late), over 2 pi rate_hz; relative to
///   `reference`: the sweep's start (times >= 0) or the instant the sensor faced +x.
/// A beam's azimuth offset (a few degrees on most sensors, up to 10 on an HDL-64) shifts its
/// points' times by that angle's share of a revolution: the time is the azimuth's, not the
/// firing's.
AzimuthTimes azimuth_times(const std::vector<Eigen::Vector3f>& xyz, double rate_hz,
                           SweepReference reference);

/// One line for reports: "from the azimuth (...)" with where the sweep began, the order and
/// the reference; or "none: " and the problem.
std::string describe(const AzimuthTimes& times);

/// One line for reports on where a cloud's times come from: its own field `time_field`
/// ("per-point field 't'"); else `derived`, as describe() says; else (nullptr) none, since
/// sensor.times_from_azimuth is false.
std::string describe_times(const std::string& time_field, const AzimuthTimes* derived);

}  // namespace featsense::slam
