#include "ouster/pcap_reader.hpp"

#include <utility>

#include "featsense/slam/scan_source.hpp"
#include "ouster/byte_order.hpp"

namespace featsense::slam::detail {
namespace {

constexpr size_t kGlobalHeaderBytes = 24;
constexpr size_t kRecordHeaderBytes = 16;
constexpr uint32_t kMagicMicroseconds = 0xa1b2c3d4u;
constexpr uint32_t kMagicNanoseconds = 0xa1b23c4du;
constexpr uint32_t kMagicPcapng = 0x0a0d0d0au;

/// Reads up to `size` bytes; the count read.
size_t read_bytes(std::istream& in, uint8_t* out, size_t size) {
  // char and uint8_t share a representation; istream only reads chars.
  in.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(size));
  return static_cast<size_t>(in.gcount());
}

}  // namespace

PcapRecordReader::PcapRecordReader(std::istream& in, std::string origin)
    : in_(in), origin_(std::move(origin)) {
  uint8_t header[kGlobalHeaderBytes];
  const size_t got = read_bytes(in_, header, sizeof(header));
  offset_ = got;
  if (got < 4)
    throw InputError(origin_ + ": too short for a pcap file (" + std::to_string(got) + " bytes)");
  const uint32_t magic = load_le<uint32_t>(header);
  if (magic == kMagicMicroseconds || magic == kMagicNanoseconds) {
    swapped_ = false;
  } else if (byte_swap32(magic) == kMagicMicroseconds || byte_swap32(magic) == kMagicNanoseconds) {
    swapped_ = true;
  } else if (magic == kMagicPcapng) {
    throw InputError(origin_ +
                     ": a pcapng capture; save it as classic pcap (editcap -F pcap IN OUT)");
  } else {
    throw InputError(origin_ + ": not a pcap file (bad magic number at offset 0)");
  }
  nanoseconds_ = (swapped_ ? byte_swap32(magic) : magic) == kMagicNanoseconds;
  if (got < kGlobalHeaderBytes) {
    throw InputError(origin_ + ": pcap global header truncated (" + std::to_string(got) +
                     " of 24 bytes)");
  }
  // u16 major version in the file's byte order.
  const uint16_t major = swapped_ ? load_be<uint16_t>(header + 4) : load_le<uint16_t>(header + 4);
  if (major != 2) {
    throw InputError(origin_ + ": unsupported pcap version " + std::to_string(major) +
                     " at offset 4 (expected 2)");
  }
  // The low 16 bits name the link type; the upper ones may hold an FCS length (pcap spec).
  link_type_ = u32(header + 20) & 0xFFFFu;
}

uint32_t PcapRecordReader::u32(const uint8_t* p) const {
  return swapped_ ? load_be<uint32_t>(p) : load_le<uint32_t>(p);
}

bool PcapRecordReader::next(PcapRecord& record) {
  if (done_) return false;
  const uint64_t record_offset = offset_;
  uint8_t header[kRecordHeaderBytes];
  const size_t got = read_bytes(in_, header, sizeof(header));
  offset_ += got;
  if (got == 0) {
    done_ = true;
    return false;
  }
  const auto stop = [&](const std::string& why) {
    done_ = true;
    problem_ = origin_ + ": " + why + " at offset " + std::to_string(record_offset) +
               "; reading stops there";
    return false;
  };
  if (got < kRecordHeaderBytes) return stop("truncated record header");
  const uint32_t seconds = u32(header);
  const uint32_t fraction = u32(header + 4);
  const uint32_t captured = u32(header + 8);
  const uint32_t original = u32(header + 12);
  if (captured > kMaxRecordBytes) {
    return stop("corrupt record (claims " + std::to_string(captured) + " captured bytes)");
  }
  record.data.resize(captured);
  const size_t data_got = read_bytes(in_, record.data.data(), captured);
  offset_ += data_got;
  if (data_got < captured) {
    return stop("truncated record (" + std::to_string(data_got) + " of " +
                std::to_string(captured) + " bytes)");
  }
  record.timestamp_ns = static_cast<int64_t>(seconds) * 1000000000 +
                        static_cast<int64_t>(fraction) * (nanoseconds_ ? 1 : 1000);
  record.original_size = original;
  record.file_offset = record_offset;
  return true;
}

}  // namespace featsense::slam::detail
