// open_scan_folder(): a folder of KITTI .bin, PCD or PLY scans, or one written by
// `featsense simulate` (sequence.yaml, see SEQUENCE_FORMAT.md).

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>

#include "cloud/cloud_file_io.hpp"
#include "cloud/frame_naming.hpp"
#include "cloud/text_lines.hpp"
#include "featsense/slam/io/imu_csv.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/io/sequence_file.hpp"
#include "imu_sweep_assigner.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;
using cloud::CloudFormat;

struct Frame {
  fs::path file;
  std::optional<int64_t> stamp_ns;  ///< from the name, times.txt or sequence.yaml
};

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::optional<CloudFormat> format_of_extension(const std::string& extension) {
  if (extension == ".bin") return CloudFormat::kKittiBin;
  if (extension == ".pcd") return CloudFormat::kPcd;
  if (extension == ".ply") return CloudFormat::kPly;
  return std::nullopt;
}

/// KITTI's times.txt (seconds, one line per scan) beside the scans or one folder up.
std::optional<std::vector<double>> read_times_txt(const fs::path& folder, std::string* used) {
  for (const fs::path& candidate : {folder / "times.txt", folder.parent_path() / "times.txt"}) {
    std::error_code ec;
    if (!fs::is_regular_file(candidate, ec)) continue;
    const std::string text = cloud::read_file_bytes(candidate);
    std::vector<double> seconds;
    cloud::LineReader lines(text);
    while (const std::optional<std::string_view> line = lines.next()) {
      const std::vector<std::string_view> words = cloud::split_words(*line);
      if (words.empty()) continue;
      const std::optional<double> t =
          words.size() == 1 ? cloud::parse_number(words[0]) : std::nullopt;
      if (!t || !std::isfinite(*t)) return std::nullopt;
      seconds.push_back(*t);
    }
    *used = candidate.string();
    return seconds;
  }
  return std::nullopt;
}

class ScanFolderSource final : public ScanSource {
 public:
  ScanFolderSource(const std::string& path, const SourceOptions& options) : folder_(path) {
    std::error_code ec;
    if (!fs::is_directory(folder_, ec)) throw InputError(path + ": not a folder");
    info_.path = path;
    timing_.from_azimuth = options.times_from_azimuth;
    if (fs::exists(folder_ / "sequence.yaml", ec)) {
      open_sequence(options);
    } else {
      open_scans(options);
    }
    info_.frames = frames_.size();
  }

  std::optional<Scan> next() override {
    while (next_ < frames_.size()) {
      const size_t index = next_++;
      if (index < first_index_) continue;  // failed while opening; counted then
      std::optional<Scan> scan;
      std::optional<int64_t> file_stamp;
      if (first_ && index == first_index_) {
        scan = std::move(first_);
        first_.reset();
        file_stamp = first_stamp_;
      } else {
        scan = read_frame(index, &file_stamp);
        if (!scan) continue;
      }
      scan->stamp_ns = stamp_of(index, file_stamp);
      scan->sequence = index;
      if (imu_) imu_->attach(*scan);
      count_frame();
      return scan;
    }
    return std::nullopt;
  }

  const SourceInfo& info() const override { return info_; }

 private:
  /// The stamp from the frame's name, times.txt or sequence.yaml; else the one the file
  /// states; else the frame's index over the rate.
  int64_t stamp_of(size_t index, const std::optional<int64_t>& file_stamp) const {
    if (frames_[index].stamp_ns) return *frames_[index].stamp_ns;
    if (file_stamp) return *file_stamp;
    return static_cast<int64_t>(std::llround(static_cast<double>(index) * 1e9 / rate_hz_));
  }

  /// The frame as a Scan, or nullopt with a counted warning when it cannot be read.
  std::optional<Scan> read_frame(size_t index, std::optional<int64_t>* file_stamp) {
    const std::string origin = frames_[index].file.string();
    try {
      const DecodedCloud decoded = cloud::decode_cloud_file(frames_[index].file, format_);
      for (const std::string& w : decoded.warnings) warn(origin + ": " + w);
      OrganizeStats stats;
      std::vector<std::string> warnings;
      Scan scan = cloud_to_scan(decoded, info_.sensor, origin, &stats, &warnings, timing_);
      cloud::describe(stats, &warnings, origin);
      for (const std::string& w : warnings) warn(w);
      *file_stamp = decoded.stamp_ns;
      return scan;
    } catch (const InputError& e) {
      skip_frame(std::string("frame skipped: ") + e.what());
      return std::nullopt;
    }
  }

