#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along:
# the CUDA-vs-CPU parity tests, compute-sanitizer, and `featsense bench tsdf` on both
# backends, the built-in scenes and the real OS1-128 frames. JSON results go to $OUT.
set -uo pipefail
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
bin=/tmp/bundle/bin
out=${OUT:-/tmp/out}
mkdir -p "$out"
nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.max.sm --format=csv
"$bin/tsdf_test_cuda_integrator" 2>&1 | grep -E "parity|OK|PASSED|FAILED|SKIPPED"
for tool in memcheck racecheck initcheck synccheck; do
  echo "compute-sanitizer $tool:"
  compute-sanitizer --tool "$tool" "$bin/tsdf_test_cuda_integrator" --gtest_filter='*Analytic*' 2>&1 | tail -1
done
summary() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(sys.argv[2], d['backend'], 'median %.3f ms p95 %.3f max %.3f, %.0f pts/scan, %.2f Mpts/s, voxels updated %d, memory %.0f MB' % (d['median_ms'], d['p95_ms'], d['max_ms'], d['points_per_scan'], d['points_per_s']/1e6, d['voxels_updated_per_scan']['median'], d['memory_bytes']/1e6))" "$1" "$2"; }
for backend in cuda cpu; do
  repeat=200; [ "$backend" = cpu ] && repeat=20
  for scene in indoor outdoor; do
    "$bin/featsense" bench tsdf --quiet --backend "$backend" --scene "$scene" --repeat "$repeat" \
      --json "$out/bench_tsdf_${backend}_${scene}.json" > /dev/null && summary "$out/bench_tsdf_${backend}_${scene}.json" "$scene"
  done
  if [ -f /tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3.pcap ]; then
    "$bin/featsense" bench tsdf --quiet --backend "$backend" --repeat "$repeat" \
      --input /tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3.pcap --meta /tmp/bundle/OS-1-128_v2.3.0_1024x10.json \
      --json "$out/bench_tsdf_${backend}_os1.json" > /dev/null && summary "$out/bench_tsdf_${backend}_os1.json" os1-real
  fi
done
