#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

void ScanSource::warn(const std::string& message) {
  ++stats_.warning_count;
  if (stats_.warnings.size() < ReadStats::kMaxKeptWarnings) stats_.warnings.push_back(message);
}

void ScanSource::skip_frame(const std::string& why) {
  ++stats_.frames_skipped;
  warn(why);
}

}  // namespace featsense::slam
