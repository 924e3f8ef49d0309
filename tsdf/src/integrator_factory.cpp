#include <stdexcept>

#include "featsense/tsdf/integrator.hpp"

namespace featsense::tsdf {

#if !FEATSENSE_HAVE_CUDA
bool cuda_backend_available(std::string* why) {
  if (why) *why = "this build has no CUDA backend (built without nvcc)";
  return false;
}

std::unique_ptr<Integrator> make_cuda_integrator(const TsdfSettings&, Vec3) {
  throw std::runtime_error("the CUDA backend is not available: this build has no CUDA support");
}
#endif

std::unique_ptr<Integrator> make_integrator(config::Backend backend, const TsdfSettings& settings,
                                            Vec3 centre_m, std::string* why) {
  std::string reason;
  const bool cuda = cuda_backend_available(&reason);
  switch (backend) {
    case config::Backend::kCpu:
      if (why) *why = "cpu backend (map.backend = cpu)";
      return make_cpu_integrator(settings, centre_m);
    case config::Backend::kCuda:
      if (!cuda) throw std::runtime_error("map.backend = cuda, but " + reason);
      if (why) *why = "cuda backend (map.backend = cuda): " + reason;
      return make_cuda_integrator(settings, centre_m);
    case config::Backend::kAuto:
      break;
  }
  if (cuda) {
    if (why) *why = "cuda backend (auto): " + reason;
    return make_cuda_integrator(settings, centre_m);
  }
  if (why) *why = "cpu backend (auto): " + reason;
  return make_cpu_integrator(settings, centre_m);
}

}  // namespace featsense::tsdf