  void open_sequence(const SourceOptions& options) {
    const fs::path index = folder_ / "sequence.yaml";
    const cloud::SequenceFile sequence =
        cloud::parse_sequence_yaml(cloud::read_file_bytes(index), index.string());
    info_.format = "simulated";
    info_.sensor = sequence.sensor;
    info_.sensor_from_metadata = true;
    rate_hz_ = sequence.rate_hz;
    format_ = CloudFormat::kPcd;
    for (const cloud::SequenceFrame& f : sequence.frames) {
      frames_.push_back({folder_ / f.file, f.stamp_ns});
    }
    if (options.sensor_preset != "auto") {
      warn("sensor.preset " + options.sensor_preset + " ignored: " + index.string() +
           " describes the sensor");
    }
    if (frames_.empty()) throw InputError(index.string() + ": lists no frames");
    open_first_cloud(options, sequence.sensor);
    info_.format = "simulated";
    info_.detail =
        std::to_string(frames_.size()) + " simulated frames, sensor " + sequence.sensor.name;
    if (options.imu) open_imu_csv();
  }

  /// The IMU's samples of imu.csv beside sequence.yaml, where there is one: small enough (a
  /// few MB an hour) to be read at once and handed to the frames as they are read.
  void open_imu_csv() {
    const fs::path path = folder_ / "imu.csv";
    std::error_code ec;
    if (!fs::exists(path, ec)) return;
    std::vector<std::string> skipped;
    size_t skipped_count = 0;
    const std::vector<ImuSample> samples =
        parse_imu_csv(cloud::read_file_bytes(path), path.string(), &skipped, &skipped_count);
    for (const std::string& line : skipped) warn(line);
    if (skipped_count > skipped.size()) {
      warn(path.string() + ": " + std::to_string(skipped_count - skipped.size()) +
           " more lines skipped");
    }
    imu_ = std::make_unique<detail::ImuSweepAssigner>(detail::sweep_duration_ns(rate_hz_));
    for (const ImuSample& sample : samples) imu_->add(sample);
    info_.imu = "imu.csv (" + std::to_string(samples.size()) + " samples, sensor frame)";
  }

  void open_scans(const SourceOptions& options) {
    std::map<std::string, std::vector<fs::path>> by_extension;
    size_t entries = 0;
    std::error_code ec;
    for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
      const fs::directory_entry& entry = *it;
      ++entries;
      std::error_code file_ec;
      if (!entry.is_regular_file(file_ec)) continue;
      const std::string extension = lower(entry.path().extension().string());
      if (format_of_extension(extension)) by_extension[extension].push_back(entry.path());
    }
    if (ec) throw InputError(info_.path + ": cannot list the folder: " + ec.message());
    if (by_extension.empty()) {
      throw InputError(info_.path + (entries == 0 ? ": empty folder"
                                                  : ": no scans (.bin, .pcd or .ply files) among " +
                                                        std::to_string(entries) + " entries"));
    }
    if (by_extension.size() > 1) {
      std::string found;
      for (const auto& [extension, files] : by_extension) {
        found += (found.empty() ? "" : ", ") + std::to_string(files.size()) + " " + extension;
      }
      throw InputError(info_.path + ": mixed scan formats in one folder (" + found +
                       "); keep one format per folder");
    }
    const auto& [extension, files] = *by_extension.begin();
    format_ = *format_of_extension(extension);
    order_frames(files);
    // Before the first frame is read: its times count from the instant its stamp stands for.
    if (!frames_.front().stamp_ns && stamps_from_times_txt()) {
      timing_.reference = SweepReference::kFacingForward;
    }

