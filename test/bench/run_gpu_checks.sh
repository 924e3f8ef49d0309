#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along:
# the CUDA-vs-CPU parity and shift-invariance tests, compute-sanitizer, `featsense bench tsdf`
# and `bench store` on both backends (CPU limited to 2 cores with taskset), and `featsense
# map` / `demo` end to end. JSON results and reports go to $OUT.
# Usage: bash test/bench/run_gpu_checks.sh [tests|bench|map|all]
set -uo pipefail
what=${1:-all}
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
bin=/tmp/bundle/bin
out=${OUT:-/tmp/out}
mkdir -p "$out"
two_cores="taskset -c 0,1"
nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.max.sm --format=csv
summary() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(sys.argv[2], d['backend'], 'median %.3f ms p95 %.3f max %.3f' % (d['median_ms'], d['p95_ms'], d['max_ms']), {k: d[k] for k in sys.argv[3:] if k in d})" "$@"; }

if [ "$what" = tests ] || [ "$what" = all ]; then
  "$bin/tsdf_test_cuda_integrator" 2>&1 | grep -E "parity|OK|PASSED|FAILED|SKIPPED"
  "$bin/storage_test_shifting_map" 2>&1 | grep -E "OK|PASSED|FAILED|SKIPPED"
  "$bin/tsdf_test_cpu_integrator_exact" 2>&1 | tail -1
  for tool in memcheck racecheck; do
    echo "compute-sanitizer $tool:"
    compute-sanitizer --tool "$tool" "$bin/tsdf_test_cuda_integrator" --gtest_filter='*Analytic*' 2>&1 | tail -1
    compute-sanitizer --tool "$tool" "$bin/storage_test_shifting_map" --gtest_filter='*ManyTimes*/1' 2>&1 | tail -1
  done
fi

if [ "$what" = bench ] || [ "$what" = all ]; then
  pcap=/tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3.pcap
  meta=/tmp/bundle/OS-1-128_v2.3.0_1024x10.json
  for backend in cuda cpu; do
    run=""; repeat=200
    if [ "$backend" = cpu ]; then run=$two_cores; repeat=10; fi
    for scene in indoor outdoor; do
      $run "$bin/featsense" bench tsdf --quiet --backend "$backend" --scene "$scene" --repeat "$repeat" \
        --json "$out/bench_tsdf_${backend}_${scene}.json" > /dev/null &&
        summary "$out/bench_tsdf_${backend}_${scene}.json" "tsdf $scene" points_per_s memory_bytes
    done
    $run "$bin/featsense" bench tsdf --quiet --backend "$backend" --repeat "$repeat" --input "$pcap" --meta "$meta" \
      --json "$out/bench_tsdf_${backend}_os1.json" > /dev/null &&
      summary "$out/bench_tsdf_${backend}_os1.json" "tsdf os1-real" points_per_s
    $run "$bin/featsense" bench store --quiet --backend "$backend" --dir /tmp/store \
      --json "$out/bench_store_${backend}.json" > /dev/null &&
      summary "$out/bench_store_${backend}.json" "store shift 10 m" slab_mb sync_s checkpoint_s file_mb
  done
  # What the defaults of the truncation and the sparse carving each change, on the CUDA backend.
  for variant in "old map.truncation=0.6 map.sparse_carving=false" "full map.sparse_carving=false" \
                 "band map.carve_free_space=false"; do
    set -- $variant; name=$1; shift
    sets=(); for kv in "$@"; do sets+=(--set "$kv"); done
    for scene in indoor outdoor; do
      "$bin/featsense" bench tsdf --quiet --backend cuda --scene "$scene" --repeat 200 "${sets[@]}" \
        --json "$out/bench_tsdf_cuda_${scene}_$name.json" > /dev/null &&
        summary "$out/bench_tsdf_cuda_${scene}_$name.json" "tsdf $scene ($*)"
    done
    "$bin/featsense" bench tsdf --quiet --backend cuda --repeat 200 --input "$pcap" --meta "$meta" "${sets[@]}" \
      --json "$out/bench_tsdf_cuda_os1_$name.json" > /dev/null &&
      summary "$out/bench_tsdf_cuda_os1_$name.json" "tsdf os1-real ($*)"
  done
  for scene in indoor outdoor; do
    $two_cores "$bin/featsense" bench tsdf --quiet --backend cpu --scene "$scene" --repeat 10 \
      --set map.carve_free_space=false --json "$out/bench_tsdf_cpu_${scene}_band.json" > /dev/null &&
      summary "$out/bench_tsdf_cpu_${scene}_band.json" "tsdf $scene (band only)"
  done
  $two_cores "$bin/featsense" bench tsdf --quiet --backend cpu --repeat 10 --input "$pcap" --meta "$meta" \
    --set map.carve_free_space=false --json "$out/bench_tsdf_cpu_os1_band.json" > /dev/null &&
    summary "$out/bench_tsdf_cpu_os1_band.json" "tsdf os1-real (band only)"
