// An Ouster recording in a pcap file plus its metadata JSON, read as a stream of scans.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/ouster_frame_assembler.hpp"
#include "featsense/slam/io/readers.hpp"
#include "ouster/pcap_udp_reader.hpp"

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

std::unique_ptr<std::ifstream> open_pcap_stream(const std::string& path,
                                                std::vector<char>* buffer) {
  auto stream = std::make_unique<std::ifstream>();
  // A large stream buffer: a lidar packet is 8 to 25 KB, the default buffer far smaller.
  buffer->resize(1 << 20);
  stream->rdbuf()->pubsetbuf(buffer->data(), static_cast<std::streamsize>(buffer->size()));
  stream->open(path, std::ios::binary);
  if (!*stream) throw InputError(path + ": cannot open (missing or permission denied?)");
  return stream;
}

class OusterPcapSource final : public ScanSource {
 public:
  OusterPcapSource(const std::string& path, const fs::path& meta_path, OusterMetadata metadata)
      : stream_(open_pcap_stream(path, &stream_buffer_)),
        udp_(*stream_, path),
        assembler_(std::move(metadata)),
        path_(path),
        meta_path_(meta_path.string()) {
    const OusterMetadata& meta = assembler_.metadata();
    packet_size_ = meta.packet_size();
    info_.format = "ouster-pcap";
    info_.path = path;
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
  }

  std::optional<Scan> next() override {
    if (ended_) return std::nullopt;
    while (std::optional<detail::UdpDatagram> datagram = udp_.next()) {
      if (datagram->size != packet_size_) {
        note_other_size(*datagram);
        continue;
      }
      ++lidar_packets_;
      if (std::optional<Scan> scan = assembler_.add_packet(datagram->payload, datagram->size)) {
        return deliver(std::move(*scan));
      }
    }
    ended_ = true;
    if (udp_.problem()) warn(*udp_.problem());
    if (udp_.stats().malformed > 0) {
      warn(path_ + ": " + std::to_string(udp_.stats().malformed) +
           " IP/UDP packets were damaged or cut short by the capture's snap length; skipped");
    }
    if (udp_.incomplete_datagrams() > 0) {
      warn(path_ + ": " + std::to_string(udp_.incomplete_datagrams()) +
           " fragmented IP datagrams could not be reassembled (fragments missing)");
    }
    if (std::optional<Scan> scan = assembler_.flush()) return deliver(std::move(*scan));
    if (stats().frames_read == 0) throw InputError(no_frames_message());
    return std::nullopt;
  }

  const SourceInfo& info() const override { return info_; }

 private:
  Scan deliver(Scan scan) {
    scan.sequence = stats().frames_read;
    if (assembler_.incomplete_frames() > incomplete_seen_) {
      incomplete_seen_ = assembler_.incomplete_frames();
      warn(path_ + ": frame " + std::to_string(scan.sequence) +
           " is incomplete (columns missing from the capture are marked invalid)");
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
    if (lidar_packets_ > 0) {
      message += std::to_string(lidar_packets_) +
                 " lidar packets, but none holds a valid column, so there is no frame";
    } else {
      const OusterMetadata& meta = assembler_.metadata();
      message += "no lidar packets of " + std::to_string(packet_size_) + " bytes (" +
                 to_string(meta.profile) + ", " + std::to_string(meta.pixels_per_column) +
                 " pixels per column, as " + meta_path_ + " says)";
      if (other_sizes_.empty()) {
        message += " and no other UDP packets either";
      } else {
        message += "; UDP payloads seen:";
        for (const auto& [size, seen] : other_sizes_) {
          message += " " + std::to_string(seen.first) + " of " + std::to_string(size) +
                     " bytes (port " + std::to_string(seen.second) + ")";
        }
        message += ". Is the metadata the one of this recording?";
      }
    }
    if (udp_.problem()) message += " [" + *udp_.problem() + "]";
    return message;
  }

  static constexpr size_t kMaxSizesKept = 8;

  std::vector<char> stream_buffer_;
  std::unique_ptr<std::ifstream> stream_;
  detail::PcapUdpReader udp_;
  OusterFrameAssembler assembler_;
  std::string path_;
  std::string meta_path_;
  SourceInfo info_;
  size_t packet_size_ = 0;
  size_t lidar_packets_ = 0;
  size_t incomplete_seen_ = 0;
  bool ended_ = false;
  std::map<size_t, std::pair<size_t, uint16_t>> other_sizes_;  ///< size -> (count, port)
};

}  // namespace

std::unique_ptr<ScanSource> open_ouster_pcap(const std::string& path,
                                             const SourceOptions& options) {
  // The metadata describes this very unit, so it wins over options.sensor_preset.
  const fs::path meta_path = options.meta_path ? fs::path(*options.meta_path) : find_metadata(path);
  OusterMetadata metadata = parse_ouster_metadata(read_text_file(meta_path), meta_path.string());
  return std::make_unique<OusterPcapSource>(path, meta_path, std::move(metadata));
}

}  // namespace featsense::slam
