#pragma once
// Hands the IMU's samples to the scans whose sweeps they were taken in. Readers that get the
// samples apart from the scans (other UDP packets, another topic, another file) buffer them
// here and attach them as each scan is handed out.

#include <cstdint>
#include <string>
#include <vector>

#include "featsense/slam/imu_sample.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam::detail {

/// A scan's sweep is [stamp_ns, stamp_ns + one revolution): the stamp is where it began and
/// the next one begins a revolution later. A sample goes to the first scan whose sweep holds
/// its stamp and to no other, so that sweeps that overlap by a stamp's jitter share nothing;
/// samples that fall before the first scan or between two sweeps (a sweep whose first columns
/// were lost) go to none. Samples may come in any order: they are sorted when attached.
class ImuSweepAssigner {
 public:
  explicit ImuSweepAssigner(int64_t sweep_ns);

  /// Buffers a sample; one older than the end of a sweep already handed out is too late for
  /// it and is dropped (counted in late()).
  void add(const ImuSample& sample);
  /// True once a sample stamped past the end of `scan`'s sweep (plus a margin for packets
  /// reordered on the way) has come: later samples are not expected to belong to it.
  bool covers(const Scan& scan) const;
  /// Moves the buffered samples of `scan`'s sweep into scan.imu, in time order; the samples
  /// before the sweep are dropped (counted in unassigned()).
  void attach(Scan& scan);

  /// Samples seen so far (before any was dropped).
  size_t received() const { return received_; }
  /// Samples handed to a scan.
  size_t assigned() const { return assigned_; }
  size_t late() const { return late_; }
  size_t unassigned() const { return unassigned_; }

 private:
  int64_t sweep_ns_;
  std::vector<ImuSample> buffer_;
  bool sorted_ = true;  ///< whether buffer_ is in time order
  bool any_received_ = false;
  int64_t newest_ns_ = 0;        ///< the latest stamp received
  bool any_attached_ = false;    ///< whether a sweep has been handed out yet
  int64_t attached_end_ns_ = 0;  ///< the end of the latest sweep handed out
  size_t received_ = 0;
  size_t assigned_ = 0;
  size_t late_ = 0;
  size_t unassigned_ = 0;
};

/// A warning where samples came but none fell in a sweep (the IMU's clock is not the
/// scans'), else empty.
std::string clock_mismatch_warning(const ImuSweepAssigner& imu, const std::string& origin);

/// One revolution at `rate_hz` in ns (a tenth of a second where the rate is not positive).
int64_t sweep_duration_ns(double rate_hz);

}  // namespace featsense::slam::detail
