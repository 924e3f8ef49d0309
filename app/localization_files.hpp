#pragma once
// trajectory.tum and localization.csv of `featsense localize`, written a scan at a time and
// flushed after each: another process (a robot's planner, `tail -f`) can follow the poses
// while the run goes on, and a run that is killed keeps every scan it finished.

#include <filesystem>
#include <fstream>

#include "featsense/mapping/localizer.hpp"

namespace featsense::app {

class LocalizationFiles {
 public:
  /// Creates (replaces) `folder`/trajectory.tum and `folder`/localization.csv. Throws
  /// std::runtime_error naming the file that cannot be written.
  explicit LocalizationFiles(const std::filesystem::path& folder);

  /// Appends the scan: to localization.csv always (status, pose where it has one, fit,
  /// time), to trajectory.tum where it has a pose. Throws std::runtime_error on a failed write.
  void add(const mapping::LocalizedScan& scan);

 private:
  std::filesystem::path tum_path_;
  std::filesystem::path csv_path_;
  std::ofstream tum_;
  std::ofstream csv_;
};

}  // namespace featsense::app
