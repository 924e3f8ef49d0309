#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along: one
# map from several recordings, in three calls on the same warm machine. `loop`: simulates the
# town loop, the town drive and the lab, and maps the loop. `continue`: the drive (starts
# 50 m away, turned 90 deg, another path) continued into the loop's map without poses: where
# it was placed against its truth, the joined map's mesh against the true surface; then the
# lab continued into that map (must be refused, the map byte-identical). `merge`: the drive
# mapped alone in its own frame, then merged into the loop's map, and the same figures.
# BACKEND=cpu maps with the CPU backend (the same map); EXTRA adds settings. Results go to $OUT.
# `full` and `moved` (after `loop`): the drive continued into the loop's map with the earlier
# session mapped again, every scan (map.keep_unmoved=false, no mesh) or only where scans moved
# (the default, with the run's mesh and evaluation); `moved` then compares the two maps voxel by
# voxel (`featsense eval maps`).
# Usage: bash test/bench/run_gpu_sessions.sh loop|continue|merge|full|moved
set -uo pipefail
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
f=/tmp/bundle/bin/featsense
out=${OUT:-/tmp/out}
mkdir -p "$out"
root=$(pwd)
# The map on the GPU where the bundle has it (BACKEND=cpu: the CPU backend, the same map).
backend=${BACKEND:-cuda}
# More settings for every map and merge, e.g. EXTRA="--set map.carve_free_space=false".
extra=${EXTRA:-}
nvidia-smi --query-gpu=name,memory.total --format=csv,noheader
lscpu | grep "Model name"
w=/tmp/sessions
mkdir -p "$w"
cd "$w"
timed() {  # name, command...
  local name=$1
  shift
  /usr/bin/time -f "$name: %e s, peak RSS %M kB" "$@" 2>> "$out/time.txt" > /dev/null
  local rc=$?
  tail -1 "$out/time.txt"
  return $rc
}
mesh_figures() {  # label, mesh
  "$f" -q eval mesh "$2" A/gt_mesh.ply --json "$out/eval_$1.json" > /dev/null &&
    python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); a = d['accuracy']
print(sys.argv[2], 'mesh vs truth: mean %.4f median %.4f p95 %.4f m (p95/mean %.2f), completeness %s' % (
      a['mean_abs'], a['median'], a['p95'], a['p95'] / a['mean_abs'], json.dumps(d['completeness'])))" "$out/eval_$1.json" "$1"
}
what=${1:-loop}
if [ "$what" = loop ]; then
  rm -rf A B L MA MB ML
  timed "simulate town loop" "$f" -q simulate --scene town --path loop -o A
  timed "simulate town drive" "$f" -q simulate --scene town --path drive -o B
  timed "simulate lab walk" "$f" -q simulate --scene lab --path walk --frames 300 -o L
  timed "map loop ($backend)" "$f" -q map A -o MA --backend "$backend" $extra --no-mesh
  cp MA/report.json "$out/loop_report.json"
  python3 "$root/test/bench/pose_error.py" MA/trajectory.tum A/gt_trajectory.tum "loop vs truth"
elif [ "$what" = continue ]; then
  rm -rf MB ML
  timed "continue with the drive ($backend)" "$f" -q map B --continue MA/map.h5 -o MB --backend "$backend" $extra
  cp MB/report.json "$out/drive_report.json"
  cp MB/trajectory.tum "$out/drive_trajectory.tum"
  python3 "$root/test/bench/pose_error.py" MB/trajectory.tum B/gt_trajectory.tum "drive placed, vs truth"
  python3 -c "
import json
r = json.load(open('MB/report.json')); l = r['relocalization']; m = r.get('eval', {}).get('mesh', {})
print('placed', l['placed'], 'at', l['seconds_in'], 's, keyframe', l['keyframe'], 'fitness', l['fitness_m'],
      'agreeing', l['agreeing'], 'links', l['links']['count'], 'earlier sessions', json.dumps(l['earlier_sessions']))
a = m.get('accuracy', {})
if a: print('mesh vs truth as mapped: mean %.4f median %.4f p95 %.4f m (p95/mean %.2f)' % (
      a['mean_abs'], a['median'], a['p95'], a['p95'] / a['mean_abs']), 'completeness', json.dumps(m.get('completeness')))
else: print('mesh', json.dumps(m)[:600])
print('sessions', [(s['id'], s['scans'], s['keyframes']) for s in r['sessions']])"
  sha256sum MB/map.h5 > "$out/before_lab.sha256"
  "$f" -q map L --continue MB/map.h5 -o ML --backend "$backend" $extra 2> "$out/lab_refused.txt"
  echo "lab into town: exit $?, $(tail -c 600 "$out/lab_refused.txt")"
  sha256sum -c "$out/before_lab.sha256"
