#pragma once
// Command-line settings of `featsense map` runs in end-to-end tests.

#include <string>

namespace featsense::test {

/// A small, coarse map on the CPU backend, quiet: each run of a short simulated sequence takes
/// seconds on two cores.
inline const std::string kSmallMap =
    " --quiet --backend cpu --set map.size=[16,16,8] --set map.voxel_size=0.1"
    " --set map.truncation=0.3 --set map.shift_threshold=1.0";

}  // namespace featsense::test
