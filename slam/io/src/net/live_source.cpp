#include "featsense/slam/io/live_source.hpp"

#include <vector>

#include "featsense/slam/io/readers.hpp"
#include "net/packet_sources.hpp"
#include "net/udp_receiver.hpp"
#include "velodyne/velodyne_packet.hpp"

namespace featsense::slam {
namespace {

constexpr int kVelodyneDataPort = 2368;

/// A feed that hands out one datagram it was given before those of another feed: the
/// Velodyne packet the model was told from.
class FirstThenFeed final : public detail::DatagramFeed {
 public:
  FirstThenFeed(std::vector<uint8_t> first, detail::UdpDatagram header,
                std::unique_ptr<detail::DatagramFeed> rest)
      : first_(std::move(first)), header_(header), rest_(std::move(rest)) {}

  std::optional<detail::UdpDatagram> next() override {
    if (given_) return rest_->next();
    given_ = true;
    header_.payload = first_.data();
    header_.size = first_.size();
    return header_;
  }
  std::optional<std::string> problem() const override { return rest_->problem(); }
  std::vector<std::string> end_warnings() const override { return rest_->end_warnings(); }
  const std::string& origin() const override { return rest_->origin(); }

 private:
  std::vector<uint8_t> first_;
  detail::UdpDatagram header_;
  std::unique_ptr<detail::DatagramFeed> rest_;
  bool given_ = false;
};

detail::UdpListenSettings listen_settings(const LiveOptions& live, std::vector<int> ports) {
  detail::UdpListenSettings s;
  s.host = live.host;
  s.ports = std::move(ports);
  s.idle_timeout_s = live.idle_timeout_s;
  s.buffer_datagrams = live.buffer_datagrams;
  s.stop_requested = live.stop_requested;
  return s;
}

std::unique_ptr<ScanSource> open_ouster_live(const LiveOptions& live,
                                             const SourceOptions& options) {
  if (!options.meta_path) {
    throw InputError("udp://" + live.host +
                     ": a live Ouster sensor needs its metadata JSON (--meta FILE, or the sensor's "
                     "address to fetch it from): the packets do not say the beams' angles");
  }
  OusterMetadata metadata = detail::read_ouster_metadata(*options.meta_path);
  const int lidar_port = live.lidar_port.value_or(metadata.udp_port_lidar);
  const int imu_port = live.imu_port.value_or(metadata.udp_port_imu);
  std::vector<int> ports = {lidar_port};
  if (options.imu && imu_port != lidar_port) ports.push_back(imu_port);
  auto feed = std::make_unique<detail::UdpReceiver>(listen_settings(live, ports));
  if (live.on_listening) live.on_listening(feed->origin());
  return detail::ouster_packet_source(std::move(feed), "ouster-live", *options.meta_path,
                                      std::move(metadata), options.imu, imu_port);
}

std::unique_ptr<ScanSource> open_velodyne_live(const LiveOptions& live,
                                               const SourceOptions& options) {
  auto feed = std::make_unique<detail::UdpReceiver>(
      listen_settings(live, {live.lidar_port.value_or(kVelodyneDataPort)}));
  if (live.on_listening) live.on_listening(feed->origin());
  // The model comes from a data packet's product id: wait for the first.
  for (;;) {
    const std::optional<detail::UdpDatagram> datagram = feed->next();
    if (!datagram) {
      throw InputError(feed->origin() + ": no Velodyne data packet (1206-byte UDP payload) " +
                       "received (" + feed->problem().value_or("ended") + ")");
    }
    if (datagram->size != kVelodynePacketBytes) continue;
    std::vector<uint8_t> first(datagram->payload, datagram->payload + datagram->size);
    const VelodyneSetup setup = velodyne_setup(first.data(), options, sensor_for, feed->origin());
    auto replaying = std::make_unique<FirstThenFeed>(std::move(first), *datagram, std::move(feed));
    return detail::velodyne_packet_source(std::move(replaying), "velodyne-live", setup);
  }
}

}  // namespace

std::unique_ptr<ScanSource> open_live_source(const LiveOptions& live,
                                             const SourceOptions& options) {
  return with_range_limits(live.sensor == LiveSensor::kOuster ? open_ouster_live(live, options)
                                                              : open_velodyne_live(live, options),
                           options);
}

}  // namespace featsense::slam
