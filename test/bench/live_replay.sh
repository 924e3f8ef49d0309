#!/usr/bin/env bash
# A dry run of live mapping over loopback: `featsense replay` sends a recording's packets with
# their recorded timing while `featsense live` maps them, as it would map the sensor.
#
#   live_replay.sh WORK NAME [--rate R] [--drop F] [--backend B] [--velodyne PRESET] [--view]
#                  [-- live options...]
#
# WORK holds town_drive/ (made here when missing: `featsense simulate --scene town --path drive
# --format ouster-pcap`, an OS1-128 at 1024x10 with IMU, 90 s, 1.5 GB), or with --velodyne
# hdl32|vlp32c town_drive_PRESET/ (`--format velodyne-pcap`, 160 MB). The run writes
# WORK/NAME/ (what live writes, report.json with timings.latency and real_time, its eval against
# the simulation's truth), WORK/NAME.replay.json and WORK/NAME.rss.txt (the live process's
# resident memory every 2 s, kB). --view: the live page served, and asked for its changes every
# second as a browser would (poll_live_view.py; WORK/NAME.view.json). FEATSENSE names the
# program (default: build/app/featsense).
set -euo pipefail
work=$1 name=$2
shift 2
rate=1 drop=0 backend=auto velodyne= view=()
while [ $# -gt 0 ]; do
  case $1 in
    --velodyne) velodyne=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --drop) drop=$2; shift 2 ;;
    --backend) backend=$2; shift 2 ;;
    --view) view=(--view --view-port 0); shift ;;
    --) shift; break ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
featsense=${FEATSENSE:-build/app/featsense}
mkdir -p "$work"
if [ -z "$velodyne" ]; then
  drive=$work/town_drive
  format=(--format ouster-pcap)
  sensor=(--sensor ouster --meta "$drive/recording.json")
else
  drive=$work/town_drive_$velodyne
  format=(--format velodyne-pcap --sensor "$velodyne")
  sensor=(--sensor velodyne)
fi
if [ ! -f "$drive/recording.pcap" ]; then
  "$featsense" simulate --scene town --path drive "${format[@]}" -o "$drive" --quiet
fi
out=$work/$name
rm -rf "$out"
log=$work/$name.live.log
"$featsense" live "${sensor[@]}" --host 127.0.0.1 -o "$out" \
  --idle-timeout 5 --backend "$backend" --reference-trajectory "$drive/gt_trajectory.tum" \
  --reference "$drive/gt_mesh.ply" "${view[@]}" "$@" > "$log" 2>&1 &
live=$!
poller=
if [ ${#view[@]} -gt 0 ]; then
  python3 "$(dirname "$0")/poll_live_view.py" "$log" "$work/$name.view.json" > /dev/null &
  poller=$!
fi
for _ in $(seq 1 300); do grep -q listening "$log" 2>/dev/null && break; sleep 0.1; done
while kill -0 $live 2>/dev/null; do
  echo "$(date +%s.%N) $(awk '/VmRSS/ {print $2}' /proc/$live/status 2>/dev/null)"
  sleep 2
done > "$work/$name.rss.txt" &
"$featsense" replay "$drive/recording.pcap" --rate "$rate" --drop "$drop" --seed 1 \
  --json "$work/$name.replay.json"
wait $live
[ -z "$poller" ] || wait $poller
