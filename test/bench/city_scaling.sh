#!/usr/bin/env bash
# Time and peak memory of each command against the route's length: prefixes of the city's
# 5 km tour (featsense simulate --scene city --path tour --frames N, 7 m/s at 10 Hz, so
# N = km * 10000 / 7), each simulated, mapped with its mesh as a tile set and compared with
# the truth (map --tiles), meshed again with cleanup (mesh --tiles --clean), its navigation
# layers made tile by tile (navmesh on the cleaned tile set), evaluated again by region (eval
# mesh on the tile set against gt_points.ply) and its report page written again (report).
#
#   city_scaling.sh WORK [KM ...]   (default: 1 2.5 5)
#
# Writes WORK/city_KM/ (the recording; removed after mapping unless KEEP=1), WORK/map_KM/,
# WORK/clean_KM/, WORK/nav_KM/, WORK/eval_KM.json and one WORK/KM.COMMAND.time.txt
# (/usr/bin/time -v) per command, and prints one JSON line per route: the frames, each
# command's wall seconds and peak RSS (GB), and the map's figures.
# FEATSENSE names the program (default: build/app/featsense); BACKEND the TSDF backend (auto);
# FORMAT the recording's (simulate --format): ouster-pcap (default: the sensor's packets, 2.4 GB
# a kilometre) or folder (PCD frames, 5.6 GB a kilometre). Both map to the same figures (the
# first 300 frames: ATE 6.07 mm from the pcap, 6.04 mm from the folder).
set -euo pipefail
work=$1
shift
routes=("$@")
[ ${#routes[@]} -gt 0 ] || routes=(1 2.5 5)
featsense=${FEATSENSE:-build/app/featsense}
backend=${BACKEND:-auto}
format=${FORMAT:-ouster-pcap}
mkdir -p "$work"

timed() {  # timed KM NAME COMMAND...
  local km=$1 name=$2
  shift 2
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -v -o "$work/$km.$name.time.txt" "$@"
    return
  fi
  # Machines without GNU time (the GPU machine): the same two lines from the kernel's
  # accounting of the finished child (ru_maxrss is in kilobytes on Linux).
  python3 - "$work/$km.$name.time.txt" "$@" <<'PY'
import resource, subprocess, sys, time
start = time.monotonic()
status = subprocess.call(sys.argv[2:])
wall = time.monotonic() - start
peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
with open(sys.argv[1], "w") as out:
    out.write("\tElapsed (wall clock) time (h:mm:ss or m:ss): %d:%05.2f\n" % divmod(wall, 60))
    out.write("\tMaximum resident set size (kbytes): %d\n" % peak_kb)
    out.write("\tExit status: %d\n" % status)
sys.exit(status)
PY
}

for km in "${routes[@]}"; do
  frames=$(python3 -c "print(round($km * 10000 / 7))")
  sim="$work/city_$km"
  rm -rf "$sim" "$work/map_$km" "$work/clean_$km" "$work/nav_$km"
  timed "$km" simulate "$featsense" simulate --quiet --scene city --path tour --seed 4 \
    --frames "$frames" --format "$format" -o "$sim"
  input="$sim"
  [ "$format" = folder ] || input="$sim/recording.pcap"
  timed "$km" map "$featsense" map --quiet "$input" -o "$work/map_$km" --tiles --backend "$backend"
  [ "${KEEP:-0}" = 1 ] || rm -f "$sim"/frame_*.pcd "$sim"/recording.pcap
  timed "$km" mesh_clean "$featsense" mesh --quiet "$work/map_$km/map.h5" \
    --tiles "$work/clean_$km" --clean
  timed "$km" navmesh "$featsense" navmesh "$work/clean_$km" -o "$work/nav_$km"
  timed "$km" eval_mesh "$featsense" eval mesh "$work/map_$km/tiles" "$sim/gt_points.ply" \
    --json "$work/eval_$km.json"
  timed "$km" report "$featsense" report "$work/map_$km"
  python3 - "$work" "$km" "$frames" <<'PY'
import json, re, sys
work, km, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])

def figures(name):
    text = open(f"{work}/{km}.{name}.time.txt").read()
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = 60 * seconds + float(part)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
    return {"wall_s": round(seconds, 1), "peak_rss_gb": round(rss / 1e6, 2)}

report = json.load(open(f"{work}/map_{km}/report.json"))
ev = report.get("eval", {})
out = {"route_km": float(km), "frames": frames,
       "commands": {name: figures(name)
                    for name in ("simulate", "map", "mesh_clean", "navmesh", "eval_mesh",
                                 "report")},
       "chunks": report["map"]["chunks"],
       "triangles": report["mesh"]["triangles"],
       "tiles": report["mesh"]["tiles"]["tiles"],
       "ate_m": ev.get("traj", {}).get("ape", {}).get("rmse"),
       "mesh_mean_abs_m": ev.get("mesh", {}).get("accuracy", {}).get("mean_abs"),
       "completeness_0.10": ev.get("mesh", {}).get("completeness", {}).get("0.10")}
print(json.dumps(out))
PY
done
