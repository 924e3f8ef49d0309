#pragma once
/// Scans from a sensor on the network, as it sends them: the same decoding and scan cutting
/// as its pcap reader (readers.hpp), fed by UDP sockets. A receive thread empties the sockets
/// into a bounded buffer, so a reader that falls behind loses counted datagrams, never memory.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

enum class LiveSensor { kOuster, kVelodyne };

struct LiveOptions {
  LiveSensor sensor = LiveSensor::kOuster;
  std::string host = "0.0.0.0";  ///< local IPv4 address to listen on (0.0.0.0: every one)
  /// Lidar data: Ouster's udp_port_lidar from the metadata (7502), Velodyne's 2368.
  std::optional<int> lidar_port;
  /// Ouster IMU packets: the metadata's udp_port_imu (7503).
  std::optional<int> imu_port;
  /// The input ends after this long without a datagram (seconds; 0: only a stop ends it).
  double idle_timeout_s = 0.0;
  size_t buffer_datagrams = 16384;  ///< datagrams held for the reader at most
  /// Polled about every 0.1 s while waiting for datagrams: true ends the input.
  std::function<bool()> stop_requested;
  /// Called once the sockets are bound, with their address ("udp://0.0.0.0:7502,7503"):
  /// datagrams sent from then on are received. (A Velodyne opener then waits for a packet.)
  std::function<void(const std::string& address)> on_listening;
};

/// Listens for `live.sensor`'s packets. Ouster: the metadata JSON is options.meta_path
/// (required: the packets do not describe the sensor). Velodyne: the model is told from the
/// first data packet (next() waits for it), the calibration and scan cut as for a pcap.
/// Throws InputError where a port cannot be listened on or the metadata cannot be read; a
/// sensor that sends nothing before the idle timeout ends with the readers' "no packets" error.
/// The scans have the range limits of open_scan_source().
std::unique_ptr<ScanSource> open_live_source(const LiveOptions& live, const SourceOptions& options);

}  // namespace featsense::slam