    // KITTI's own scans come from an HDL-64E; a .bin folder of another sensor's scans is told
    // by the elevations its points lie on.
    open_first_cloud(options, std::nullopt, format_ == CloudFormat::kKittiBin ? "hdl64" : "");
    rate_hz_ = info_.sensor.rate_hz;
  }

  /// Name stamps order the frames when every name has one; else natural name order.
  void order_frames(const std::vector<fs::path>& files) {
    for (const fs::path& f : files)
      frames_.push_back({f, cloud::stamp_from_name(f.stem().string())});
    const bool all_stamped = std::all_of(frames_.begin(), frames_.end(),
                                         [](const Frame& f) { return f.stamp_ns.has_value(); });
    if (!all_stamped) {
      for (Frame& f : frames_) f.stamp_ns.reset();
    }
    std::sort(frames_.begin(), frames_.end(), [](const Frame& a, const Frame& b) {
      if (a.stamp_ns != b.stamp_ns) return a.stamp_ns < b.stamp_ns;
      return cloud::natural_less(a.file.filename().string(), b.file.filename().string());
    });
  }

  /// KITTI's times.txt as the frames' stamps; whether it was used.
  bool stamps_from_times_txt() {
    std::string used;
    const std::optional<std::vector<double>> seconds = read_times_txt(folder_, &used);
    if (!seconds) {
      if (!used.empty()) warn(used + ": not one time per line; not used");
      return false;
    }
    auto stamp = [](double s) { return static_cast<int64_t>(std::llround(s * 1e9)); };
    if (seconds->size() == frames_.size()) {
      for (size_t i = 0; i < frames_.size(); ++i) frames_[i].stamp_ns = stamp((*seconds)[i]);
      return true;
    }
    // A subset of a KITTI sequence: names are the frame numbers that index times.txt.
    std::vector<size_t> numbers;
    for (const Frame& f : frames_) {
      const std::optional<uint64_t> n = cloud::parse_unsigned(f.file.stem().string());
      if (!n || *n >= seconds->size()) {
        warn(used + " has " + std::to_string(seconds->size()) + " lines for " +
             std::to_string(frames_.size()) + " scans; not used");
        return false;
      }
      numbers.push_back(static_cast<size_t>(*n));
    }
    for (size_t i = 0; i < frames_.size(); ++i) frames_[i].stamp_ns = stamp((*seconds)[numbers[i]]);
    return true;
  }

  /// The first readable frame tells the fields and where the times come from and, unless
  /// `known`, decides the sensor; it is kept for next(). A frame that cannot be read is skipped,
  /// and a folder without any readable frame is an error. A sensor that cannot be chosen fails at
  /// once, as it would for every frame.
  void open_first_cloud(const SourceOptions& options,
                        const std::optional<config::SensorModel>& known,
                        const std::string& unmatched_preset = "") {
    std::string last_error;
    for (size_t i = 0; i < frames_.size(); ++i) {
      const std::string origin = frames_[i].file.string();
      DecodedCloud decoded;
      try {
        decoded = cloud::decode_cloud_file(frames_[i].file, format_);
      } catch (const InputError& e) {
        last_error = e.what();
        skip_frame("frame skipped: " + last_error);
        continue;
      }
      std::string why = "from " + (folder_ / "sequence.yaml").string();
      info_.sensor =
          known ? *known : choose_sensor(decoded, options, origin, &why, unmatched_preset);
      OrganizeStats stats;
      std::vector<std::string> warnings;
      try {
        first_ =
            cloud_to_scan(decoded, info_.sensor, origin, &stats, &warnings, timing_, &info_.times);
      } catch (const InputError& e) {
        last_error = e.what();
        skip_frame("frame skipped: " + last_error);
        continue;
      }
      cloud::check_sensor_fits(stats, decoded.cloud, info_.sensor, origin);
      for (const std::string& w : decoded.warnings) warn(origin + ": " + w);
      cloud::describe(stats, &warnings, origin);
      for (const std::string& w : warnings) warn(w);
      info_.format = decoded.format;
      info_.fields = decoded.fields;
      info_.detail =
          std::to_string(frames_.size()) + " " + decoded.format + " scans, sensor " + why;
      first_stamp_ = decoded.stamp_ns;
      first_index_ = i;
      return;
    }
    throw InputError(info_.path + ": no readable scan; the last error: " + last_error);
  }

  fs::path folder_;
  SourceInfo info_;
  std::vector<Frame> frames_;
  CloudFormat format_ = CloudFormat::kPcd;
  CloudTiming timing_;
  double rate_hz_ = 10.0;
  std::unique_ptr<detail::ImuSweepAssigner> imu_;  ///< imu.csv's samples not handed out yet
  size_t next_ = 0;
  std::optional<Scan> first_;
  std::optional<int64_t> first_stamp_;
  size_t first_index_ = 0;
};

}  // namespace

std::unique_ptr<ScanSource> open_scan_folder(const std::string& path,
                                             const SourceOptions& options) {
  return std::make_unique<ScanFolderSource>(path, options);
}

}  // namespace featsense::slam
