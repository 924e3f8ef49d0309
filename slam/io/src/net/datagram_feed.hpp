#pragma once
// Where the packet readers (Ouster, Velodyne) get their UDP datagrams from: a pcap file or a
// socket that a sensor sends to. The decoders and the scan assembly do not know which.

#include <optional>
#include <string>
#include <vector>

#include "ouster/pcap_udp_reader.hpp"

namespace featsense::slam::detail {

class DatagramFeed {
 public:
  virtual ~DatagramFeed() = default;

  /// The next datagram, or nullopt at the end of the input (the capture's end, a live
  /// stream's idle timeout or stop). Its payload stays valid until the next call.
  virtual std::optional<UdpDatagram> next() = 0;
  /// What ended the input early or damaged it, for the error of a feed without frames.
  virtual std::optional<std::string> problem() const = 0;
  /// What was skipped or lost, one line each; asked once, at the end.
  virtual std::vector<std::string> end_warnings() const = 0;
  /// A file's path or a socket's address, for messages.
  virtual const std::string& origin() const = 0;
};

}  // namespace featsense::slam::detail
