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
  # Built-in scenes: 50 scans of a moving sensor, each pass into a new map (cuda 4 passes,
  # cpu 1); the real recording's 3 frames at the origin, each pass into a new map.
  # Variants: the default; "nosettle" (w_max 500, so no free space settles within the run:
  # the work of every carving ray, as before settled free space was passed by); band only.
  bench() {  # backend name extra-args...
    local backend=$1 name=$2; shift 2
    local run="" passes=4 real_passes=20
    if [ "$backend" = cpu ]; then run=$two_cores; passes=1; real_passes=3; fi
    for scene in indoor outdoor; do
      $run "$bin/featsense" bench tsdf --quiet --backend "$backend" --scene "$scene" --passes "$passes" "$@" \
        --json "$out/bench_tsdf_${backend}_${scene}_$name.json" > /dev/null &&
        summary "$out/bench_tsdf_${backend}_${scene}_$name.json" "tsdf $scene $name" empty_map_ms voxels_updated_per_scan
    done
    $run "$bin/featsense" bench tsdf --quiet --backend "$backend" --passes "$real_passes" --input "$pcap" --meta "$meta" "$@" \
      --json "$out/bench_tsdf_${backend}_os1_$name.json" > /dev/null &&
      summary "$out/bench_tsdf_${backend}_os1_$name.json" "tsdf os1-real $name" voxels_updated_per_scan
  }
  for backend in cuda cpu; do
    run=""; [ "$backend" = cpu ] && run=$two_cores
    bench "$backend" default
    bench "$backend" nosettle --set map.max_weight=500
    bench "$backend" band --set map.carve_free_space=false
    $run "$bin/featsense" bench store --quiet --backend "$backend" --dir /tmp/store \
      --json "$out/bench_store_${backend}.json" > /dev/null &&
      summary "$out/bench_store_${backend}.json" "store shift 10 m" slab_mb sync_s checkpoint_s file_mb
  done
  echo "points/s and memory:"; summary "$out/bench_tsdf_cuda_indoor_default.json" "cuda indoor" points_per_s memory_bytes
fi

if [ "$what" = map ] || [ "$what" = all ]; then
  sim=/tmp/parking
  "$bin/featsense" simulate --quiet --scene parking --path drive -o "$sim" 2>&1 | tail -1
  frames=$(ls "$sim"/frame_*.pcd | wc -l)
  echo "parking drive: $frames frames"
  report() { python3 -c "import json,sys; r=json.load(open(sys.argv[1])); t=r['timings']; e=r.get('eval',{}).get('mesh',{}); print(sys.argv[2], r['frames'], 'frames', '%.1f scans/s' % r['scans_per_s'], 'rtf %.2f' % r['real_time_factor'], 'integrate median %.2f ms p95 %.2f' % (t['integrate']['median_ms'], t['integrate']['p95_ms']), 'shift max %.0f ms' % t['shift']['max_ms'], 'final flush %.1f s' % (t['final_flush']['max_ms'] / 1000) if t['final_flush']['count'] else '', 'rss %.0f MB' % r['peak_rss_mb'], 'mesh', r.get('mesh'), 'accuracy', e.get('accuracy',{}).get('mean_abs'), 'completeness', e.get('completeness'))" "$@"; }
  "$bin/featsense" map "$sim" -o "$out/map_parking_cuda" --gt "$sim/gt_trajectory.tum" --backend cuda --quiet
  report "$out/map_parking_cuda/report.json" "map parking cuda"
  $two_cores "$bin/featsense" map "$sim" -o "$out/map_parking_cpu" --gt "$sim/gt_trajectory.tum" --backend cpu --quiet
  report "$out/map_parking_cpu/report.json" "map parking cpu 2 cores"
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
