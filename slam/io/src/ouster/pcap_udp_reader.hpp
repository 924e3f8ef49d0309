#pragma once
// UDP datagrams out of a classic pcap stream: link layer (Ethernet with VLAN tags, Linux
// cooked, raw IP, BSD loopback) -> IPv4 (fragments reassembled) -> UDP. Everything else
// (ARP, IPv6, TCP, damaged frames) is skipped and counted.

#include <cstdint>
#include <istream>
#include <optional>
#include <string>

#include "ouster/ip_reassembly.hpp"
#include "ouster/pcap_reader.hpp"

namespace featsense::slam::detail {

/// One UDP datagram; `payload` points into the reader and stays valid until its next call.
struct UdpDatagram {
  int64_t timestamp_ns = 0;  ///< capture time of its last packet, ns since the Unix epoch
  uint64_t file_offset = 0;  ///< offset of the record that completed it
  uint16_t source_port = 0;
  uint16_t destination_port = 0;
  const uint8_t* payload = nullptr;
  size_t size = 0;
};

/// What the reader skipped, by reason.
struct PcapUdpStats {
  size_t records = 0;
  size_t not_ipv4 = 0;     ///< other link-layer protocols (ARP, IPv6, ...)
  size_t not_udp = 0;      ///< IPv4 of another protocol (TCP, ICMP, ...)
  size_t malformed = 0;    ///< headers that contradict the bytes captured
  size_t fragments = 0;    ///< IPv4 fragments seen
  size_t reassembled = 0;  ///< datagrams rebuilt from fragments
  size_t datagrams = 0;    ///< UDP datagrams handed out
};

class PcapUdpReader {
 public:
  /// Reads the pcap global header; throws InputError (naming `origin`) when it is bad or the
  /// link type is one this reader does not know.
  PcapUdpReader(std::istream& in, std::string origin);

  /// The next UDP datagram, or nullopt at the end of the input (or at a truncated or corrupt
  /// record: problem() then says what and where).
  std::optional<UdpDatagram> next();

  const std::optional<std::string>& problem() const { return records_.problem(); }
  const PcapUdpStats& stats() const { return stats_; }
  /// Fragmented datagrams given up or left incomplete so far.
  size_t incomplete_datagrams() const { return reassembler_.dropped() + reassembler_.pending(); }
  uint64_t offset() const { return records_.offset(); }

 private:
  /// Where the IPv4 packet of the current record starts, or false to skip the record.
  bool find_ipv4(size_t* start) const;
  /// The UDP datagram in `ip_payload`, or nullopt (counted) when damaged.
  std::optional<UdpDatagram> udp(const uint8_t* ip_payload, size_t size);

  PcapRecordReader records_;
  PcapRecord record_;
  IpReassembler reassembler_;
  PcapUdpStats stats_;
};

}  // namespace featsense::slam::detail
