#pragma once
// Writes UDP datagrams into a classic pcap capture as they would cross an Ethernet link:
// Ethernet II, IPv4 (RFC 791; fragmented where a datagram exceeds the link's MTU, as a
// sensor's large packets are on a standard 1500-byte link) and UDP (RFC 768, checksum 0:
// "not computed", allowed over IPv4). Microsecond time stamps, the format every tool reads.

#include <array>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace featsense::slam::detail {

struct PcapEndpoints {
  std::array<uint8_t, 4> sender_address = {169, 254, 0, 2};  ///< the sensor, link-local
  std::array<uint8_t, 4> receiver_address = {169, 254, 0, 1};
  size_t mtu = 1500;  ///< largest IPv4 packet on the link, bytes
};

class PcapWriter {
 public:
  /// Creates `path`, writing the global header. Throws WriteError naming it.
  PcapWriter(std::string path, PcapEndpoints endpoints = {});

  /// One datagram sent at `time_ns` (ns since the Unix epoch) from `source_port` to
  /// `destination_port`. Throws WriteError when it is larger than UDP allows or the write fails.
  void add(int64_t time_ns, uint16_t source_port, uint16_t destination_port, const uint8_t* payload,
           size_t size);
  /// Flushes and closes; throws WriteError when anything failed (disk full).
  void finish();

  uint64_t datagrams() const { return datagrams_; }

 private:
  void add_record(int64_t time_ns, const std::vector<uint8_t>& frame);

  std::string path_;
  PcapEndpoints endpoints_;
  std::ofstream out_;
  uint16_t identification_ = 1;
  uint64_t datagrams_ = 0;
  std::vector<uint8_t> frame_;  ///< reused per record
};

}  // namespace featsense::slam::detail
