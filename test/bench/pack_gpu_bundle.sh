#!/usr/bin/env bash
# Builds the GPU checks for Hopper (sm_90) and packs them with their libraries and the real
# OS1-128 recording into .device/bundle.tar.xz for the GPU machine (see run_gpu_checks.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
cmake -S . -B build-gpu -G Ninja -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
tests=(tsdf_test_cuda_integrator tsdf_test_cpu_integrator tsdf_test_cpu_integrator_exact
       storage_test_shifting_map)
ninja -C build-gpu featsense "${tests[@]}"
data=../shared/data/ouster
extras=()
[ -d "$data" ] && extras=(-- "$data/OS-1-128_v2.3.0_1024x10_lb_n3.pcap" "$data/OS-1-128_v2.3.0_1024x10.json"
                          "$data/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt")
../shared/tools/device-bundle .device/bundle.tar.xz build-gpu/app/featsense \
  "${tests[@]/#/build-gpu/test/}" "${extras[@]}"
# Without debug information the bundle is half the size (the carry limit is 64 MiB).
work=$(mktemp -d)
tar xJf .device/bundle.tar.xz -C "$work"
strip --strip-debug "$work"/bundle/bin/* "$work"/bundle/lib/libfeatsense_*
tar cf - -C "$work" bundle | xz -T2 -6 > .device/bundle.tar.xz
rm -rf "$work"
# The two real places for the scene runs of run_gpu_checks.sh.
mkdir -p .device/scenes
cp ../shared/data/scenes/small_house.ply ../shared/data/scenes/gas_station_with_ground.ply .device/scenes/ 2>/dev/null || true
# three.js for `live --view` (run_gpu_live.sh view): the GPU machine lacks Debian's libjs-three.
three=/usr/share/javascript/three
if [ -d "$three" ]; then
  mkdir -p .device/three/build .device/three/examples/js/controls
  cp "$three/build/three.min.js" .device/three/build/
  cp "$three"/examples/js/controls/{OrbitControls,FlyControls}.js .device/three/examples/js/controls/
fi