fi

if [ "$what" = map ] || [ "$what" = all ]; then
  sim=/tmp/parking
  "$bin/featsense" simulate --quiet --scene parking --path drive -o "$sim" 2>&1 | tail -1
  frames=$(ls "$sim"/frame_*.pcd | wc -l)
  echo "parking drive: $frames frames"
  report() { python3 -c "import json,sys; r=json.load(open(sys.argv[1])); t=r['timings']; e=r.get('eval',{}).get('mesh',{}); print(sys.argv[2], r['frames'], 'frames', '%.1f scans/s' % r['scans_per_s'], 'rtf %.2f' % r['real_time_factor'], 'integrate median %.2f ms p95 %.2f' % (t['integrate']['median_ms'], t['integrate']['p95_ms']), 'shift max %.0f ms' % t['shift']['max_ms'], 'final flush %.1f s' % (t['final_flush']['max_ms'] / 1000) if t['final_flush']['count'] else '', 'rss %.0f MB' % r['peak_rss_mb'], 'mesh', r.get('mesh'), 'accuracy', e.get('accuracy',{}).get('mean_abs'), 'completeness', e.get('completeness'))" "$@"; }
  "$bin/featsense" map "$sim" -o "$out/map_parking_cuda" --gt "$sim/gt_trajectory.tum" --backend cuda --quiet
  report "$out/map_parking_cuda/report.json" "map parking cuda"
  $two_cores "$bin/featsense" map "$sim" -o "$out/map_parking_cpu" --gt "$sim/gt_trajectory.tum" --backend cpu --quiet --end 80 --no-mesh
  report "$out/map_parking_cpu/report.json" "map parking cpu 2 cores (80 frames)"
  $two_cores "$bin/featsense" map "$sim" -o "$out/map_parking_cpu_band" --gt "$sim/gt_trajectory.tum" --backend cpu --quiet \
    --set map.carve_free_space=false
  report "$out/map_parking_cpu_band/report.json" "map parking cpu 2 cores, band only (no free-space carving)"
  "$bin/featsense" map /tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3.pcap --meta /tmp/bundle/OS-1-128_v2.3.0_1024x10.json \
    --gt /tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt -o "$out/map_os1" --backend cuda --quiet
  report "$out/map_os1/report.json" "map os1 real"
  # The two real places (meshes in .device/scenes/), on the paths of make_scene_paths.py.
  python3 test/bench/make_scene_paths.py /tmp/paths
  for scene in small_house gas_station; do
    mesh=.device/scenes/$scene.ply
    [ "$scene" = gas_station ] && mesh=.device/scenes/gas_station_with_ground.ply
    [ -f "$mesh" ] || continue
    "$bin/featsense" simulate --quiet --scene "$mesh" --trajectory /tmp/paths/$scene.tum -o /tmp/$scene
    "$bin/featsense" map /tmp/$scene -o "$out/map_$scene" --gt /tmp/$scene/gt_trajectory.tum --backend cuda --quiet
    report "$out/map_$scene/report.json" "map $scene"
  done
  # Peak memory of a short and a long run of the same drive: it must not grow with the run.
  "$bin/featsense" map "$sim" -o /tmp/rss_short --gt "$sim/gt_trajectory.tum" --backend cuda --quiet --end 40 --no-mesh
  report /tmp/rss_short/report.json "map parking first 40 frames"
  du -b "$out/map_parking_cuda/map.h5" | awk '{print "parking map.h5 bytes", $1}'
  rm -f "$out"/map_*/map.h5 "$out"/map_*/map.h5.journal "$out"/map_*/mesh.*
  /usr/bin/time -v "$bin/featsense" demo -o /tmp/demo --backend cuda 2>&1 | grep -E "demo|mapped|mesh|against|Maximum resident|Elapsed"
  cp /tmp/demo/report.json "$out/demo_report.json"
fi
