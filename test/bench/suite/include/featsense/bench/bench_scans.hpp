#pragma once
// The scans a front-end benchmark runs over, one at a time: a recording's, or a simulation's
// made frame by frame outside the timed stages, so that a long sequence needs no memory of
// its own (the peak RSS is the front end's).

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::bench {

class BenchScans {
 public:
  /// The first `limit` scans of a recording; `name` says which in messages.
  BenchScans(std::unique_ptr<slam::ScanSource> recording, std::string name, uint64_t limit);
  /// Frames 0 .. frames-1 of `simulator` (which must outlive this), the truth at their stamps.
  BenchScans(const slam::LidarSimulator& simulator, uint64_t frames, slam::Trajectory truth,
             std::string description);

  std::optional<slam::Scan> next();

  /// Throws InputError when the source gave no scan at all.
  void check_read() const;

  const std::optional<slam::Trajectory>& truth() const { return truth_; }
  /// The sensor that recorded the scans (the recording's, or the simulated one).
  const config::SensorModel& sensor() const;

  /// The figures every front-end benchmark starts with: its name, the scans, their size.
  nlohmann::json json(const char* benchmark) const;

 private:
  std::unique_ptr<slam::ScanSource> recording_;
  const slam::LidarSimulator* simulator_ = nullptr;
  std::optional<slam::Trajectory> truth_;
  std::string name_;
  std::string description_;
  uint64_t limit_;
  uint64_t count_ = 0;
  int rows_ = 0;
  int cols_ = 0;
};

}  // namespace featsense::bench
