// open_pcd_file() and open_ply_file(): one file, one frame.

#include <filesystem>

#include "cloud/cloud_file_io.hpp"
#include "cloud/frame_naming.hpp"
#include "featsense/slam/io/readers.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

/// The file is read and organized when opened (its fields and sensor are part of info()),
/// and handed out by the first next().
class CloudFileSource final : public ScanSource {
 public:
  CloudFileSource(const std::string& path, const SourceOptions& options,
                  cloud::CloudFormat format) {
    const DecodedCloud decoded = cloud::decode_cloud_file(path, format);
    for (const std::string& w : decoded.warnings) warn(path + ": " + w);
    std::string why;
    info_.sensor = choose_sensor(decoded, options, path, &why);
    info_.format = decoded.format;
    info_.path = path;
    info_.frames = 1;
    info_.fields = decoded.fields;
    OrganizeStats stats;
    std::vector<std::string> warnings;
    // The stamp (below) is never KITTI's: derived times count from the sweep's start.
    CloudTiming timing;
    timing.from_azimuth = options.times_from_azimuth;
    scan_ = cloud_to_scan(decoded, info_.sensor, path, &stats, &warnings, timing, &info_.times);
    cloud::check_sensor_fits(stats, decoded.cloud, info_.sensor, path);
    info_.detail = cloud::describe(stats, &warnings, path) + "; sensor " + why;
    for (const std::string& w : warnings) warn(w);
    // As in folders: a stamp in the name, else the one the file states, else 0.
    scan_->stamp_ns = cloud::stamp_from_name(fs::path(path).stem().string())
                          .value_or(decoded.stamp_ns.value_or(0));
  }

  std::optional<Scan> next() override {
    if (!scan_) return std::nullopt;
    std::optional<Scan> out = std::move(scan_);
    scan_.reset();
    count_frame();
    return out;
  }
  const SourceInfo& info() const override { return info_; }

 private:
  SourceInfo info_;
  std::optional<Scan> scan_;
};

}  // namespace

std::unique_ptr<ScanSource> open_pcd_file(const std::string& path, const SourceOptions& options) {
  return std::make_unique<CloudFileSource>(path, options, cloud::CloudFormat::kPcd);
}

std::unique_ptr<ScanSource> open_ply_file(const std::string& path, const SourceOptions& options) {
  return std::make_unique<CloudFileSource>(path, options, cloud::CloudFormat::kPly);
}

}  // namespace featsense::slam
