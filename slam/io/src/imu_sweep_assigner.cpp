#include "imu_sweep_assigner.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace featsense::slam::detail {
namespace {

/// How long after a sweep's end a sample may still arrive for it: UDP packets overtake each
/// other by far less, bag messages are written in the order they came.
constexpr int64_t kReorderMarginNs = 20'000'000;

}  // namespace

int64_t sweep_duration_ns(double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) return 100'000'000;
  return static_cast<int64_t>(std::llround(1.0e9 / rate_hz));
}

std::string clock_mismatch_warning(const ImuSweepAssigner& imu, const std::string& origin) {
  if (imu.received() == 0 || imu.assigned() > 0) return {};
  return origin + ": " + std::to_string(imu.received()) +
         " IMU samples, but none was stamped within a scan's sweep (do the IMU and the "
         "LiDAR stamp with different clocks?); the scans have no IMU samples";
}

ImuSweepAssigner::ImuSweepAssigner(int64_t sweep_ns) : sweep_ns_(std::max<int64_t>(sweep_ns, 1)) {}

void ImuSweepAssigner::add(const ImuSample& sample) {
  ++received_;
  if (any_attached_ && sample.stamp_ns < attached_end_ns_) {
    ++late_;
    return;
  }
  if (!buffer_.empty() && sample.stamp_ns < buffer_.back().stamp_ns) sorted_ = false;
  newest_ns_ = any_received_ ? std::max(newest_ns_, sample.stamp_ns) : sample.stamp_ns;
  any_received_ = true;
  buffer_.push_back(sample);
}

bool ImuSweepAssigner::covers(const Scan& scan) const {
  return any_received_ && newest_ns_ >= scan.stamp_ns + sweep_ns_ + kReorderMarginNs;
}

void ImuSweepAssigner::attach(Scan& scan) {
  const int64_t begin = scan.stamp_ns;
  const int64_t end = scan.stamp_ns + sweep_ns_;
  if (!sorted_) {
    std::stable_sort(buffer_.begin(), buffer_.end(), [](const ImuSample& a, const ImuSample& b) {
      return a.stamp_ns < b.stamp_ns;
    });
    sorted_ = true;
  }
  const auto first_in = std::lower_bound(
      buffer_.begin(), buffer_.end(), begin,
      [](const ImuSample& sample, int64_t stamp) { return sample.stamp_ns < stamp; });
  const auto first_after = std::lower_bound(
      first_in, buffer_.end(), end,
      [](const ImuSample& sample, int64_t stamp) { return sample.stamp_ns < stamp; });
  unassigned_ += static_cast<size_t>(std::distance(buffer_.begin(), first_in));
  assigned_ += static_cast<size_t>(std::distance(first_in, first_after));
  scan.imu.insert(scan.imu.end(), first_in, first_after);
  std::stable_sort(scan.imu.begin(), scan.imu.end(),
                   [](const ImuSample& a, const ImuSample& b) { return a.stamp_ns < b.stamp_ns; });
  buffer_.erase(buffer_.begin(), first_after);
  attached_end_ns_ = any_attached_ ? std::max(attached_end_ns_, end) : end;
  any_attached_ = true;
}

}  // namespace featsense::slam::detail
