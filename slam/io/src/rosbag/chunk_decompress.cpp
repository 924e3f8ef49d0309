#include "rosbag/chunk_decompress.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <climits>

namespace featsense::slam {
namespace {

/// What one call of a streaming decoder did.
struct Step {
  size_t consumed = 0;
  size_t produced = 0;
  bool end_of_stream = false;  ///< a bzip2 stream or an LZ4 frame ended
  std::string error;           ///< the decoder's complaint; empty if none
};

/// libbz2's streaming decoder. Its API takes non-const input pointers but never writes
/// through them.
class Bz2Decoder {
 public:
  Bz2Decoder() { ok_ = BZ2_bzDecompressInit(&stream_, 0, 0) == BZ_OK; }
  ~Bz2Decoder() {
    if (ok_) BZ2_bzDecompressEnd(&stream_);
  }
  Bz2Decoder(const Bz2Decoder&) = delete;
  Bz2Decoder& operator=(const Bz2Decoder&) = delete;

  bool ok() const { return ok_; }

  Step step(const uint8_t* in, size_t in_size, uint8_t* out, size_t out_size) {
    const unsigned int in_avail = static_cast<unsigned int>(std::min<size_t>(in_size, UINT_MAX));
    const unsigned int out_avail = static_cast<unsigned int>(std::min<size_t>(out_size, UINT_MAX));
    stream_.next_in = reinterpret_cast<char*>(const_cast<uint8_t*>(in));
    stream_.avail_in = in_avail;
    stream_.next_out = reinterpret_cast<char*>(out);
    stream_.avail_out = out_avail;
    const int rc = BZ2_bzDecompress(&stream_);
    Step step;
    step.consumed = in_avail - stream_.avail_in;
    step.produced = out_avail - stream_.avail_out;
    if (rc == BZ_STREAM_END) {
      step.end_of_stream = true;
    } else if (rc != BZ_OK) {
      step.error = "bzip2 error " + std::to_string(rc);
    }
    return step;
  }

  /// Starts over for a further stream concatenated after the one that ended, if the rest
  /// of the input starts like one ("BZh").
  bool restart(const uint8_t* in, size_t in_size) {
    if (in_size < 3 || in[0] != 'B' || in[1] != 'Z' || in[2] != 'h') return false;
    BZ2_bzDecompressEnd(&stream_);
    stream_ = bz_stream{};
    ok_ = BZ2_bzDecompressInit(&stream_, 0, 0) == BZ_OK;
    return ok_;
  }

 private:
  bz_stream stream_{};
  bool ok_ = false;
};

/// liblz4's frame decoder; the context resets itself after each complete frame.
class Lz4FrameDecoder {
 public:
  Lz4FrameDecoder() {
    ok_ = !LZ4F_isError(LZ4F_createDecompressionContext(&context_, LZ4F_VERSION));
  }
  ~Lz4FrameDecoder() {
    if (context_ != nullptr) LZ4F_freeDecompressionContext(context_);
  }
  Lz4FrameDecoder(const Lz4FrameDecoder&) = delete;
  Lz4FrameDecoder& operator=(const Lz4FrameDecoder&) = delete;

  bool ok() const { return ok_; }

  Step step(const uint8_t* in, size_t in_size, uint8_t* out, size_t out_size) {
    size_t in_used = in_size;
    size_t out_used = out_size;
    const size_t rc = LZ4F_decompress(context_, out, &out_used, in, &in_used, nullptr);
    Step step;
    step.consumed = in_used;
    step.produced = out_used;
    if (LZ4F_isError(rc)) {
      step.error = std::string("lz4 error: ") + LZ4F_getErrorName(rc);
    } else if (rc == 0) {
      step.end_of_stream = true;
    }
    return step;
  }

  bool restart(const uint8_t*, size_t in_size) { return in_size > 0; }

 private:
  LZ4F_dctx* context_ = nullptr;
  bool ok_ = false;
};

/// libzstd's streaming decoder (MCAP's "zstd" chunks); it starts the next frame by itself.
class ZstdDecoder {
 public:
  ZstdDecoder() : stream_(ZSTD_createDStream()) {
    ok_ = stream_ != nullptr && !ZSTD_isError(ZSTD_initDStream(stream_));
  }
  ~ZstdDecoder() { ZSTD_freeDStream(stream_); }
  ZstdDecoder(const ZstdDecoder&) = delete;
  ZstdDecoder& operator=(const ZstdDecoder&) = delete;

  bool ok() const { return ok_; }

  Step step(const uint8_t* in, size_t in_size, uint8_t* out, size_t out_size) {
    ZSTD_inBuffer input{in, in_size, 0};
    ZSTD_outBuffer output{out, out_size, 0};
    const size_t rc = ZSTD_decompressStream(stream_, &output, &input);
    Step step;
    step.consumed = input.pos;
    step.produced = output.pos;
    if (ZSTD_isError(rc)) {
      step.error = std::string("zstd error: ") + ZSTD_getErrorName(rc);
    } else if (rc == 0) {
      step.end_of_stream = true;
    }
    return step;
  }

