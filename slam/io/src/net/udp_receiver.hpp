#pragma once
// UDP datagrams as a sensor sends them, as a DatagramFeed: sockets bound to the given ports,
// a receive thread that empties them into a bounded buffer, and next() taking from it. The
// reader never blocks the receiving: where it falls behind by a full buffer, datagrams are
// dropped and counted, never queued without bound.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "net/datagram_feed.hpp"

namespace featsense::slam::detail {

struct UdpListenSettings {
  std::string host = "0.0.0.0";  ///< local IPv4 address to listen on (0.0.0.0: every one)
  std::vector<int> ports;        ///< one socket each (1 .. 65535)
  /// next() ends the input after this long without a datagram (seconds; 0: never).
  double idle_timeout_s = 0.0;
  size_t buffer_datagrams = 16384;  ///< the bounded buffer (an OS1-128 sends 640 a second)
  /// Asked about every 0.1 s while next() waits: true ends the input (Ctrl+C).
  std::function<bool()> stop_requested;
};

/// What the receiver saw, by outcome.
struct UdpReceiveStats {
  size_t received = 0;        ///< datagrams taken off the sockets
  size_t dropped_full = 0;    ///< of those, dropped: the buffer was full
  size_t truncated = 0;       ///< of those, longer than the largest UDP payload; dropped
  size_t receive_errors = 0;  ///< socket errors other than "nothing to read"
};

class UdpReceiver final : public DatagramFeed {
 public:
  /// Binds one socket per port and starts receiving. Throws InputError naming the address
  /// and the reason where a socket cannot be bound (a port in use, a host not of this machine).
  explicit UdpReceiver(UdpListenSettings settings);
  ~UdpReceiver() override;
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  std::optional<UdpDatagram> next() override;
  std::optional<std::string> problem() const override { return ended_why_; }
  std::vector<std::string> end_warnings() const override;
  const std::string& origin() const override { return origin_; }

  UdpReceiveStats stats() const;

 private:
  struct Received {
    std::vector<uint8_t> bytes;
    int64_t timestamp_ns = 0;
    uint16_t source_port = 0;
    uint16_t destination_port = 0;
  };

  void receive_loop();
  void drain(int socket, uint16_t port, std::vector<uint8_t>& buffer);

  UdpListenSettings settings_;
  std::string origin_;
  std::vector<int> sockets_;
  std::vector<uint16_t> ports_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;

  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<Received> buffer_;
  UdpReceiveStats stats_;

  Received current_;  ///< the datagram next() handed out last
  std::optional<std::string> ended_why_;
};

}  // namespace featsense::slam::detail
