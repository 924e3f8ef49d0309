#pragma once
/// Streaming access to a recording: one Scan at a time, never the whole file in memory.

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam {

/// Input that cannot be read at all (missing, truncated before the first frame, corrupt
/// header, wrong format). The message names the file and, where known, the byte offset.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a recording holds, known after opening (before reading frames).
struct SourceInfo {
  std::string format;  ///< "ouster-pcap", "rosbag", "pcd", "ply", "kitti-bin", "simulated", ...
  std::string path;
  config::SensorModel sensor;         ///< from the recording's metadata or a preset
  bool sensor_from_metadata = false;  ///< true when the recording described its own sensor
  std::optional<size_t> frames;       ///< known without reading the data (folders), else unset
  std::vector<std::string> fields;    ///< per-point fields the recording carries
  std::string detail;                 ///< one line for humans, e.g. "profile RNG15_RFL8_NIR8"
  /// Where the per-point times come from, one line for humans: "per-point field 't'",
  /// "from the azimuth (...)", "none: why"; as the first frame had them.
  std::string times;
  /// Where the IMU's samples (Scan::imu) come from and in which frame, one line for humans;
  /// empty where the recording has none or they are not read.
  std::string imu;
  /// Recordings of several topics (bags, MCAP): each as "name (type, encoding, N messages)".
  std::vector<std::string> topics;
};

/// Counts of what a source skipped; warnings are counted, the first few kept verbatim.
struct ReadStats {
  size_t frames_read = 0;
  size_t frames_skipped = 0;
  size_t warning_count = 0;
  std::vector<std::string> warnings;  ///< the first kMaxKeptWarnings messages

  static constexpr size_t kMaxKeptWarnings = 20;
};

class ScanSource {
 public:
  virtual ~ScanSource() = default;

  /// The next scan in recording order, or nullopt at the end. A damaged frame is skipped
  /// with a counted warning; input that cannot be read at all throws InputError.
  virtual std::optional<Scan> next() = 0;
  virtual const SourceInfo& info() const = 0;
  virtual const ReadStats& stats() const { return stats_; }

 protected:
  void warn(const std::string& message);
  /// Counts a skipped frame and warns why.
  void skip_frame(const std::string& why);
  /// Counts a frame handed out.
  void count_frame() { ++stats_.frames_read; }

 private:
  ReadStats stats_;
};

}  // namespace featsense::slam
