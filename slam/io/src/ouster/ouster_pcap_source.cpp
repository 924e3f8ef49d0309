// An Ouster recording in a pcap file plus its metadata JSON, read as a stream of scans.

#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/ouster_frame_assembler.hpp"
#include "featsense/slam/io/readers.hpp"
#include "imu_sweep_assigner.hpp"
#include "net/packet_sources.hpp"
#include "net/pcap_datagram_feed.hpp"
#include "ouster/ouster_imu_packet.hpp"
#include "ouster/ouster_packet.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

std::string read_text_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open the metadata file");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

size_t common_prefix_length(const std::string& a, const std::string& b) {
  const auto mismatch = std::mismatch(
      a.begin(), a.begin() + static_cast<std::ptrdiff_t>(std::min(a.size(), b.size())), b.begin());
  return static_cast<size_t>(mismatch.first - a.begin());
}

/// The .json beside the pcap whose file name shares the longest prefix with the pcap's name.
fs::path find_metadata(const fs::path& pcap) {
  const fs::path folder = pcap.has_parent_path() ? pcap.parent_path() : fs::path(".");
  const std::string pcap_name = pcap.filename().string();
  std::vector<fs::path> best;
  size_t best_length = 0;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() != ".json" || !entry.is_regular_file(ec)) continue;
    const size_t length = common_prefix_length(entry.path().filename().string(), pcap_name);
    if (best.empty() || length > best_length) {
      best = {entry.path()};
      best_length = length;
    } else if (length == best_length) {
      best.push_back(entry.path());
    }
  }
  if (best.empty()) {
    throw InputError(pcap.string() + ": no Ouster metadata found (looked for a .json file in " +
                     folder.string() + " whose name shares a prefix with " + pcap_name +
                     "); pass it with --meta FILE");
  }
  if (best.size() > 1) {
    std::sort(best.begin(), best.end());
    std::string names;
    for (const fs::path& p : best) names += " " + p.filename().string();
    throw InputError(pcap.string() + ": several metadata files match equally well (" +
                     names.substr(1) + "); pass one with --meta FILE");
  }
  return best.front();
}

/// An Ouster sensor's packets, from a pcap file or from the network.
class OusterPacketSource final : public ScanSource {
 public:
  /// `imu_port`: the port the IMU packets arrive on (else the metadata's udp_port_imu).
  OusterPacketSource(std::unique_ptr<detail::DatagramFeed> feed, std::string format,
                     const fs::path& meta_path, OusterMetadata metadata, bool read_imu,
                     std::optional<int> imu_port = std::nullopt)
      : feed_(std::move(feed)),
        assembler_(std::move(metadata)),
        imu_(detail::sweep_duration_ns(assembler_.metadata().rate_hz)),
        read_imu_(read_imu),
        path_(feed_->origin()),
        meta_path_(meta_path.string()) {
    const OusterMetadata& meta = assembler_.metadata();
    packet_size_ = meta.packet_size();
    imu_port_ = imu_port.value_or(meta.udp_port_imu);
    imu_to_sensor_ = detail::ouster_imu_to_sensor_rotation(meta);
    info_.format = std::move(format);
    info_.path = path_;
    info_.sensor = meta.sensor_model();
    try {
      info_.sensor.validate();
    } catch (const config::ConfigError& e) {
      throw InputError(meta_path_ + ": " + e.what());
    }
    info_.sensor_from_metadata = true;
    info_.fields = {"x", "y", "z", "range", "t", "reflectivity", "nir"};
    if (meta.profile != OusterProfile::kRng15Rfl8Nir8) info_.fields.push_back("signal");
    info_.detail = meta.prod_line + " " + meta.lidar_mode + " " + to_string(meta.profile);
    info_.times = "per column, from the lidar packets' timestamps";
    if (read_imu_) {
      info_.imu = "the IMU packets on UDP port " + std::to_string(imu_port_) +
                  ", turned into the sensor frame by the metadata's imu_to_sensor_transform";
    }
  }

