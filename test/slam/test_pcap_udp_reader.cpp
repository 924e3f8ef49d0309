// The pcap -> UDP layer on captures built in the test: link types, byte orders, VLAN tags,
// IPv4 fragments in and out of order, and damaged records.

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <sstream>

#include "featsense/slam/scan_source.hpp"
#include "ouster/ip_reassembly.hpp"
#include "ouster/pcap_udp_reader.hpp"
#include "pcap_test_util.hpp"

namespace featsense::slam {
namespace {

using detail::PcapUdpReader;
using detail::UdpDatagram;
using test::CapturedFrame;

std::vector<uint8_t> payload_of(size_t size, uint8_t seed) {
  std::vector<uint8_t> payload(size);
  for (size_t i = 0; i < size; ++i) payload[i] = static_cast<uint8_t>(seed + i * 31 + (i >> 8));
  return payload;
}

CapturedFrame frame_of(std::vector<uint8_t> bytes, uint32_t seconds = 100) {
  CapturedFrame frame;
  frame.seconds = seconds;
  frame.bytes = std::move(bytes);
  return frame;
}

struct Received {
  uint16_t port = 0;
  std::vector<uint8_t> payload;
  int64_t timestamp_ns = 0;
};

/// Everything a reader handed out and what it said about the rest.
struct Capture {
  std::vector<Received> datagrams;
  detail::PcapUdpStats stats;
  std::optional<std::string> problem;
  size_t incomplete_datagrams = 0;
};

Capture read_udp(const std::string& pcap) {
  std::istringstream in(pcap);
  PcapUdpReader reader(in, "test.pcap");
  Capture capture;
  while (std::optional<UdpDatagram> d = reader.next()) {
    capture.datagrams.push_back({d->destination_port,
                                 std::vector<uint8_t>(d->payload, d->payload + d->size),
                                 d->timestamp_ns});
  }
  capture.stats = reader.stats();
  capture.problem = reader.problem();
  capture.incomplete_datagrams = reader.incomplete_datagrams();
  return capture;
}

std::string error_of(const std::string& pcap) {
  try {
    read_udp(pcap);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PcapUdpReader, ReadsEthernetUdp) {
  const auto a = payload_of(100, 1);
  const auto b = payload_of(3000, 2);  // larger than an Ethernet MTU; captures may hold that
  std::vector<CapturedFrame> frames = {frame_of(test::ethernet_ipv4_udp(a, 7502, 1)),
                                       frame_of(test::ethernet_ipv4_udp(b, 7503, 2), 101)};
  frames[1].fraction = 250000;  // microseconds
  const Capture capture = read_udp(test::write_pcap(frames));
  const std::vector<Received>& got = capture.datagrams;
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].payload, a);
  EXPECT_EQ(got[0].port, 7502);
  EXPECT_EQ(got[1].payload, b);
  EXPECT_EQ(got[1].port, 7503);
  EXPECT_EQ(got[1].timestamp_ns, 101'250'000'000);
  EXPECT_FALSE(capture.problem.has_value());
}

TEST(PcapUdpReader, BothByteOrdersAndNanosecondStamps) {
  const auto a = payload_of(500, 3);
  std::vector<CapturedFrame> frames = {frame_of(test::ethernet_ipv4_udp(a, 7502, 1))};
  frames[0].fraction = 123456789;
  for (const bool big_endian : {false, true}) {
    test::PcapWriteOptions options;
    options.big_endian = big_endian;
    options.nanoseconds = true;
    const std::vector<Received> got = read_udp(test::write_pcap(frames, options)).datagrams;
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].payload, a);
    EXPECT_EQ(got[0].timestamp_ns, 100'123'456'789);
  }
}

TEST(PcapUdpReader, VlanTagsLinuxCookedAndRawIp) {
  const auto a = payload_of(200, 4);
  const std::vector<uint8_t> ethernet = test::ethernet_ipv4_udp(a, 7502, 9);
  const std::vector<uint8_t> ip(ethernet.begin() + 14, ethernet.end());

  // An 802.1ad outer tag and an 802.1Q inner tag between the MAC addresses and the EtherType.
  std::vector<uint8_t> tagged(ethernet.begin(), ethernet.begin() + 12);
  tagged.insert(tagged.end(), {0x88, 0xa8, 0x00, 0x05, 0x81, 0x00, 0x00, 0x06});
  tagged.insert(tagged.end(), ethernet.begin() + 12, ethernet.end());
  std::vector<Received> got = read_udp(test::write_pcap({frame_of(tagged)})).datagrams;
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, a);

  // Linux cooked (SLL): 16 bytes, protocol in the last two.
  std::vector<uint8_t> cooked(16, 0);
  cooked[14] = 0x08;
  cooked.insert(cooked.end(), ip.begin(), ip.end());
  test::PcapWriteOptions options;
  options.link_type = 113;
  got = read_udp(test::write_pcap({frame_of(cooked)}, options)).datagrams;
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, a);

  for (const uint32_t raw : {101u, 228u}) {
    options.link_type = raw;
    got = read_udp(test::write_pcap({frame_of(ip)}, options)).datagrams;
    ASSERT_EQ(got.size(), 1u) << raw;
    EXPECT_EQ(got[0].payload, a);
  }
}

