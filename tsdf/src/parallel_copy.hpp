#pragma once
// A large host-to-host copy spread over the CPU's threads: a scan's rays are copied into
// page-locked memory before each upload, and one thread copying 3 MB costs more than the
// upload itself.

#include <cstddef>

namespace featsense::tsdf::detail {

void parallel_copy(void* destination, const void* source, size_t bytes);

}  // namespace featsense::tsdf::detail
