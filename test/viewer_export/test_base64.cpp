// Base64 against RFC 4648's test vectors, and bytes of every value.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "featsense/viewer_export/base64.hpp"

namespace featsense::viewer_export {
namespace {

TEST(Base64, MatchesTheRfcVectors) {
  EXPECT_EQ(base64_encode(std::string("")), "");
  EXPECT_EQ(base64_encode(std::string("f")), "Zg==");
  EXPECT_EQ(base64_encode(std::string("fo")), "Zm8=");
  EXPECT_EQ(base64_encode(std::string("foo")), "Zm9v");
  EXPECT_EQ(base64_encode(std::string("foob")), "Zm9vYg==");
  EXPECT_EQ(base64_encode(std::string("fooba")), "Zm9vYmE=");
  EXPECT_EQ(base64_encode(std::string("foobar")), "Zm9vYmFy");
}

TEST(Base64, EncodesHighBytesAndTheLastLetters) {
  // 0xFB 0xFF: six-bit groups 62 and 63, the alphabet's '+' and '/'.
  EXPECT_EQ(base64_encode(std::vector<uint8_t>{0xFB, 0xFF, 0xBF}), "+/+/");
  EXPECT_EQ(base64_encode(std::vector<uint8_t>{0x00, 0x00, 0x00}), "AAAA");
  EXPECT_EQ(base64_encode(std::vector<uint8_t>{0x89, 'P', 'N', 'G'}), "iVBORw==");
}

TEST(Base64, LengthIsFourPerThreeBytesRoundedUp) {
  std::vector<uint8_t> bytes;
  for (int n = 0; n < 300; ++n) {
    EXPECT_EQ(base64_encode(bytes).size(), (bytes.size() + 2) / 3 * 4);
    bytes.push_back(static_cast<uint8_t>(n * 37));
  }
}

}  // namespace
}  // namespace featsense::viewer_export
