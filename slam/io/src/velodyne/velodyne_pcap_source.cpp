// A Velodyne recording in a pcap file (as VeloView and tcpdump capture it): the UDP data
// packets of 1206 bytes (port 2368 by default; position packets of 512 bytes on 8308 and
// anything else are passed over), read as a stream of scans.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/io/readers.hpp"
#include "net/packet_sources.hpp"
#include "net/pcap_datagram_feed.hpp"
#include "velodyne/velodyne_setup.hpp"

namespace featsense::slam {
namespace {

/// UDP datagrams looked at to tell a Velodyne capture from an Ouster one.
constexpr size_t kProbeDatagrams = 64;
/// A position packet (GPS time and NMEA sentence, port 8308): not data, passed over.
constexpr size_t kVelodynePositionPacketBytes = 512;

/// A Velodyne sensor's data packets, from a pcap file or from the network.
class VelodynePacketSource final : public ScanSource {
 public:
  VelodynePacketSource(std::unique_ptr<detail::DatagramFeed> feed, std::string format,
                       const VelodyneSetup& setup)
      : feed_(std::move(feed)), assembler_(make_velodyne_assembler(setup)) {
    info_.format = std::move(format);
    info_.path = feed_->origin();
    info_.sensor = setup.sensor;
    info_.sensor_from_metadata = true;
    info_.fields = velodyne_fields();
    info_.detail = setup.detail;
    info_.times = "per point, from the firing timing of the packets";
  }

  std::optional<Scan> next() override {
    for (;;) {
      if (std::optional<Scan> scan = assembler_.take()) {
        count_frame();
        return scan;
      }
      if (done_) return std::nullopt;
      const std::optional<detail::UdpDatagram> datagram = feed_->next();
      if (!datagram) {
        done_ = true;
        for (const std::string& warning : feed_->end_warnings()) warn(warning);
        if (foreign_datagrams_ > 0) warn(foreign_datagrams_message());
        if (assembler_.decoder().bad_blocks() > 0) {
          warn(std::to_string(assembler_.decoder().bad_blocks()) +
               " Velodyne data blocks with a flag or azimuth the model does not use; skipped");
        }
        assembler_.flush();
        continue;
      }
      if (datagram->size != kVelodynePacketBytes) {
        count_other(*datagram);
        continue;
      }
      if (!data_port_) data_port_ = datagram->destination_port;
      assembler_.add_packet(datagram->payload, datagram->timestamp_ns);
    }
  }

  const SourceInfo& info() const override { return info_; }

 private:
  /// A datagram of another size on the data packets' port (a second sensor of another kind,
  /// a wrong port setting) is counted; position packets and other ports' traffic are not.
  void count_other(const detail::UdpDatagram& datagram) {
    if (datagram.size == kVelodynePositionPacketBytes || !data_port_ ||
        datagram.destination_port != *data_port_) {
      return;
    }
    ++foreign_datagrams_;
    ++foreign_sizes_[datagram.size];
  }

  std::string foreign_datagrams_message() const {
    std::string sizes;
    for (const auto& [size, count] : foreign_sizes_) {
      if (!sizes.empty()) sizes += ", ";
      sizes += std::to_string(count) + " of " + std::to_string(size) + " bytes";
      if (sizes.size() > 200) break;
    }
    return feed_->origin() + ": " + std::to_string(foreign_datagrams_) +
           " datagrams on the data port " + std::to_string(*data_port_) +
           " were no Velodyne data packets (" + sizes + "); skipped";
  }

  SourceInfo info_;
  std::unique_ptr<detail::DatagramFeed> feed_;
  VelodyneScanAssembler assembler_;
  bool done_ = false;
  std::optional<uint16_t> data_port_;  ///< where the first data packet came
  size_t foreign_datagrams_ = 0;
  std::map<size_t, size_t> foreign_sizes_;
};

/// The first Velodyne data packet among the first datagrams, if any.
std::optional<std::vector<uint8_t>> first_velodyne_packet(const std::string& path) {
  detail::PcapDatagramFeed feed(path);
  for (size_t i = 0; i < kProbeDatagrams; ++i) {
    const std::optional<detail::UdpDatagram> datagram = feed.next();
    if (!datagram) break;
    if (datagram->size == kVelodynePacketBytes) {
      return std::vector<uint8_t>(datagram->payload, datagram->payload + datagram->size);
    }
  }
  return std::nullopt;
}

}  // namespace

std::unique_ptr<ScanSource> detail::velodyne_packet_source(std::unique_ptr<DatagramFeed> feed,
                                                           std::string format,
                                                           const VelodyneSetup& setup) {
  return std::make_unique<VelodynePacketSource>(std::move(feed), std::move(format), setup);
}

bool is_velodyne_pcap(const std::string& path) {
  try {
    return first_velodyne_packet(path).has_value();
  } catch (const InputError&) {
    return false;  // the Ouster reader names what is wrong with the file
  }
}

std::unique_ptr<ScanSource> open_velodyne_pcap(const std::string& path,
                                               const SourceOptions& options) {
  const std::optional<std::vector<uint8_t>> first = first_velodyne_packet(path);
  if (!first) throw InputError(path + ": no Velodyne data packet (1206-byte UDP payload)");
  return detail::velodyne_packet_source(std::make_unique<detail::PcapDatagramFeed>(path),
                                        "velodyne-pcap",
                                        velodyne_setup(first->data(), options, sensor_for, path));
}

}  // namespace featsense::slam
