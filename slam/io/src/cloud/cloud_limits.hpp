#pragma once
// Bounds that keep a lying header from asking for absurd memory; what a header promises is
// also checked against the bytes actually present before anything is sized by it.

#include <cstddef>
#include <cstdint>

namespace featsense::slam::cloud {

constexpr uint64_t kMaxPoints = uint64_t{1} << 28;  ///< per file; LiDAR frames hold ~1e6
constexpr size_t kMaxPointBytes = size_t{1} << 16;  ///< one point record

}  // namespace featsense::slam::cloud
