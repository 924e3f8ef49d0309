#pragma once
/// Decompression of bag and MCAP chunks: `none`, `bz2` (one or more bzip2 streams), `lz4`
/// (the LZ4 frame format, as ROS's roslz4 and MCAP writers write it) and `zstd` (one or
/// more Zstandard frames; MCAP only).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

enum class ChunkCompression { kNone, kBz2, kLz4, kZstd };

/// The compression named by a ROS1 bag chunk's `compression` field (none, bz2, lz4), or
/// nullopt if unknown.
std::optional<ChunkCompression> parse_chunk_compression(std::string_view name);
std::string to_string(ChunkCompression compression);

struct ChunkDecompression {
  enum class Status {
    kComplete,        ///< exactly the declared size came out
    kShort,           ///< the input ended (truncated chunk) or the data ended early
    kLongerThanSaid,  ///< more data than the declared size; output holds the declared size
    kCorrupt,         ///< the decoder rejected the data; output holds what came out before
  };
  Status status = Status::kComplete;
  size_t size = 0;      ///< bytes written to the output
  std::string problem;  ///< for the warning, when status is not kComplete
};

/// Decompresses `input` into `output[0, declared_size)`. The output buffer is reused: it
/// is grown as data actually comes out (never to more than declared_size), so a lying
/// `size` field costs no memory; its size may exceed the result's size afterwards.
ChunkDecompression decompress_chunk(ChunkCompression compression, ByteView input,
                                    size_t declared_size, std::vector<uint8_t>& output);

}  // namespace featsense::slam