  bool restart(const uint8_t*, size_t in_size) { return in_size > 0; }

 private:
  ZSTD_DStream* stream_ = nullptr;
  bool ok_ = false;
};

ChunkDecompression result(ChunkDecompression::Status status, size_t size, std::string problem) {
  ChunkDecompression out;
  out.status = status;
  out.size = size;
  out.problem = std::move(problem);
  return out;
}

std::string sizes(size_t produced, size_t declared) {
  return std::to_string(produced) + " of the declared " + std::to_string(declared) + " bytes";
}

/// Runs a streaming decoder over the input, growing the output only as data comes out, and
/// checks the amount against the declared size (one probe past it tells "longer than said").
template <typename Decoder>
ChunkDecompression run_decoder(Decoder& decoder, ByteView input, size_t declared,
                               std::vector<uint8_t>& output) {
  using Status = ChunkDecompression::Status;
  if (!decoder.ok()) return result(Status::kCorrupt, 0, "cannot start the decoder");
  constexpr size_t kMinGrowth = 64 * 1024;
  uint8_t probe[64];
  size_t produced = 0;
  size_t in_pos = 0;
  for (;;) {
    // The reused buffer may be longer than this chunk: the declared size bounds the writes,
    // not the buffer's size, so produced <= declared always holds.
    const bool probing = produced == declared;
    if (!probing && produced == output.size()) {
      const size_t wanted = std::max({output.size() * 2, produced + kMinGrowth, 4 * input.size});
      output.resize(std::min(declared, wanted));
    }
    uint8_t* out = probing ? probe : output.data() + produced;
    const size_t out_size = probing ? sizeof(probe) : std::min(output.size(), declared) - produced;
    const Step step = decoder.step(input.data + in_pos, input.size - in_pos, out, out_size);
    if (!step.error.empty()) {
      return result(Status::kCorrupt, produced, step.error + " after " + sizes(produced, declared));
    }
    in_pos += step.consumed;
    if (probing && step.produced > 0) {
      return result(
          Status::kLongerThanSaid, produced,
          "decompresses to more than the declared " + std::to_string(declared) + " bytes");
    }
    produced += step.produced;
    if (step.end_of_stream) {
      if (in_pos < input.size && decoder.restart(input.data + in_pos, input.size - in_pos)) {
        continue;
      }
      if (produced == declared) return result(Status::kComplete, produced, "");
      return result(Status::kShort, produced, "data ends after " + sizes(produced, declared));
    }
    if (step.consumed == 0 && step.produced == 0) {
      if (in_pos == input.size) {
        return result(Status::kShort, produced,
                      "compressed data is cut off after " + sizes(produced, declared));
      }
      return result(Status::kCorrupt, produced,
                    "the decoder makes no progress after " + sizes(produced, declared));
    }
  }
}

}  // namespace

std::optional<ChunkCompression> parse_chunk_compression(std::string_view name) {
  if (name == "none") return ChunkCompression::kNone;
  if (name == "bz2") return ChunkCompression::kBz2;
  if (name == "lz4") return ChunkCompression::kLz4;
  return std::nullopt;
}

std::string to_string(ChunkCompression compression) {
  switch (compression) {
    case ChunkCompression::kNone:
      return "none";
    case ChunkCompression::kBz2:
      return "bz2";
    case ChunkCompression::kLz4:
      return "lz4";
    case ChunkCompression::kZstd:
      return "zstd";
  }
  return "unknown";
}

ChunkDecompression decompress_chunk(ChunkCompression compression, ByteView input,
                                    size_t declared_size, std::vector<uint8_t>& output) {
  using Status = ChunkDecompression::Status;
  switch (compression) {
    case ChunkCompression::kNone: {
      const size_t size = std::min(input.size, declared_size);
      if (output.size() < size) output.resize(size);
      if (size > 0) std::copy(input.data, input.data + size, output.begin());
      if (input.size > declared_size) {
        return result(Status::kLongerThanSaid, size,
                      "holds " + std::to_string(input.size) + " bytes, more than the declared " +
                          std::to_string(declared_size));
      }
      if (input.size < declared_size) {
        return result(Status::kShort, size, "data ends after " + sizes(size, declared_size));
      }
      return result(Status::kComplete, size, "");
    }
    case ChunkCompression::kBz2: {
      Bz2Decoder decoder;
      return run_decoder(decoder, input, declared_size, output);
    }
    case ChunkCompression::kLz4: {
      Lz4FrameDecoder decoder;
      return run_decoder(decoder, input, declared_size, output);
    }
    case ChunkCompression::kZstd: {
      ZstdDecoder decoder;
      return run_decoder(decoder, input, declared_size, output);
    }
  }
  return result(Status::kCorrupt, 0, "unknown compression");
}

}  // namespace featsense::slam