TEST(PcapUdpReader, EthernetPaddingIsNotPayload) {
  // A short datagram padded to Ethernet's 60-byte minimum: the IP and UDP lengths rule.
  const auto a = payload_of(4, 5);
  std::vector<uint8_t> frame = test::ethernet_ipv4_udp(a, 7503, 1);
  frame.resize(60, 0xEE);
  const std::vector<Received> got = read_udp(test::write_pcap({frame_of(frame)})).datagrams;
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, a);
}

TEST(PcapUdpReader, SkipsOtherTrafficAndDamagedHeaders) {
  const auto a = payload_of(64, 6);
  std::vector<uint8_t> arp(42, 0);
  arp[12] = 0x08;
  arp[13] = 0x06;
  std::vector<uint8_t> tcp = test::ethernet_ipv4_udp(a, 80, 2);
  tcp[14 + 9] = 6;
  std::vector<uint8_t> long_ip = test::ethernet_ipv4_udp(a, 7502, 3);
  long_ip[14 + 2] = 0x40;  // IP total length beyond the captured bytes
  std::vector<uint8_t> long_udp = test::ethernet_ipv4_udp(a, 7502, 4);
  long_udp[14 + 20 + 4] = 0x40;  // UDP length beyond the IP payload
  std::vector<uint8_t> short_header = test::ethernet_ipv4_udp(a, 7502, 5);
  short_header[14] = 0x44;  // a 16-byte IP header cannot be
  std::vector<uint8_t> stub(10, 0);
  const Capture capture = read_udp(test::write_pcap(
      {frame_of(arp), frame_of(tcp), frame_of(long_ip), frame_of(long_udp), frame_of(short_header),
       frame_of(stub), frame_of(test::ethernet_ipv4_udp(a, 7502, 6))}));
  const std::vector<Received>& got = capture.datagrams;
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, a);
  EXPECT_EQ(capture.stats.records, 7u);
  EXPECT_EQ(capture.stats.not_ipv4, 2u);  // ARP, the stub
  EXPECT_EQ(capture.stats.not_udp, 1u);
  EXPECT_EQ(capture.stats.malformed, 3u);
}

/// Fragments of several datagrams, reordered by `order` (a permutation of fragment indices).
std::vector<CapturedFrame> fragmented(
    const std::vector<std::vector<uint8_t>>& payloads,
    const std::function<void(std::vector<CapturedFrame>&)>& order) {
  std::vector<CapturedFrame> frames;
  for (size_t k = 0; k < payloads.size(); ++k) {
    const auto frame = test::ethernet_ipv4_udp(payloads[k], 7502, static_cast<uint16_t>(100 + k));
    for (auto& fragment : test::fragment_ipv4(frame, 1500)) frames.push_back(frame_of(fragment));
  }
  order(frames);
  return frames;
}

TEST(PcapUdpReader, ReassemblesFragmentsInAnyOrder) {
  const std::vector<std::vector<uint8_t>> payloads = {payload_of(8448, 1), payload_of(24832, 2),
                                                      payload_of(1000, 3), payload_of(4000, 4)};
  const auto in_order = [](std::vector<CapturedFrame>&) {};
  const auto reversed = [](std::vector<CapturedFrame>& f) { std::reverse(f.begin(), f.end()); };
  const auto shuffled = [](std::vector<CapturedFrame>& f) {
    std::mt19937 random(7);
    std::shuffle(f.begin(), f.end(), random);
  };
  for (const auto& order : {std::function<void(std::vector<CapturedFrame>&)>(in_order),
                            std::function<void(std::vector<CapturedFrame>&)>(reversed),
                            std::function<void(std::vector<CapturedFrame>&)>(shuffled)}) {
    const Capture capture = read_udp(test::write_pcap(fragmented(payloads, order)));
    const std::vector<Received>& got = capture.datagrams;
    ASSERT_EQ(got.size(), payloads.size());
    std::vector<std::vector<uint8_t>> received;
    for (const Received& r : got) received.push_back(r.payload);
    std::vector<std::vector<uint8_t>> expected = payloads;
    std::sort(received.begin(), received.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(received, expected);
    EXPECT_EQ(capture.stats.reassembled, 3u);  // the 1000-byte one fits in one packet
    EXPECT_EQ(capture.incomplete_datagrams, 0u);
  }
}

TEST(PcapUdpReader, MissingOrDuplicateFragments) {
  const std::vector<std::vector<uint8_t>> payloads = {payload_of(8448, 1), payload_of(8448, 2)};
  // Drop the third fragment of the first datagram, duplicate one of the second.
  std::vector<CapturedFrame> frames = fragmented(payloads, [](std::vector<CapturedFrame>& f) {
    f.erase(f.begin() + 2);
    f.insert(f.begin() + 8, f[8]);
  });
  const Capture capture = read_udp(test::write_pcap(frames));
  const std::vector<Received>& got = capture.datagrams;
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, payloads[1]);
  EXPECT_EQ(capture.incomplete_datagrams, 1u);
}