elif [ "$what" = full ] || [ "$what" = moved ]; then
  reintegration() {  # report
    python3 -c "
import json, sys
r = json.load(open(sys.argv[1])); l = r['relocalization']; e = l['earlier_sessions']
print('earlier keyframes moved up to %.1f mm, %.3f deg' % (1000 * e['moved_max_m'], e['moved_max_deg']))
print('reintegration', json.dumps(e.get('reintegration')))
m = r.get('eval', {}).get('mesh', {}); a = m.get('accuracy', {})
if a: print('mesh vs truth as mapped: mean %.4f median %.4f p95 %.4f m (p95/mean %.2f)' % (
      a['mean_abs'], a['median'], a['p95'], a['p95'] / a['mean_abs']), 'completeness', json.dumps(m.get('completeness')))" "$1"
  }
  if [ "$what" = full ]; then
    rm -rf MBF
    timed "continue, every scan again ($backend)" "$f" -q map B --continue MA/map.h5 -o MBF \
      --backend "$backend" $extra --no-mesh --set map.keep_unmoved=false
    cp MBF/report.json "$out/full_report.json"
    reintegration MBF/report.json
  else
    rm -rf MBS
    timed "continue, only where moved ($backend)" "$f" -q map B --continue MA/map.h5 -o MBS \
      --backend "$backend" $extra
    cp MBS/report.json "$out/moved_report.json"
    reintegration MBS/report.json
    python3 "$root/test/bench/pose_error.py" MBS/trajectory.tum B/gt_trajectory.tum "drive placed, vs truth"
    if [ -f MBF/map.h5 ]; then
      timed "eval maps" "$f" eval maps MBF/map.h5 MBS/map.h5 --json "$out/maps_difference.json"
      cat "$out/maps_difference.json"; echo
    fi
    timed "eval maps, loop before vs moved" "$f" eval maps MA/map.h5 MBS/map.h5 --json "$out/maps_before_moved.json"
    cat "$out/maps_before_moved.json"; echo
  fi
elif [ "$what" = drive ] || [ "$what" = merges ]; then
  # `drive`: only the drive mapped alone, for `merges` in a later call of the same machine.
  if [ "$what" = drive ] || [ ! -f MB2/map.h5 ]; then
    rm -rf B2 MB2
    mkdir B2 && for x in B/*; do case $x in *gt_*) ;; *) ln -s "$w/$x" B2/ ;; esac; done
    timed "map the drive alone ($backend)" "$f" -q map B2 -o MB2 --backend "$backend" $extra --no-mesh
    [ "$what" = drive ] && exit 0
  fi
  rm -rf MF* MS*
  # Alternating, ROUNDS times (default 1; a round is about 5 min on 16 cores).
  for round in $(seq "${ROUNDS:-1}"); do
    timed "merge $round, every scan again ($backend)" "$f" -q merge MA/map.h5 MB2/map.h5 \
      -o MF$round.h5 --backend "$backend" $extra --set map.keep_unmoved=false
    timed "merge $round, only where moved ($backend)" "$f" -q merge MA/map.h5 MB2/map.h5 \
      -o MS$round.h5 --backend "$backend" $extra
  done
  for h in MF*.h5 MS*.h5; do
    m=${h%.h5}
    cp $m.report.json "$out/${m}_report.json"
    python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
print(sys.argv[2], 'reintegration', json.dumps(r.get('reintegration')))" $m.report.json $m
  done
  for s in 0 1; do
    cmp MF1.session$s.tum MS1.session$s.tum && echo "session $s: the same poses in both merges"
  done
  python3 "$root/test/bench/pose_error.py" MS1.session1.tum B/gt_trajectory.tum "drive merged, vs truth"
  timed "eval maps, full vs moved" "$f" eval maps MF1.h5 MS1.h5 --json "$out/merges_difference.json"
  cat "$out/merges_difference.json"; echo
  timed "eval maps, loop before vs moved" "$f" eval maps MA/map.h5 MS1.h5 --json "$out/merges_before_moved.json"
  cat "$out/merges_before_moved.json"; echo
else
  rm -rf B2 MB2 MM.*
  mkdir B2 && for x in B/*; do case $x in *gt_*) ;; *) ln -s "$w/$x" B2/ ;; esac; done
  timed "map the drive alone ($backend)" "$f" -q map B2 -o MB2 --backend "$backend" $extra --no-mesh
  timed "merge ($backend)" "$f" -q merge MA/map.h5 MB2/map.h5 -o MM.h5 --backend "$backend" $extra
  cp MM.report.json "$out/merge_report.json"
  python3 "$root/test/bench/pose_error.py" MM.session1.tum B/gt_trajectory.tum "drive merged, vs truth"
  python3 "$root/test/bench/pose_error.py" MM.session0.tum A/gt_trajectory.tum "loop merged, vs truth"
  timed "mesh merged" "$f" -q mesh MM.h5 -o MM.ply
  mesh_figures merged MM.ply
fi
