#pragma once
/// The fits (mean correspondence distance) of the last registrations that converged: what a
/// good fit looks like in the scene the sensor is in now, to tell a wrong minimum by.

#include <cstddef>
#include <deque>
#include <vector>

#include "featsense/slam/upper_median.hpp"

namespace featsense::slam::odometry {

class RecentFits {
 public:
  /// Scans remembered: two seconds at 10 Hz, so the median follows a change of scene.
  static constexpr size_t kKept = 20;
  /// Fewer fits than this say nothing yet.
  static constexpr size_t kEnough = 5;

  void add(double fit_m) {
    fits_.push_back(fit_m);
    if (fits_.size() > kKept) fits_.pop_front();
  }

  /// The median of the fits kept; 0 until there are kEnough.
  double median() const {
    if (fits_.size() < kEnough) return 0.0;
    std::vector<double> fits(fits_.begin(), fits_.end());
    return upper_median(fits);
  }

 private:
  std::deque<double> fits_;
};

}  // namespace featsense::slam::odometry
