#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along: the
# loop closure. `bench` (default): bench odometry --refine --loops over the built-in paths
# (loops found, false loops against the truth, ATE before and after, ms per keyframe), on all
# cores and on 2 pinned cores. `town`: featsense demo of the town loop on the CUDA backend
# (both passes, the mesh against the truth, also aligned with the true path) and with the true
# poses, for the mesh's baseline (`town estimated`: only the first). `wrong`: the town loop's
# bench with a deliberately wrong loop added at the end (the robust loss at work).
# Results go to $OUT. Usage: bash test/bench/run_gpu_loops.sh [bench|town [estimated]|wrong]
set -uo pipefail
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
bin=/tmp/bundle/bin
out=${OUT:-/tmp/out}
mkdir -p "$out"
nvidia-smi --query-gpu=name,memory.total --format=csv,noheader
lscpu | grep "Model name"
what=${1:-bench}
summary() {
  python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); l = d['loops']; r = d.get('refine', {})
print(sys.argv[2], 'scans', d['sequence_scans'], 'ATE odometry %.4f refined %.4f loops %.4f' % (
      d.get('ape_rmse_m', -1), r.get('ape_rmse_m', -1), l.get('ape_rmse_m', -1)),
      'keyframes', l['keyframes'], 'candidates', l['candidates'], 'verified', l['verified'],
      'accepted', l['accepted'], 'false', l.get('false_loops'), 'worst %.3f m %.2f deg' % (
      l.get('worst_loop_error_m', 0), l.get('worst_loop_error_deg', 0)),
      'rejected', json.dumps(l['rejected']), 'keyframe ms median %.1f p95 %.1f max %.1f' % (
      l['keyframe']['median_ms'], l['keyframe']['p95_ms'], l['keyframe']['max_ms']),
      'real-time factor %.1f' % l['real_time_factor'])
if 'wrong_loop' in l: print('  wrong loop', json.dumps(l['wrong_loop']))" "$@"
}
if [ "$what" = bench ]; then
  for seq in "town loop 1500" "town drive 900" "parking loop 500" "parking drive 400" \
             "parking drone 400" "corridor walk 400" "lab walk 420"; do
    set -- $seq
    "$bin/featsense" bench odometry --quiet --scene "$1" --path "$2" --scans "$3" --refine --loops \
      --json "$out/loops_$1_$2.json" > /dev/null && summary "$out/loops_$1_$2.json" "$1 $2 (16 cores)"
  done
  # The speed on 2 cores, where the loop closure shares them with the front end.
  taskset -c 0,1 "$bin/featsense" bench odometry --quiet --scene town --path loop --scans 1500 \
    --refine --loops --json "$out/loops_town_loop_2cores.json" > /dev/null &&
    summary "$out/loops_town_loop_2cores.json" "town loop (2 cores)"
elif [ "$what" = wrong ]; then
  "$bin/featsense" bench odometry --quiet --scene town --path loop --scans 1500 --refine --loops \
    --wrong-loop --json "$out/loops_town_loop_wrong.json" > /dev/null &&
    summary "$out/loops_town_loop_wrong.json" "town loop, a wrong loop added (16 cores)"
else
  runs="estimated truth"
  [ "${2:-}" = estimated ] && runs=estimated
  for run in $runs; do
    extra=""
    [ "$run" = truth ] && extra="--gt-poses"
    /usr/bin/time -v "$bin/featsense" demo --quiet --scene town --path loop --backend cuda \
      -o "/tmp/town_$run" $extra 2> "$out/time_town_$run.txt"
    cp "/tmp/town_$run/report.json" "$out/town_$run.json"
    python3 -c "
import json, sys
r = json.load(open(sys.argv[1])); e = r.get('eval', {}); m = e.get('mesh', {}); l = r.get('loops', {})
print(sys.argv[2], 'scans/s %.1f' % r['scans_per_s'], 'ATE %.4f' % e['traj']['ape']['rmse'] if 'traj' in e else '',
      'before loops %.4f' % e['traj_before_loops']['ape']['rmse'] if 'traj_before_loops' in e else '',
      'mesh mean %.4f median %.4f p95 %.4f complete10cm %s' % (m['accuracy']['mean_abs'], m['accuracy']['median'], m['accuracy']['p95'], m['completeness'].get('0.10')) if 'accuracy' in m else 'no mesh eval',
      'aligned mean %.4f median %.4f p95 %.4f' % (m['aligned']['accuracy']['mean_abs'], m['aligned']['accuracy']['median'], m['aligned']['accuracy']['p95']) if 'aligned' in m else '',
      'loops', l.get('accepted'), l.get('second_pass'), json.dumps(l.get('first_pass')), json.dumps(l.get('second_pass_run')),
      'keyframe', json.dumps(l.get('timings', {}).get('keyframe')))" "$out/town_$run.json" "town $run"
    grep -E "Elapsed|Maximum resident" "$out/time_town_$run.txt"
  done
  cp /tmp/town_estimated/topdown.png "$out/town_topdown.png" 2> /dev/null
fi