  std::optional<Scan> next() override {
    for (;;) {
      // A completed frame waits until the IMU's samples of its sweep have come (they may
      // follow the next frame's first lidar packet), at most until the next frame completes.
      if (!pending_.empty() && (ended_ || !read_imu_ || imu_.received() == 0 ||
                                pending_.size() > 1 || imu_.covers(pending_.front()))) {
        Scan scan = std::move(pending_.front());
        pending_.pop_front();
        return deliver(std::move(scan));
      }
      if (ended_) {
        if (stats().frames_read == 0) throw InputError(no_frames_message());
        if (!imu_checked_) {
          imu_checked_ = true;
          const std::string mismatch = detail::clock_mismatch_warning(imu_, path_);
          if (!mismatch.empty()) warn(mismatch);
        }
        return std::nullopt;
      }
      read_datagram();
    }
  }

  const SourceInfo& info() const override { return info_; }

 private:
  /// Reads one UDP datagram: a lidar packet goes to the assembler (a completed frame to
  /// pending_), an IMU packet to the IMU's samples; at the end of the capture the frame in
  /// progress completes.
  void read_datagram() {
    std::optional<detail::UdpDatagram> datagram = feed_->next();
    if (!datagram) {
      end_of_capture();
      return;
    }
    if (datagram->size == packet_size_) {
      if (!from_this_sensor(datagram->payload, datagram->size)) return;
      ++lidar_packets_;
      if (std::optional<Scan> scan = assembler_.add_packet(datagram->payload, datagram->size)) {
        pending_.push_back(std::move(*scan));
      }
      return;
    }
    if (read_imu_ && datagram->destination_port == imu_port_) {
      if (std::optional<ImuSample> sample =
              detail::decode_ouster_imu_packet(datagram->payload, datagram->size, imu_to_sensor_)) {
        imu_.add(*sample);
        return;
      }
      ++malformed_imu_packets_;
    }
    note_other_size(*datagram);
  }

  /// False (counted) for a packet of another unit than the metadata's: its serial number
  /// differs. The same unit initialized again since the metadata was written is warned of
  /// once and read: a packet of the expected size has the layout the metadata describes.
  bool from_this_sensor(const uint8_t* payload, size_t size) {
    const OusterMetadata& meta = assembler_.metadata();
    const std::optional<detail::OusterPacketSender> sender =
        detail::ouster_packet_sender(meta.profile, payload, size);
    if (!sender) return true;
    if (meta.serial && sender->serial != *meta.serial) {
      if (foreign_packets_++ == 0) foreign_serial_ = sender->serial;
      return false;
    }
    if (meta.initialization_id && sender->initialization_id != *meta.initialization_id &&
        !reinitialized_warned_) {
      reinitialized_warned_ = true;
      warn(path_ + ": the packets' initialization id " + std::to_string(sender->initialization_id) +
           " is not the metadata's (" + std::to_string(*meta.initialization_id) + ", " +
           meta_path_ +
           "): the sensor was initialized again since; read with this metadata (fetch it "
           "again if its mode or profile changed)");
    }
    return true;
  }

  std::string foreign_packets_text() const {
    return std::to_string(foreign_packets_) + " lidar packets from another sensor (serial " +
           std::to_string(foreign_serial_) + ") than the metadata's (serial " +
           std::to_string(assembler_.metadata().serial.value_or(0)) + ", " + meta_path_ + ")";
  }

  void end_of_capture() {
    ended_ = true;
    for (const std::string& warning : feed_->end_warnings()) warn(warning);
    if (foreign_packets_ > 0 && lidar_packets_ > 0)
      warn(path_ + ": " + foreign_packets_text() + "; skipped");
    if (malformed_imu_packets_ > 0) {
      warn(path_ + ": " + std::to_string(malformed_imu_packets_) + " packets on the IMU port " +
           std::to_string(imu_port_) + " were not " +
           std::to_string(detail::kOusterImuPacketBytes) +
           "-byte IMU packets of finite values; skipped");
    }
    if (std::optional<Scan> scan = assembler_.flush()) pending_.push_back(std::move(*scan));
  }

  Scan deliver(Scan scan) {
    scan.sequence = stats().frames_read;
    if (read_imu_) imu_.attach(scan);
    if (assembler_.incomplete_frames() > incomplete_seen_) {
      incomplete_seen_ = assembler_.incomplete_frames();
      warn(path_ + ": frame " + std::to_string(scan.sequence) +
           " is incomplete (the columns whose packets did not come are marked invalid)");
    }
    count_frame();
    return scan;
  }

