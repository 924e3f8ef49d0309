#pragma once
// What placing a recording in a saved map did: what was tried, where and by which keyframes it
// was placed, the links to the map's earlier sessions and what became of them. Plain data: a
// caller writes it as it likes (the command line as report.json's "relocalization").

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "featsense/mapping/map_policy.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/loops/relocalizer.hpp"

namespace featsense::mapping {

struct RelocalizationReport {
  std::string map;  ///< the saved map
  size_t map_sessions = 0;
  size_t map_keyframes = 0;
  size_t max_scans = 0;  ///< relocalize.max_scans
  slam::loops::RelocalizationCounts tried;
  /// Where it was placed; none: it was not (then `why` says what was tried).
  std::optional<slam::loops::Relocalization> placement;
  std::string why;
  uint32_t session = 0;     ///< the recording's id among the map's sessions
  double seconds_in = 0.0;  ///< sensor time from its first scan to the keyframe that placed it
  KeyframeId matched;       ///< the map's keyframe it matched
  SessionLinks links;       ///< every link between the sessions
  double earlier_moved_max_m = 0.0;  ///< how far the links moved the map's earlier keyframes
  double earlier_moved_max_deg = 0.0;
  EarlierSessionsOutcome earlier;
  /// Where the earlier sessions were mapped again: what was integrated again and kept.
  std::optional<ReintegrationCounts> reintegration;
};

/// The recording could not be placed in the map: nothing was written into it.
class RelocalizationFailed : public std::runtime_error {
 public:
  RelocalizationFailed(const std::string& why, RelocalizationReport report)
      : std::runtime_error(why), report_(std::move(report)) {}
  const RelocalizationReport& report() const { return report_; }

 private:
  RelocalizationReport report_;
};

}  // namespace featsense::mapping
