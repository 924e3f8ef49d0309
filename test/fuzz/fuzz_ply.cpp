// libFuzzer target: bytes as a PLY file, decoded and organized into a Scan. Any input must
// give a Scan or an InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_cloud_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    featsense::fuzz::organize_decoded(featsense::slam::decode_ply(bytes, "fuzz.ply"), "fuzz.ply");
  } catch (const featsense::slam::InputError&) {
  }
  return 0;
}
