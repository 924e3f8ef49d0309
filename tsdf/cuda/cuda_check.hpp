#pragma once
// Every CUDA call goes through FEATSENSE_CUDA_CHECK: a failure becomes an exception naming
// the call, file and line (the library never exits the process).

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace featsense::tsdf::cuda {

inline void check(cudaError_t status, const char* call, const char* file, int line) {
  if (status != cudaSuccess) {
    throw std::runtime_error(std::string("CUDA error in ") + call + " at " + file + ":" +
                             std::to_string(line) + ": " + cudaGetErrorString(status));
  }
}

}  // namespace featsense::tsdf::cuda

#define FEATSENSE_CUDA_CHECK(call) ::featsense::tsdf::cuda::check((call), #call, __FILE__, __LINE__)
