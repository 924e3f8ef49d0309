// Chunk decompression (none, bz2, lz4 frames): round trips, and declared sizes that lie.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "rosbag/chunk_decompress.hpp"
#include "slam/rosbag_test_writer.hpp"

namespace featsense::slam {
namespace {

using Status = ChunkDecompression::Status;
using test::TestCompression;

constexpr TestCompression kAll[] = {TestCompression::kNone, TestCompression::kBz2,
                                    TestCompression::kLz4};

ChunkCompression to_chunk_compression(TestCompression c) {
  return *parse_chunk_compression(test::compression_name(c));
}

/// Bytes that compress somewhat (runs of a pseudo-random byte), like real chunks.
std::vector<uint8_t> sample_data(size_t size) {
  std::vector<uint8_t> data(size);
  uint32_t state = 2024u;
  for (size_t i = 0; i < size; ++i) {
    if (i % 7 == 0) state = state * 1664525u + 1013904223u;
    data[i] = static_cast<uint8_t>(state >> 24);
  }
  return data;
}

ByteView view(const std::vector<uint8_t>& bytes) { return {bytes.data(), bytes.size()}; }

TEST(ChunkDecompress, RoundTripsEveryCompression) {
  for (const TestCompression c : kAll) {
    for (const size_t size : {size_t{0}, size_t{1}, size_t{1000}, size_t{300000}}) {
      SCOPED_TRACE(std::string(test::compression_name(c)) + " " + std::to_string(size));
      const std::vector<uint8_t> data = sample_data(size);
      const std::vector<uint8_t> packed = test::compress(c, data);
      std::vector<uint8_t> out;
      const ChunkDecompression r =
          decompress_chunk(to_chunk_compression(c), view(packed), size, out);
      EXPECT_EQ(r.status, Status::kComplete) << r.problem;
      ASSERT_EQ(r.size, size);
      EXPECT_TRUE(std::equal(data.begin(), data.end(), out.begin()));
    }
  }
  EXPECT_EQ(parse_chunk_compression("zstd"), std::nullopt);
}

TEST(ChunkDecompress, NeverWritesPastTheDeclaredSizeOfAReusedBuffer) {
  // A buffer left larger by an earlier chunk, and data longer than this chunk declares:
  // the bytes past the declared size stay as they were.
  for (const TestCompression c : kAll) {
    SCOPED_TRACE(test::compression_name(c));
    const std::vector<uint8_t> data = sample_data(2000);
    const std::vector<uint8_t> packed = test::compress(c, data);
    std::vector<uint8_t> out(10000, 0xAB);
    const ChunkDecompression r = decompress_chunk(to_chunk_compression(c), view(packed), 1000, out);
    EXPECT_EQ(r.status, Status::kLongerThanSaid);
    ASSERT_EQ(r.size, 1000u);
    EXPECT_TRUE(std::equal(data.begin(), data.begin() + 1000, out.begin()));
    EXPECT_EQ(out.size(), 10000u);
    for (size_t i = 1000; i < out.size(); ++i) ASSERT_EQ(out[i], 0xAB) << "byte " << i;
  }
}

TEST(ChunkDecompress, DeclaredSizeLargerThanTheData) {
  for (const TestCompression c : kAll) {
    SCOPED_TRACE(test::compression_name(c));
    const std::vector<uint8_t> data = sample_data(5000);
    const std::vector<uint8_t> packed = test::compress(c, data);
    std::vector<uint8_t> out;
    const ChunkDecompression r = decompress_chunk(to_chunk_compression(c), view(packed), 9000, out);
    EXPECT_EQ(r.status, Status::kShort);
    ASSERT_EQ(r.size, 5000u);
    EXPECT_TRUE(std::equal(data.begin(), data.end(), out.begin()));
    // A lying size costs no memory beyond what came out (plus the growth step).
    const ChunkDecompression huge =
        decompress_chunk(to_chunk_compression(c), view(packed), size_t{1} << 30, out);
    EXPECT_EQ(huge.status, Status::kShort);
    EXPECT_LT(out.capacity(), size_t{1} << 20);
  }
}

TEST(ChunkDecompress, CutOffAndCorruptInput) {
  for (const TestCompression c : {TestCompression::kBz2, TestCompression::kLz4}) {
    SCOPED_TRACE(test::compression_name(c));
    const std::vector<uint8_t> data = sample_data(300000);
    const std::vector<uint8_t> packed = test::compress(c, data);
    // Cut in half: a prefix of the data comes out, never more than there is.
    std::vector<uint8_t> out;
    const ChunkDecompression cut = decompress_chunk(
        to_chunk_compression(c), ByteView{packed.data(), packed.size() / 2}, data.size(), out);
    EXPECT_EQ(cut.status, Status::kShort) << cut.problem;
    EXPECT_LT(cut.size, data.size());
    EXPECT_TRUE(
        std::equal(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(cut.size), data.begin()));
    // Junk in the middle: reported, not a crash.
    std::vector<uint8_t> junk = packed;
    for (size_t i = junk.size() / 2; i < junk.size() / 2 + 100; ++i) junk[i] ^= 0x5A;
    const ChunkDecompression bad =
        decompress_chunk(to_chunk_compression(c), view(junk), data.size(), out);
    EXPECT_NE(bad.status, Status::kComplete);
    EXPECT_FALSE(bad.problem.empty());
  }
}

TEST(ChunkDecompress, ConcatenatedStreamsAndFrames) {
  for (const TestCompression c : {TestCompression::kBz2, TestCompression::kLz4}) {
    SCOPED_TRACE(test::compression_name(c));
    const std::vector<uint8_t> first = sample_data(3000);
    const std::vector<uint8_t> second(4000, 0x11);
    std::vector<uint8_t> packed = test::compress(c, first);
    const std::vector<uint8_t> packed_second = test::compress(c, second);
    packed.insert(packed.end(), packed_second.begin(), packed_second.end());
    std::vector<uint8_t> out;
    const ChunkDecompression r = decompress_chunk(to_chunk_compression(c), view(packed), 7000, out);
    EXPECT_EQ(r.status, Status::kComplete) << r.problem;
    ASSERT_EQ(r.size, 7000u);
    EXPECT_TRUE(std::equal(first.begin(), first.end(), out.begin()));
    EXPECT_TRUE(std::equal(second.begin(), second.end(), out.begin() + 3000));
  }
}

}  // namespace
}  // namespace featsense::slam
