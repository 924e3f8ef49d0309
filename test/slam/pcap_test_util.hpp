#pragma once
// Builds and takes apart pcap captures for the reader tests, written here from the pcap,
// Ethernet, IPv4 and UDP specifications (independently of the reader under test).

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::test {

/// One pcap record: its time stamp and captured bytes.
struct CapturedFrame {
  uint32_t seconds = 0;
  uint32_t fraction = 0;  ///< microseconds (or nanoseconds in a nanosecond capture)
  std::vector<uint8_t> bytes;
};

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

inline void write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file) throw std::runtime_error("cannot write " + path.string());
}

inline uint32_t le32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (size_t i = 0; i < 4; ++i)
    v |= static_cast<uint32_t>(static_cast<uint8_t>(bytes[at + i])) << (8 * i);
  return v;
}

/// The records of a little-endian classic pcap (the byte order of the shared recordings).
inline std::vector<CapturedFrame> read_pcap_frames(const std::string& file) {
  if (file.size() < 24 || le32(file, 0) != 0xa1b2c3d4u) throw std::runtime_error("not a LE pcap");
  std::vector<CapturedFrame> frames;
  size_t at = 24;
  while (at + 16 <= file.size()) {
    CapturedFrame frame;
    frame.seconds = le32(file, at);
    frame.fraction = le32(file, at + 4);
    const uint32_t size = le32(file, at + 8);
    at += 16;
    if (at + size > file.size()) break;
    frame.bytes.assign(file.begin() + static_cast<std::ptrdiff_t>(at),
                       file.begin() + static_cast<std::ptrdiff_t>(at + size));
    at += size;
    frames.push_back(std::move(frame));
  }
  return frames;
}

inline void put(std::string& out, uint32_t value, size_t bytes, bool big_endian) {
  for (size_t i = 0; i < bytes; ++i) {
    const size_t shift = 8 * (big_endian ? bytes - 1 - i : i);
    out += static_cast<char>((value >> shift) & 0xFFu);
  }
}

struct PcapWriteOptions {
  uint32_t link_type = 1;  ///< Ethernet
  bool big_endian = false;
  bool nanoseconds = false;
};

/// A classic pcap holding `frames` (time stamps copied as they are).
inline std::string write_pcap(const std::vector<CapturedFrame>& frames,
                              const PcapWriteOptions& options = {}) {
  std::string out;
  const bool be = options.big_endian;
  put(out, options.nanoseconds ? 0xa1b23c4du : 0xa1b2c3d4u, 4, be);
  put(out, 2, 2, be);  // version 2.4
  put(out, 4, 2, be);
  put(out, 0, 4, be);  // time zone
  put(out, 0, 4, be);  // accuracy
  put(out, 262144, 4, be);
  put(out, options.link_type, 4, be);
  for (const CapturedFrame& frame : frames) {
    put(out, frame.seconds, 4, be);
    put(out, frame.fraction, 4, be);
    put(out, static_cast<uint32_t>(frame.bytes.size()), 4, be);
    put(out, static_cast<uint32_t>(frame.bytes.size()), 4, be);
    out.append(frame.bytes.begin(), frame.bytes.end());
  }
  return out;
}

inline uint16_t be16(const std::vector<uint8_t>& b, size_t at) {
  return static_cast<uint16_t>((b[at] << 8) | b[at + 1]);
}

inline void set_be16(std::vector<uint8_t>& b, size_t at, uint32_t value) {
  b[at] = static_cast<uint8_t>((value >> 8) & 0xFFu);
  b[at + 1] = static_cast<uint8_t>(value & 0xFFu);
}

/// The RFC 791 header checksum of an IPv4 header (its checksum field zeroed first).
inline void set_ipv4_checksum(std::vector<uint8_t>& b, size_t ip_at, size_t header_bytes) {
  set_be16(b, ip_at + 10, 0);
  uint32_t sum = 0;
  for (size_t i = 0; i < header_bytes; i += 2) sum += be16(b, ip_at + i);
  while (sum >> 16) sum = (sum & 0xFFFFu) + (sum >> 16);
  set_be16(b, ip_at + 10, ~sum & 0xFFFFu);
}

/// An Ethernet II / IPv4 / UDP frame carrying `payload` to `port` (checksum-free UDP).
inline std::vector<uint8_t> ethernet_ipv4_udp(const std::vector<uint8_t>& payload, uint16_t port,
                                              uint16_t identification) {
  std::vector<uint8_t> b(14 + 20 + 8, 0);
  for (size_t i = 0; i < 12; ++i) b[i] = static_cast<uint8_t>(0x10 + i);  // MAC addresses
  set_be16(b, 12, 0x0800);
  b[14] = 0x45;  // version 4, 5-word header
  set_be16(b, 16, static_cast<uint32_t>(20 + 8 + payload.size()));
  set_be16(b, 18, identification);
  b[22] = 64;  // TTL
  b[23] = 17;  // UDP
  const uint8_t addresses[8] = {169, 254, 0, 2, 169, 254, 0, 1};
  std::memcpy(&b[26], addresses, sizeof(addresses));
  set_ipv4_checksum(b, 14, 20);
  set_be16(b, 34, 7502);  // source port
  set_be16(b, 36, port);
  set_be16(b, 38, static_cast<uint32_t>(8 + payload.size()));
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

/// Splits an Ethernet / IPv4 frame (no VLAN tag) into IPv4 fragments of at most `mtu` bytes
/// of IP packet each (RFC 791: offsets in 8-byte units, "more fragments" on all but the last).
/// A frame that already fits is returned as it is.
inline std::vector<std::vector<uint8_t>> fragment_ipv4(const std::vector<uint8_t>& frame,
                                                       size_t mtu) {
  const size_t ip_at = 14;
  const size_t header_bytes = static_cast<size_t>(frame[ip_at] & 0x0F) * 4;
  const size_t total = be16(frame, ip_at + 2);
  if (total <= mtu) return {frame};
  const size_t payload_bytes = total - header_bytes;
  const size_t chunk = (mtu - header_bytes) / 8 * 8;
  std::vector<std::vector<uint8_t>> fragments;
  for (size_t offset = 0; offset < payload_bytes; offset += chunk) {
    const size_t size = std::min(chunk, payload_bytes - offset);
    const bool more = offset + size < payload_bytes;
    std::vector<uint8_t> f(frame.begin(),
                           frame.begin() + static_cast<std::ptrdiff_t>(ip_at + header_bytes));
    const auto from = frame.begin() + static_cast<std::ptrdiff_t>(ip_at + header_bytes + offset);
    f.insert(f.end(), from, from + static_cast<std::ptrdiff_t>(size));
    set_be16(f, ip_at + 2, static_cast<uint32_t>(header_bytes + size));
    set_be16(f, ip_at + 6, (more ? 0x2000u : 0u) | static_cast<uint32_t>(offset / 8));
    set_ipv4_checksum(f, ip_at, header_bytes);
    fragments.push_back(std::move(f));
  }
  return fragments;
}

}  // namespace featsense::test
