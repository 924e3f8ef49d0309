#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along (the
# featsense program and its libraries, ../shared/tools/device-bundle): live mapping over
# loopback on the CUDA backend (test/bench/live_replay.sh). The simulated town drive is made
# there, replayed at 1x while `featsense live` maps it, and mapped offline from the same pcap;
# the figures, one JSON line per run (live_figures.py), go to $OUT.
#   run_gpu_live.sh [ouster] [view] [vlp32c] [offline]   (default: ouster vlp32c offline)
# ouster: the OS1-128 drive live; view: the same with the live page served and asked for its
# changes every second (live_replay.sh --view); vlp32c: a VLP-32C's drive live; offline: both
# pcaps mapped by `featsense map`.
set -uo pipefail
steps=${*:-ouster vlp32c offline}
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
export FEATSENSE=/tmp/bundle/bin/featsense
out=${OUT:-/tmp/out}
work=/tmp/live
mkdir -p "$out" "$work"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
lscpu | grep "Model name"
nproc
offline() {  # NAME DRIVE
  /usr/bin/time -f "offline $1 %e s %M KB" "$FEATSENSE" map "$2/recording.pcap" -o "$work/$1" \
    --backend cuda --reference-trajectory "$2/gt_trajectory.tum" --reference "$2/gt_mesh.ply" \
    --quiet
}
runs=()
for step in $steps; do
  case $step in
    ouster) bash test/bench/live_replay.sh "$work" gpu_live --backend cuda
            runs+=(gpu_live) ;;
    view) bash test/bench/live_replay.sh "$work" gpu_live_view --backend cuda --view \
            -- --three "${THREE:-.device/three}"
          cp "$work/gpu_live_view.view.json" "$out/" 2>/dev/null
          runs+=(gpu_live_view) ;;
    vlp32c) bash test/bench/live_replay.sh "$work" gpu_live_vlp32c --backend cuda --velodyne vlp32c
            runs+=(gpu_live_vlp32c) ;;
    offline) [ -f "$work/town_drive/recording.pcap" ] && offline gpu_offline "$work/town_drive" &&
               runs+=(gpu_offline)
             [ -f "$work/town_drive_vlp32c/recording.pcap" ] &&
               offline gpu_offline_vlp32c "$work/town_drive_vlp32c" && runs+=(gpu_offline_vlp32c) ;;
  esac
done
for run in "${runs[@]}"; do tail -2 "$work/$run.live.log" 2>/dev/null; done
python3 test/bench/live_figures.py "$work" "${runs[@]}" | tee "$out/live_figures.jsonl"
for run in "${runs[@]}"; do cp "$work/$run/report.json" "$out/${run}_report.json"; done
# A Velodyne's packets carry the time past the full hour only: a live run is stamped by this
# machine's clock, and its poses are compared with the truth here, shifted by whole hours.
[ -f "$work/gpu_live_vlp32c/trajectory.tum" ] &&
  cp "$work/gpu_live_vlp32c/trajectory.tum" "$out/gpu_live_vlp32c_trajectory.tum"
true
