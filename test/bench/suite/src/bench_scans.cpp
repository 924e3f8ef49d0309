#include "featsense/bench/bench_scans.hpp"

#include <utility>

namespace featsense::bench {

BenchScans::BenchScans(std::unique_ptr<slam::ScanSource> recording, std::string name,
                       uint64_t limit)
    : recording_(std::move(recording)),
      name_(std::move(name)),
      description_(recording_->info().format + " " + name_),
      limit_(limit) {}

BenchScans::BenchScans(const slam::LidarSimulator& simulator, uint64_t frames,
                       slam::Trajectory truth, std::string description)
    : simulator_(&simulator),
      truth_(std::move(truth)),
      name_("the simulation"),
      description_(std::move(description)),
      limit_(frames) {}

std::optional<slam::Scan> BenchScans::next() {
  if (count_ >= limit_) return std::nullopt;
  std::optional<slam::Scan> scan;
  if (recording_) {
    scan = recording_->next();
  } else {
    scan = std::move(simulator_->simulate(count_).scan);
    scan->sequence = count_;
  }
  if (!scan) return std::nullopt;
  if (count_ == 0) {
    rows_ = scan->rows;
    cols_ = scan->cols;
  }
  ++count_;
  return scan;
}

const config::SensorModel& BenchScans::sensor() const {
  return recording_ ? recording_->info().sensor : simulator_->settings().sensor;
}

void BenchScans::check_read() const {
  if (count_ == 0) throw slam::InputError(name_ + ": no readable frame");
}

nlohmann::json BenchScans::json(const char* benchmark) const {
  return {{"benchmark", benchmark},
          {"scans", description_},
          {"sequence_scans", count_},
          {"rows", rows_},
          {"cols", cols_}};
}

}  // namespace featsense::bench
