#!/usr/bin/env bash
# Builds the GPU checks for Hopper (sm_90) and packs them with their libraries and the real
# OS1-128 recording into .device/bundle.tar.xz for the GPU machine (see run_gpu_checks.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
cmake -S . -B build-gpu -G Ninja -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
ninja -C build-gpu featsense tsdf_test_cuda_integrator tsdf_test_cpu_integrator
data=../shared/data/ouster
extras=()
[ -d "$data" ] && extras=(-- "$data/OS-1-128_v2.3.0_1024x10_lb_n3.pcap" "$data/OS-1-128_v2.3.0_1024x10.json")
../shared/tools/device-bundle .device/bundle.tar.xz build-gpu/app/featsense \
  build-gpu/test/tsdf_test_cuda_integrator build-gpu/test/tsdf_test_cpu_integrator "${extras[@]}"
