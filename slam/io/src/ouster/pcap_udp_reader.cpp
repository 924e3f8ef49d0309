#include "ouster/pcap_udp_reader.hpp"

#include <utility>

#include "featsense/slam/scan_source.hpp"
#include "ouster/byte_order.hpp"

namespace featsense::slam::detail {
namespace {

constexpr uint16_t kEtherTypeIpv4 = 0x0800;
constexpr uint16_t kEtherTypeVlan = 0x8100;  // 802.1Q
constexpr uint16_t kEtherTypeQinQ = 0x88a8;  // 802.1ad
constexpr uint16_t kEtherTypeQinQLegacy = 0x9100;
constexpr size_t kEthernetHeaderBytes = 14;
constexpr size_t kVlanTagBytes = 4;
constexpr size_t kLinuxCookedHeaderBytes = 16;   // protocol in bytes 14..15
constexpr size_t kLinuxCooked2HeaderBytes = 20;  // protocol in bytes 0..1
constexpr size_t kNullHeaderBytes = 4;
constexpr uint32_t kAddressFamilyInet = 2;
constexpr size_t kIpv4MinHeaderBytes = 20;
constexpr uint8_t kProtocolUdp = 17;
constexpr size_t kUdpHeaderBytes = 8;
constexpr uint16_t kMoreFragments = 0x2000;
constexpr uint16_t kFragmentOffsetMask = 0x1FFF;

bool known_link_type(uint32_t link_type) {
  switch (static_cast<PcapLinkType>(link_type)) {
    case PcapLinkType::kNull:
    case PcapLinkType::kEthernet:
    case PcapLinkType::kRaw:
    case PcapLinkType::kLinuxCooked:
    case PcapLinkType::kIpv4:
    case PcapLinkType::kLinuxCooked2:
      return true;
  }
  return false;
}

}  // namespace

PcapUdpReader::PcapUdpReader(std::istream& in, std::string origin) : records_(in, origin) {
  if (!known_link_type(records_.link_type())) {
    throw InputError(origin + ": pcap link type " + std::to_string(records_.link_type()) +
                     " is not supported (Ethernet, Linux cooked, raw IPv4 or loopback captures)");
  }
}

bool PcapUdpReader::find_ipv4(size_t* start) const {
  const std::vector<uint8_t>& d = record_.data;
  const size_t n = d.size();
  switch (static_cast<PcapLinkType>(records_.link_type())) {
    case PcapLinkType::kEthernet: {
      if (n < kEthernetHeaderBytes) return false;
      size_t type_at = 12;
      uint16_t type = load_be<uint16_t>(&d[type_at]);
      while (type == kEtherTypeVlan || type == kEtherTypeQinQ || type == kEtherTypeQinQLegacy) {
        type_at += kVlanTagBytes;
        if (type_at + 2 > n) return false;
        type = load_be<uint16_t>(&d[type_at]);
      }
      *start = type_at + 2;
      return type == kEtherTypeIpv4;
    }
    case PcapLinkType::kLinuxCooked:
      *start = kLinuxCookedHeaderBytes;
      return n >= kLinuxCookedHeaderBytes && load_be<uint16_t>(&d[14]) == kEtherTypeIpv4;
    case PcapLinkType::kLinuxCooked2:
      *start = kLinuxCooked2HeaderBytes;
      return n >= kLinuxCooked2HeaderBytes && load_be<uint16_t>(&d[0]) == kEtherTypeIpv4;
    case PcapLinkType::kNull: {
      if (n < kNullHeaderBytes) return false;
      // The family is in the writer's byte order, which the file does not say: try both.
      const uint32_t family = load_le<uint32_t>(&d[0]);
      *start = kNullHeaderBytes;
      return family == kAddressFamilyInet || byte_swap32(family) == kAddressFamilyInet;
    }
    case PcapLinkType::kRaw:
    case PcapLinkType::kIpv4:
      *start = 0;
      return n >= 1 && (d[0] >> 4) == 4;
  }
  return false;
}

std::optional<UdpDatagram> PcapUdpReader::udp(const uint8_t* ip_payload, size_t size) {
  if (size < kUdpHeaderBytes) {
    ++stats_.malformed;
    return std::nullopt;
  }
  const size_t udp_length = load_be<uint16_t>(ip_payload + 4);
  // The UDP length covers header and payload; it may be shorter than the IP payload (padding),
  // never longer.
  if (udp_length < kUdpHeaderBytes || udp_length > size) {
    ++stats_.malformed;
    return std::nullopt;
  }
  UdpDatagram datagram;
  datagram.timestamp_ns = record_.timestamp_ns;
  datagram.file_offset = record_.file_offset;
  datagram.source_port = load_be<uint16_t>(ip_payload);
  datagram.destination_port = load_be<uint16_t>(ip_payload + 2);
  datagram.payload = ip_payload + kUdpHeaderBytes;
  datagram.size = udp_length - kUdpHeaderBytes;
  ++stats_.datagrams;
  return datagram;
}

std::optional<UdpDatagram> PcapUdpReader::next() {
  while (records_.next(record_)) {
    ++stats_.records;
    size_t start = 0;
    if (!find_ipv4(&start)) {
      ++stats_.not_ipv4;
      continue;
    }
    const uint8_t* ip = record_.data.data() + start;
    const size_t available = record_.data.size() - start;
    if (available < kIpv4MinHeaderBytes || (ip[0] >> 4) != 4) {
      ++stats_.not_ipv4;
      continue;
    }
    const size_t header_bytes = static_cast<size_t>(ip[0] & 0x0F) * 4;
    const size_t total_bytes = load_be<uint16_t>(ip + 2);
    // A total length beyond the captured bytes means the capture cut the packet (snap
    // length); shorter is Ethernet padding, which is dropped.
    if (header_bytes < kIpv4MinHeaderBytes || total_bytes < header_bytes ||
        total_bytes > available) {
      ++stats_.malformed;
      continue;
    }
    // Checksums are not verified: captures taken on the sending host hold packets whose
    // checksums the network card fills in later, so they look wrong in the file.
    const uint8_t protocol = ip[9];
    const uint16_t flags_offset = load_be<uint16_t>(ip + 6);
    const uint8_t* payload = ip + header_bytes;
    const size_t payload_bytes = total_bytes - header_bytes;
    const bool more_fragments = (flags_offset & kMoreFragments) != 0;
    const size_t fragment_offset = static_cast<size_t>(flags_offset & kFragmentOffsetMask) * 8;
    if (more_fragments || fragment_offset != 0) {
      ++stats_.fragments;
      FragmentKey key;
      key.source = load_be<uint32_t>(ip + 12);
      key.destination = load_be<uint32_t>(ip + 16);
      key.identification = load_be<uint16_t>(ip + 4);
      key.protocol = protocol;
      const std::vector<uint8_t>* whole = reassembler_.add(
          key, fragment_offset, more_fragments, payload, payload_bytes, record_.timestamp_ns);
      if (whole == nullptr) continue;
      ++stats_.reassembled;
      if (protocol != kProtocolUdp) {
        ++stats_.not_udp;
        continue;
      }
      if (std::optional<UdpDatagram> datagram = udp(whole->data(), whole->size())) return datagram;
      continue;
    }
    if (protocol != kProtocolUdp) {
      ++stats_.not_udp;
      continue;
    }
    if (std::optional<UdpDatagram> datagram = udp(payload, payload_bytes)) return datagram;
  }
  return std::nullopt;
}

}  // namespace featsense::slam::detail
