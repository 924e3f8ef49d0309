#pragma once
// Classic pcap files (not pcapng), read one record at a time from a stream so that memory stays
// flat however large the capture is. Both byte orders, micro- and nanosecond time stamps.

#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <vector>

namespace featsense::slam::detail {

/// One captured link-layer frame.
struct PcapRecord {
  int64_t timestamp_ns = 0;    ///< capture time, ns since the Unix epoch
  uint32_t original_size = 0;  ///< bytes on the wire (data may hold fewer: snap length)
  uint64_t file_offset = 0;    ///< byte offset of the record header in the file
  std::vector<uint8_t> data;   ///< the captured bytes
};

/// Link-layer types of pcap's LINKTYPE_ registry that the readers handle.
enum class PcapLinkType : uint32_t {
  kNull = 0,  ///< BSD loopback: u32 address family in the writer's byte order
  kEthernet = 1,
  kRaw = 101,          ///< raw IPv4 or IPv6
  kLinuxCooked = 113,  ///< Linux "any" device, SLL
  kIpv4 = 228,
  kLinuxCooked2 = 276,
};

class PcapRecordReader {
 public:
  /// The largest record accepted (libpcap's own limit); a larger length means corruption.
  static constexpr uint32_t kMaxRecordBytes = 262144;

  /// Reads the 24-byte global header. Throws InputError naming `origin` when it is missing,
  /// truncated or not a classic pcap header.
  PcapRecordReader(std::istream& in, std::string origin);

  uint32_t link_type() const { return link_type_; }
  /// Bytes consumed so far.
  uint64_t offset() const { return offset_; }

  /// Reads the next record into `record` (reusing its buffer). False at the end of the input,
  /// and also at a truncated or corrupt record, after which problem() says what and where
  /// (reading cannot resynchronise after a bad record length, so it stops there).
  bool next(PcapRecord& record);
  const std::optional<std::string>& problem() const { return problem_; }

 private:
  uint32_t u32(const uint8_t* p) const;

  std::istream& in_;
  std::string origin_;
  bool swapped_ = false;      ///< written on a host of the other byte order
  bool nanoseconds_ = false;  ///< time stamps in ns rather than us
  uint32_t link_type_ = 0;
  uint64_t offset_ = 0;
  bool done_ = false;
  std::optional<std::string> problem_;
};

}  // namespace featsense::slam::detail
