#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along (see
# pack_gpu_bundle.sh): the whole pipeline with the odometry front end. Simulated sequences
# are written to local disk first, then mapped without --gt on the CUDA backend (all cores)
# and on the CPU backend limited to 2 cores; scans/s and the per-stage times go to $OUT.
# Usage: bash test/bench/run_gpu_frontend.sh
set -uo pipefail
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
bin=/tmp/bundle/bin
out=${OUT:-/tmp/out}
work=/tmp/frontend
mkdir -p "$out" "$work"
nvidia-smi --query-gpu=name,memory.total --format=csv,noheader
lscpu | grep "Model name"
summary() {
  python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
t = r['timings']; o = r.get('odometry', {}).get('timings', {})
e = r.get('eval', {})
print(sys.argv[2], r['backend'], 'scans/s %.1f' % r['scans_per_s'],
      'locate %.1f refine %.1f integrate %.1f read %.1f ms' % (t['locate']['median_ms'], t['refine']['median_ms'], t['integrate']['median_ms'], t['read']['median_ms']),
      'refine: registration %.0f ms median' % r['refine']['timings']['registration']['median_ms'] if 'refine' in r else '',
      'features %.1f registration %.1f ms' % (o['features']['median_ms'], o['registration']['median_ms']) if o else '',
      'ATE %.4f' % e['traj']['ape']['rmse'] if 'traj' in e else '')" "$@"
}
# Each sequence with the refinement (the default) and without it ("_noref").
for seq in "parking drive 120" "lab walk 120" "parking drone 120"; do
  set -- $seq
  dir="$work/$1_$2"
  "$bin/featsense" simulate --quiet --scene "$1" --path "$2" --frames "$3" --seed 1 -o "$dir" || continue
  for run in "cuda" "cpu2" "cuda_noref" "cpu2_noref"; do
    refine=""
    case "$run" in *_noref) refine="--set refine.enabled=false" ;; esac
    if [ "${run%_noref}" = cuda ]; then
      "$bin/featsense" map "$dir" -o "$work/out_$1_$2_$run" --backend cuda --quiet --no-mesh --overwrite $refine
    else
      taskset -c 0,1 "$bin/featsense" map "$dir" -o "$work/out_$1_$2_$run" --backend cpu --quiet --no-mesh --overwrite $refine
    fi
    cp "$work/out_$1_$2_$run/report.json" "$out/map_$1_$2_$run.json"
    summary "$out/map_$1_$2_$run.json" "$1 $2 $run"
  done
done
# The front end alone on 2 cores (features + registration per scan): simulated OS1-128
# sequences and the real OS1-128 pcap when it was packed.
for seq in "parking drive" "lab walk" "parking drone"; do
  set -- $seq
  taskset -c 0,1 "$bin/featsense" bench odometry --quiet --scene "$1" --path "$2" --scans 150 \
    --refine --json "$out/bench_odometry_$1_$2.json" > /dev/null
  python3 -c "import json, sys; d = json.load(open(sys.argv[1])); r = d['refine']; print(sys.argv[2], '2 cores: features %.1f registration %.1f total %.1f ms median (p95 %.1f), ATE %.4f; refined ATE %.4f, a stretch %.0f ms for %.0f ms recorded' % (d['features']['median_ms'], d['registration']['median_ms'], d['total']['median_ms'], d['total']['p95_ms'], d['ape_rmse_m'], r['ape_rmse_m'], r['per_stretch_ms'], r['recorded_per_stretch_ms']))" "$out/bench_odometry_$1_$2.json" "bench odometry $1 $2"
done
pcap=/tmp/bundle/OS-1-128_v2.3.0_1024x10_lb_n3.pcap
if [ -f "$pcap" ]; then
  taskset -c 0,1 "$bin/featsense" bench odometry --quiet --input "$pcap" \
    --meta /tmp/bundle/OS-1-128_v2.3.0_1024x10.json --json "$out/bench_odometry_os1.json" > /dev/null
  python3 -c "import json, sys; d = json.load(open(sys.argv[1])); print('bench odometry os1 pcap 2 cores: total %.1f ms (%d timed scan)' % (d['total']['median_ms'], d['timed_scans']))" "$out/bench_odometry_os1.json"
fi

