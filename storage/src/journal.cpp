#include "journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "chunk_codec.hpp"
#include "file_ops.hpp"

namespace featsense::storage::detail {

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the journal is little-endian");

constexpr std::array<char, 8> kFileMagic = {'F', 'S', 'J', 'R', 'N', 'L', '0', '1'};
constexpr uint32_t kRecordMagic = 0x4B4E4843u;  // "CHNK" in little-endian bytes
/// A record's payload is at most a compressed chunk (zlib's bound on 1 MiB), a trajectory, a
/// keyframe or a sessions table; anything larger is a torn or foreign size field.
constexpr uint32_t kMaxPayload = 1u << 30;

struct RecordHeader {
  uint32_t magic = kRecordMagic;
  uint32_t type = 0;
  int32_t x = 0, y = 0, z = 0;
  uint32_t payload_size = 0;
};
static_assert(sizeof(RecordHeader) == 24, "packed record header");

}  // namespace

Journal::Journal(const std::filesystem::path& path, bool writable, bool truncate)
    : path_(path), writable_(writable) {
  if (!writable && !std::filesystem::exists(path)) return;  // reads as empty
  const bool existed = std::filesystem::exists(path);
  const int flags = writable ? (O_RDWR | O_CREAT | (truncate ? O_TRUNC : 0)) : O_RDONLY;
  fd_ = ::open(path.c_str(), flags | O_CLOEXEC, 0644);
  if (fd_ < 0) throw_errno("cannot open the journal", path);
  const off_t file_size = ::lseek(fd_, 0, SEEK_END);
  if (file_size < 0) throw_errno("cannot seek in the journal", path);
  if (file_size == 0) {
    if (writable_) {
      write_all(kFileMagic.data(), kFileMagic.size(), 0);
      sync();
      if (!existed) sync_directory(path.parent_path());
    }
    end_ = writable_ ? kFileMagic.size() : 0;
    return;
  }
  std::array<char, 8> magic{};
  if (file_size < static_cast<off_t>(magic.size()) ||
      ::pread(fd_, magic.data(), magic.size(), 0) != static_cast<ssize_t>(magic.size()) ||
      magic != kFileMagic) {
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error("not a featsense map journal: " + path.string());
  }
  end_ = kFileMagic.size();
}

Journal::~Journal() {
  if (fd_ >= 0) ::close(fd_);
}

std::vector<JournalRecord> Journal::replay() {
  std::vector<JournalRecord> records;
  if (fd_ < 0) return records;
  const off_t file_size = ::lseek(fd_, 0, SEEK_END);
  if (file_size < 0) throw_errno("cannot seek in the journal", path_);
  uint64_t position = kFileMagic.size();
  std::vector<uint8_t> payload;
  while (true) {
    RecordHeader header;
    if (position + sizeof(header) + 4 > static_cast<uint64_t>(file_size)) break;
    if (::pread(fd_, &header, sizeof(header), static_cast<off_t>(position)) !=
        static_cast<ssize_t>(sizeof(header)))
      break;
    if (header.magic != kRecordMagic || header.payload_size > kMaxPayload ||
        header.type < static_cast<uint32_t>(RecordType::kChunk) ||
        header.type > static_cast<uint32_t>(RecordType::kSessions))
      break;
    const uint64_t payload_offset = position + sizeof(header);
    const uint64_t record_end = payload_offset + header.payload_size + 4;
    if (record_end > static_cast<uint64_t>(file_size)) break;  // torn: cut short
    payload.resize(header.payload_size);
    uint32_t stored_crc = 0;
    if (::pread(fd_, payload.data(), payload.size(), static_cast<off_t>(payload_offset)) !=
            static_cast<ssize_t>(payload.size()) ||
        ::pread(fd_, &stored_crc, 4, static_cast<off_t>(payload_offset + header.payload_size)) != 4)
      break;
    uint32_t crc = crc32_update(0, &header, sizeof(header));
    crc = crc32_update(crc, payload.data(), payload.size());
    if (crc != stored_crc) break;  // torn: partly written
    records.push_back({static_cast<RecordType>(header.type),
                       {header.x, header.y, header.z},
                       payload_offset,
                       header.payload_size});
    position = record_end;
  }
  end_ = position;
  if (writable_ && static_cast<uint64_t>(file_size) != end_) {
    // New records must follow the last valid one, or a later replay would stop before them.
    if (::ftruncate(fd_, static_cast<off_t>(end_)) != 0)
      throw_errno("cannot truncate the journal", path_);
    sync();
  }
  return records;
}

void Journal::write_all(const void* data, std::size_t size, uint64_t offset) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t written = ::pwrite(fd_, bytes, size, static_cast<off_t>(offset));
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) {
      if (written == 0) errno = ENOSPC;
      throw_errno("cannot write the journal", path_);
    }
    bytes += written;
    size -= static_cast<std::size_t>(written);
    offset += static_cast<uint64_t>(written);
  }
}

uint64_t Journal::append(RecordType type, const ChunkKey& key,
                         const std::vector<uint8_t>& payload) {
  if (!writable_) throw std::runtime_error("the journal is read-only: " + path_.string());
  RecordHeader header;
  header.type = static_cast<uint32_t>(type);
  header.x = key.x;
  header.y = key.y;
  header.z = key.z;
  header.payload_size = static_cast<uint32_t>(payload.size());
  uint32_t crc = crc32_update(0, &header, sizeof(header));
  crc = crc32_update(crc, payload.data(), payload.size());
  // One buffer, one write: fewer system calls, and a torn record is still caught by its CRC.
  std::vector<uint8_t> record(sizeof(header) + payload.size() + 4);
  std::memcpy(record.data(), &header, sizeof(header));
  if (!payload.empty()) std::memcpy(record.data() + sizeof(header), payload.data(), payload.size());
  std::memcpy(record.data() + sizeof(header) + payload.size(), &crc, 4);
  try {
    write_all(record.data(), record.size(), end_);
  } catch (...) {
    // Leave no partial record behind a failed write (disk full); best effort.
    if (::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
    }
    throw;
  }
  const uint64_t payload_offset = end_ + sizeof(header);
  end_ += record.size();
  return payload_offset;
}

void Journal::sync() {
  if (fd_ >= 0 && writable_ && ::fdatasync(fd_) != 0) throw_errno("cannot sync the journal", path_);
}

std::vector<uint8_t> Journal::read_payload(uint64_t offset, uint32_t size) const {
  std::vector<uint8_t> payload(size);
  if (size > 0 &&
      ::pread(fd_, payload.data(), size, static_cast<off_t>(offset)) != static_cast<ssize_t>(size))
    throw_errno("cannot read the journal", path_);
  return payload;
}

void Journal::reset() {
  if (!writable_) throw std::runtime_error("the journal is read-only: " + path_.string());
  if (::ftruncate(fd_, static_cast<off_t>(kFileMagic.size())) != 0)
    throw_errno("cannot truncate the journal", path_);
  end_ = kFileMagic.size();
  sync();
}

}  // namespace featsense::storage::detail
