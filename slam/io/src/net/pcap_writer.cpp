#include "net/pcap_writer.hpp"

#include <algorithm>

#include "featsense/slam/io/scan_writers.hpp"
#include "ouster/byte_order.hpp"

namespace featsense::slam::detail {
namespace {

constexpr size_t kEthernetHeaderBytes = 14;
constexpr size_t kIpv4HeaderBytes = 20;  // no options
constexpr size_t kUdpHeaderBytes = 8;
constexpr size_t kMaxUdpPayload = 65535 - kIpv4HeaderBytes - kUdpHeaderBytes;
constexpr uint32_t kSnapLength = 262144;
constexpr uint32_t kLinkTypeEthernet = 1;

void put_le(std::vector<uint8_t>& out, uint32_t value, size_t bytes) {
  out.resize(out.size() + bytes);
  store_le_bytes(out.data() + out.size() - bytes, value, bytes);
}

void set_be16(std::vector<uint8_t>& b, size_t at, uint32_t value) {
  b[at] = static_cast<uint8_t>((value >> 8) & 0xFFu);
  b[at + 1] = static_cast<uint8_t>(value & 0xFFu);
}

/// RFC 791's header checksum: the ones' complement of the ones' complement sum of the
/// header's 16-bit words, the checksum field counted as zero.
void set_ipv4_checksum(std::vector<uint8_t>& b, size_t ip_at) {
  set_be16(b, ip_at + 10, 0);
  uint32_t sum = 0;
  for (size_t i = 0; i < kIpv4HeaderBytes; i += 2)
    sum += static_cast<uint32_t>((b[ip_at + i] << 8) | b[ip_at + i + 1]);
  while (sum >> 16) sum = (sum & 0xFFFFu) + (sum >> 16);
  set_be16(b, ip_at + 10, ~sum & 0xFFFFu);
}

}  // namespace

PcapWriter::PcapWriter(std::string path, PcapEndpoints endpoints)
    : path_(std::move(path)), endpoints_(endpoints), out_(path_, std::ios::binary) {
  if (!out_) throw WriteError(path_ + ": cannot open for writing");
  std::vector<uint8_t> header;
  put_le(header, 0xa1b2c3d4u, 4);  // microsecond time stamps, written little-endian
  put_le(header, 2, 2);            // version 2.4
  put_le(header, 4, 2);
  put_le(header, 0, 4);  // time zone
  put_le(header, 0, 4);  // accuracy
  put_le(header, kSnapLength, 4);
  put_le(header, kLinkTypeEthernet, 4);
  out_.write(reinterpret_cast<const char*>(header.data()),
             static_cast<std::streamsize>(header.size()));
}

void PcapWriter::add_record(int64_t time_ns, const std::vector<uint8_t>& frame) {
  const int64_t us = time_ns / 1000;
  std::vector<uint8_t> header;
  put_le(header, static_cast<uint32_t>(us / 1000000), 4);
  put_le(header, static_cast<uint32_t>(us % 1000000), 4);
  put_le(header, static_cast<uint32_t>(frame.size()), 4);
  put_le(header, static_cast<uint32_t>(frame.size()), 4);
  out_.write(reinterpret_cast<const char*>(header.data()),
             static_cast<std::streamsize>(header.size()));
  out_.write(reinterpret_cast<const char*>(frame.data()),
             static_cast<std::streamsize>(frame.size()));
}

void PcapWriter::add(int64_t time_ns, uint16_t source_port, uint16_t destination_port,
                     const uint8_t* payload, size_t size) {
  if (size > kMaxUdpPayload) {
    throw WriteError(path_ + ": a datagram of " + std::to_string(size) +
                     " bytes exceeds UDP's limit");
  }
  // The UDP datagram (header + payload) is the IPv4 payload, cut into fragments whose sizes
  // are multiples of 8 bytes (all but the last).
  std::vector<uint8_t> udp(kUdpHeaderBytes, 0);
  set_be16(udp, 0, source_port);
  set_be16(udp, 2, destination_port);
  set_be16(udp, 4, static_cast<uint32_t>(kUdpHeaderBytes + size));
  udp.insert(udp.end(), payload, payload + size);
  const size_t chunk = (endpoints_.mtu - kIpv4HeaderBytes) / 8 * 8;
  const uint16_t identification = identification_++;
  for (size_t offset = 0; offset < udp.size(); offset += chunk) {
    const size_t part = std::min(chunk, udp.size() - offset);
    const bool more = offset + part < udp.size();
    frame_.assign(kEthernetHeaderBytes + kIpv4HeaderBytes, 0);
    for (size_t i = 0; i < 6; ++i) {
      frame_[i] = static_cast<uint8_t>(0x02 + i);      // destination MAC (locally administered)
      frame_[6 + i] = static_cast<uint8_t>(0x12 + i);  // source MAC
    }
    set_be16(frame_, 12, 0x0800);  // IPv4
    const size_t ip = kEthernetHeaderBytes;
    frame_[ip] = 0x45;  // version 4, five-word header
    set_be16(frame_, ip + 2, static_cast<uint32_t>(kIpv4HeaderBytes + part));
    set_be16(frame_, ip + 4, identification);
    set_be16(frame_, ip + 6, (more ? 0x2000u : 0u) | static_cast<uint32_t>(offset / 8));
    frame_[ip + 8] = 64;  // TTL
    frame_[ip + 9] = 17;  // UDP
    std::copy(endpoints_.sender_address.begin(), endpoints_.sender_address.end(),
              frame_.begin() + static_cast<std::ptrdiff_t>(ip + 12));
    std::copy(endpoints_.receiver_address.begin(), endpoints_.receiver_address.end(),
              frame_.begin() + static_cast<std::ptrdiff_t>(ip + 16));
    set_ipv4_checksum(frame_, ip);
    frame_.insert(frame_.end(), udp.begin() + static_cast<std::ptrdiff_t>(offset),
                  udp.begin() + static_cast<std::ptrdiff_t>(offset + part));
    add_record(time_ns, frame_);
  }
  ++datagrams_;
  if (!out_) throw WriteError(path_ + ": writing failed (disk full?)");
}

void PcapWriter::finish() {
  out_.close();
  if (!out_) throw WriteError(path_ + ": writing failed (disk full?)");
}

}  // namespace featsense::slam::detail
