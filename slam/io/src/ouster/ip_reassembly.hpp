#pragma once
// Reassembly of IPv4 datagrams split into fragments (RFC 791): fragments of one datagram share
// source, destination, identification and protocol; offsets count 8-byte units; the last
// fragment has the "more fragments" flag clear. Memory is bounded: a fixed number of datagrams
// in progress, each at most 64 KiB, and the stale ones are dropped.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace featsense::slam::detail {

/// What identifies the fragments of one datagram.
struct FragmentKey {
  uint32_t source = 0;
  uint32_t destination = 0;
  uint16_t identification = 0;
  uint8_t protocol = 0;

  bool operator==(const FragmentKey& other) const {
    return source == other.source && destination == other.destination &&
           identification == other.identification && protocol == other.protocol;
  }
};

class IpReassembler {
 public:
  struct Settings {
    size_t max_pending = 64;             ///< datagrams in progress; the oldest is dropped
    int64_t timeout_ns = 2'000'000'000;  ///< capture time after which a datagram is stale
    size_t max_fragments_per_datagram = 1024;
  };
  /// The largest IPv4 payload: a 16-bit total length less the 20-byte minimal header.
  static constexpr size_t kMaxPayloadBytes = 65535 - 20;

  IpReassembler() = default;
  explicit IpReassembler(Settings settings) : settings_(settings) {}

  /// Adds the payload of one fragment (`offset_bytes` into the datagram's payload). Returns
  /// the whole reassembled payload when this fragment completes its datagram (valid until the
  /// next call), else nullptr. Inconsistent fragments drop their datagram (counted).
  const std::vector<uint8_t>* add(const FragmentKey& key, size_t offset_bytes, bool more_fragments,
                                  const uint8_t* data, size_t size, int64_t timestamp_ns);

  /// Datagrams given up (stale, evicted, inconsistent), not counting those still pending.
  size_t dropped() const { return dropped_; }
  size_t pending() const { return pending_.size(); }
  size_t reassembled() const { return reassembled_; }

 private:
  struct Pending {
    FragmentKey key;
    int64_t first_seen_ns = 0;
    size_t total_bytes = 0;  ///< known once the last fragment arrived, else 0
    bool total_known = false;
    std::vector<uint8_t> data;  ///< grows to the furthest fragment end
    /// Received byte ranges [begin, end), sorted and merged.
    std::vector<std::pair<size_t, size_t>> ranges;
    size_t fragments = 0;
  };

  void drop_stale(int64_t now_ns);
  void drop(size_t index);
  static void add_range(std::vector<std::pair<size_t, size_t>>& ranges, size_t begin, size_t end);

  Settings settings_;
  std::vector<Pending> pending_;  ///< oldest first
  std::vector<uint8_t> completed_;
  size_t dropped_ = 0;
  size_t reassembled_ = 0;
};

}  // namespace featsense::slam::detail