  /// Remembers the sizes of other UDP payloads (IMU, other sensors) for the error message.
  void note_other_size(const detail::UdpDatagram& datagram) {
    auto it = other_sizes_.find(datagram.size);
    if (it != other_sizes_.end()) {
      ++it->second.first;
    } else if (other_sizes_.size() < kMaxSizesKept) {
      other_sizes_[datagram.size] = {1, datagram.destination_port};
    }
  }

  std::string no_frames_message() const {
    std::string message = path_ + ": ";
    if (lidar_packets_ == 0 && foreign_packets_ > 0) {
      message += "all " + foreign_packets_text() + ": is the metadata this sensor's?";
    } else if (lidar_packets_ > 0) {
      message += std::to_string(lidar_packets_) +
                 " lidar packets, but none holds a valid column, so there is no frame";
    } else {
      const OusterMetadata& meta = assembler_.metadata();
      message += "no lidar packets of " + std::to_string(packet_size_) + " bytes (" +
                 to_string(meta.profile) + ", " + std::to_string(meta.pixels_per_column) +
                 " pixels per column, as " + meta_path_ + " says)";
      const size_t imu_packets = imu_.received() + malformed_imu_packets_;
      if (other_sizes_.empty() && imu_packets == 0) {
        message += " and no other UDP packets either";
      } else {
        message += "; UDP payloads seen:";
        if (imu_packets > 0) {
          message += " " + std::to_string(imu_packets) + " IMU packets (port " +
                     std::to_string(imu_port_) + ")";
        }
        for (const auto& [size, seen] : other_sizes_) {
          message += " " + std::to_string(seen.first) + " of " + std::to_string(size) +
                     " bytes (port " + std::to_string(seen.second) + ")";
        }
        message += ". Is the metadata the one of this recording?";
      }
    }
    if (feed_->problem()) message += " [" + *feed_->problem() + "]";
    return message;
  }

  static constexpr size_t kMaxSizesKept = 8;

  std::unique_ptr<detail::DatagramFeed> feed_;
  OusterFrameAssembler assembler_;
  std::deque<Scan> pending_;  ///< completed frames not handed out yet
  detail::ImuSweepAssigner imu_;
  bool read_imu_ = true;
  int imu_port_ = 0;
  Eigen::Matrix3d imu_to_sensor_ = Eigen::Matrix3d::Identity();
  size_t malformed_imu_packets_ = 0;
  std::string path_;
  std::string meta_path_;
  SourceInfo info_;
  size_t packet_size_ = 0;
  size_t lidar_packets_ = 0;
  size_t foreign_packets_ = 0;   ///< of the right size, from another unit
  uint64_t foreign_serial_ = 0;  ///< the first such unit's serial number
  bool reinitialized_warned_ = false;
  size_t incomplete_seen_ = 0;
  bool ended_ = false;
  bool imu_checked_ = false;
  std::map<size_t, std::pair<size_t, uint16_t>> other_sizes_;  ///< size -> (count, port)
};

}  // namespace

namespace detail {

std::unique_ptr<ScanSource> ouster_packet_source(std::unique_ptr<DatagramFeed> feed,
                                                 std::string format,
                                                 const std::filesystem::path& meta_path,
                                                 OusterMetadata metadata, bool read_imu,
                                                 std::optional<int> imu_port) {
  return std::make_unique<OusterPacketSource>(std::move(feed), std::move(format), meta_path,
                                              std::move(metadata), read_imu, imu_port);
}

OusterMetadata read_ouster_metadata(const std::filesystem::path& path) {
  return parse_ouster_metadata(read_text_file(path), path.string());
}

}  // namespace detail

std::unique_ptr<ScanSource> open_ouster_pcap(const std::string& path,
                                             const SourceOptions& options) {
  // The metadata describes this very unit, so it wins over options.sensor_preset.
  const fs::path meta_path = options.meta_path ? fs::path(*options.meta_path) : find_metadata(path);
  return detail::ouster_packet_source(std::make_unique<detail::PcapDatagramFeed>(path),
                                      "ouster-pcap", meta_path,
                                      detail::read_ouster_metadata(meta_path), options.imu);
}

}  // namespace featsense::slam
