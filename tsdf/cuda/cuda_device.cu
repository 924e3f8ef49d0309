// The device probe: whether this build's CUDA backend finds a usable GPU (integrator.hpp).

#include <cuda_runtime.h>

#include <string>

#include "featsense/tsdf/integrator.hpp"

namespace featsense::tsdf {

bool cuda_backend_available(std::string* why) {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0) {
    if (why) {
      *why = status != cudaSuccess ? std::string("no usable GPU: ") + cudaGetErrorString(status)
                                   : std::string("no GPU found");
    }
    return false;
  }
  cudaDeviceProp properties{};
  if (cudaGetDeviceProperties(&properties, 0) == cudaSuccess && why) {
    *why = std::string("GPU ") + properties.name;
  }
  return true;
}

}  // namespace featsense::tsdf
