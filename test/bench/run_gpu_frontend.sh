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
      'locate %.1f integrate %.1f read %.1f ms' % (t['locate']['median_ms'], t['integrate']['median_ms'], t['read']['median_ms']),
      'features %.1f registration %.1f ms' % (o['features']['median_ms'], o['registration']['median_ms']) if o else '',
      'ATE %.4f' % e['traj']['ape']['rmse'] if 'traj' in e else '')" "$@"
}
for seq in "parking drive 120" "lab walk 120"; do
  set -- $seq
  dir="$work/$1_$2"
  "$bin/featsense" simulate --quiet --scene "$1" --path "$2" --frames "$3" --seed 1 -o "$dir" || continue
  for run in "cuda" "cpu2"; do
    if [ "$run" = cuda ]; then
      "$bin/featsense" map "$dir" -o "$work/out_$1_$2_$run" --backend cuda --quiet --no-mesh --overwrite
    else
      taskset -c 0,1 "$bin/featsense" map "$dir" -o "$work/out_$1_$2_$run" --backend cpu --quiet --no-mesh --overwrite
    fi
    cp "$work/out_$1_$2_$run/report.json" "$out/map_$1_$2_$run.json"
    summary "$out/map_$1_$2_$run.json" "$1 $2 $run"
  done
done