TEST(IpReassembler, BoundsPendingDatagramsAndDropsStaleOnes) {
  detail::IpReassembler::Settings settings;
  settings.max_pending = 4;
  settings.timeout_ns = 1000;
  detail::IpReassembler reassembler(settings);
  const std::vector<uint8_t> chunk(16, 1);
  // First fragments of ten datagrams: only four are kept.
  for (uint16_t id = 0; id < 10; ++id) {
    detail::FragmentKey key{1, 2, id, 17};
    EXPECT_EQ(reassembler.add(key, 0, true, chunk.data(), chunk.size(), 0), nullptr);
  }
  EXPECT_EQ(reassembler.pending(), 4u);
  EXPECT_EQ(reassembler.dropped(), 6u);
  // Datagram 9 completes; then time passes and the rest go stale.
  detail::FragmentKey nine{1, 2, 9, 17};
  const std::vector<uint8_t>* whole = reassembler.add(nine, 16, false, chunk.data(), 8, 10);
  ASSERT_NE(whole, nullptr);
  EXPECT_EQ(whole->size(), 24u);
  detail::FragmentKey late{1, 2, 50, 17};
  reassembler.add(late, 0, true, chunk.data(), chunk.size(), 5000);
  EXPECT_EQ(reassembler.pending(), 1u);
  EXPECT_EQ(reassembler.dropped(), 9u);
}

TEST(IpReassembler, RejectsFragmentsBeyondTheIpv4Limit) {
  detail::IpReassembler reassembler;
  const std::vector<uint8_t> chunk(1480, 1);
  detail::FragmentKey key{1, 2, 3, 17};
  // Offset 8191 * 8 plus 1480 bytes would exceed 65,535.
  EXPECT_EQ(reassembler.add(key, 8191 * 8, false, chunk.data(), chunk.size(), 0), nullptr);
  EXPECT_EQ(reassembler.pending(), 0u);
  EXPECT_EQ(reassembler.dropped(), 1u);
  // Two "last" fragments that disagree about the end.
  reassembler.add(key, 1480, false, chunk.data(), chunk.size(), 0);
  EXPECT_EQ(reassembler.add(key, 1480, false, chunk.data(), 100, 0), nullptr);
  EXPECT_EQ(reassembler.pending(), 0u);
}

TEST(PcapUdpReader, BadGlobalHeaders) {
  EXPECT_NE(error_of("").find("too short for a pcap"), std::string::npos);
  EXPECT_NE(error_of("GARBAGE GARBAGE GARBAGE GARBAGE").find("not a pcap file"), std::string::npos);
  const std::string good = test::write_pcap({});
  EXPECT_NE(error_of(good.substr(0, 10)).find("global header truncated"), std::string::npos);
  std::string pcapng = good;
  pcapng[0] = 0x0a, pcapng[1] = 0x0d, pcapng[2] = 0x0d, pcapng[3] = 0x0a;
  EXPECT_NE(error_of(pcapng).find("pcapng"), std::string::npos);
  test::PcapWriteOptions options;
  options.link_type = 147;  // a user-defined link type
  EXPECT_NE(error_of(test::write_pcap({}, options)).find("link type 147"), std::string::npos);
  std::string version = good;
  version[4] = 9;
  EXPECT_NE(error_of(version).find("version 9"), std::string::npos);
  // A header alone is a valid, empty capture.
  EXPECT_EQ(error_of(good), "");
}

TEST(PcapUdpReader, TruncatedAndCorruptRecordsStopWithAProblem) {
  const std::string pcap =
      test::write_pcap({frame_of(test::ethernet_ipv4_udp(payload_of(300, 1), 7502, 1)),
                        frame_of(test::ethernet_ipv4_udp(payload_of(300, 2), 7502, 2))});
  const size_t second_record = 24 + 16 + 342;
  for (const size_t cut : {second_record + 5, second_record + 16, second_record + 100}) {
    const Capture capture = read_udp(pcap.substr(0, cut));
    const std::vector<Received>& got = capture.datagrams;
    EXPECT_EQ(got.size(), 1u) << cut;
    ASSERT_TRUE(capture.problem.has_value()) << cut;
    EXPECT_NE(capture.problem->find("truncated record"), std::string::npos);
    EXPECT_NE(capture.problem->find("offset " + std::to_string(second_record)), std::string::npos)
        << *capture.problem;
  }
  std::string corrupt = pcap;
  corrupt[second_record + 8 + 3] = 0x7F;  // captured length of the second record ~2 GB
  const Capture capture = read_udp(corrupt);
  EXPECT_EQ(capture.datagrams.size(), 1u);
  ASSERT_TRUE(capture.problem.has_value());
  EXPECT_NE(capture.problem->find("corrupt record"), std::string::npos);
}

}  // namespace
}  // namespace featsense::slam
