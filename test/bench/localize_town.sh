#!/usr/bin/env bash
# Localization in a saved map of the town: the loop mapped once (odometry, loops, gravity; the
# map's frame is the simulation's, the run starting from the true first pose), then recordings
# the map never saw localized in it with their truth beside them.
#
#   localize_town.sh WORK [PATH[@SCAN] ...]
#                      (default: drive walk kidnap drive-changed walk-changed lab)
#
# PATH@SCAN localizes the recording from its scan SCAN on (`--start`), into WORK/loc_PATH@SCAN:
# walk@300 and drive@160 start on the loop's streets, 70 m and 52 m from the loop's start (the
# walk itself starts on a street the loop only crossed, 44 m from the loop's path).
# kidnap is the drive with its scans 400-659 cut out (splice_recording.py): between two sweeps
# the sensor is 114 m away, on another street. drive-changed and walk-changed are the drive
# and the walk through the town on another day (--scene town-changed: the parked cars moved).
# lab is the lab walk (another place, an indoor room): it must never be found (exit status 3).
#
# WORK/town_loop, WORK/loop_map (featsense simulate --scene town --path loop --seed 4; featsense
# map --no-mesh: 5 to 30 min on 2 cores) and WORK/town_PATH (featsense simulate --path PATH)
# are made where missing. Each run writes WORK/loc_PATH/ (trajectory.tum, localization.csv,
# report.json with eval against the truth) and WORK/loc_PATH.time.txt (/usr/bin/time -v), and
# prints one JSON line: the first fix, the scans by status, the errors of the localized poses,
# tracking time and peak memory, and the share localized after the first fix by how far the
# sensor is from the loop's path (the map holds a surface within half of map.size's horizontal
# extent of where the loop went, 20 m by default; beyond it only the keyframes' points).
# FEATSENSE names the program (default: build/app/featsense); MAP_DIR the loop map's folder in
# WORK (default loop_map) and MAP_OPTIONS more options for making it (e.g. "--set
# map.size=[80,80,15]").
set -euo pipefail
work=$1
shift
paths=("$@")
[ ${#paths[@]} -gt 0 ] || paths=(drive walk kidnap drive-changed walk-changed lab)
featsense=${FEATSENSE:-build/app/featsense}
mkdir -p "$work"
[ -d "$work/town_loop" ] ||
  "$featsense" simulate --quiet --scene town --path loop --seed 4 -o "$work/town_loop"
map_dir=$work/${MAP_DIR:-loop_map}
# shellcheck disable=SC2086  # MAP_OPTIONS is a list of options
[ -f "$map_dir/map.h5" ] ||
  "$featsense" map --quiet "$work/town_loop" -o "$map_dir" --no-mesh ${MAP_OPTIONS:-}
here=$(dirname "$0")
for spec in "${paths[@]}"; do
  path=${spec%@*}
  start=0
  [ "$spec" = "$path" ] || start=${spec#*@}
  scene=town
  route=${path%-changed}
  [ "$route" = "$path" ] || scene=town-changed
  case $route in drive) seed=8 ;; walk) seed=7 ;; *) seed=9 ;; esac
  if [ "$path" = kidnap ]; then
    [ -d "$work/town_drive" ] ||
      "$featsense" simulate --quiet --scene town --path drive --seed 8 -o "$work/town_drive"
    [ -d "$work/town_kidnap" ] ||
      python3 "$here/splice_recording.py" "$work/town_kidnap" "$work/town_drive:0:399" \
        "$work/town_drive:660:901"
  fi
  if [ "$path" = lab ]; then
    [ -d "$work/town_lab" ] ||
      "$featsense" simulate --quiet --scene lab --path walk --seed 5 -o "$work/town_lab"
  fi
  [ -d "$work/town_$path" ] ||
    "$featsense" simulate --quiet --scene $scene --path "$route" --seed $seed -o "$work/town_$path"
  rc=0
  /usr/bin/time -v -o "$work/loc_$spec.time.txt" "$featsense" localize --quiet \
    "$map_dir/map.h5" "$work/town_$path" -o "$work/loc_$spec" --start "$start" \
    --gt "$work/town_$path/gt_trajectory.tum" || rc=$?
  python3 - "$work/loc_$spec/report.json" "$spec" "$rc" "$work/town_loop/gt_trajectory.tum" \
    "$work/town_$path/gt_trajectory.tum" "$work/loc_$spec/localization.csv" "$start" <<'PY'
import csv, json, math, sys
r = json.load(open(sys.argv[1]))
loc, ev, t = r["localization"], r.get("eval", {}), r["timings"]
fix = loc.get("first_fix", {})
out = {"path": sys.argv[2], "exit_status": int(sys.argv[3]), "frames": r["frames"],
       "scans": loc["scans"],
       "first_fix_s": fix.get("seconds_in"), "found_by": fix.get("found_by"),
       "localized_share_after_first_fix": loc.get("localized_share_after_first_fix"),
       "losses": loc["losses"],
       "localized_error_m": ev.get("localized", {}).get("translation_m"),
       "localized_error_deg": ev.get("localized", {}).get("rotation_deg"),
       "localized_over_0_5_m": ev.get("localized_over_0_5_m"),
       "tracking_ms": {k: t["tracking"][k] for k in ("median_ms", "p95_ms")},
       "tracking_parts_median_ms": {k: v["median_ms"] for k, v in t["tracking_parts"].items()
                                    if isinstance(v, dict)},
       "search_total_s": t["search_total_s"], "peak_rss_mb": r["peak_rss_mb"],
       "map_cache": r["map_cache"]}


def positions(path):
    return [tuple(map(float, line.split()[1:3])) for line in open(path)
            if line.strip() and not line.startswith("#")]


# The share localized after the first fix, by the sensor's true distance from the loop's path.
loop = positions(sys.argv[4])[::2]
rows = list(csv.DictReader(open(sys.argv[6])))
truth = positions(sys.argv[5])[int(sys.argv[7]):]
# Where the run starts: how far from the loop's start and from its path.
out["start_from_loop_start_m"] = round(math.dist(truth[0], loop[0]), 1)
out["start_from_loop_path_m"] = round(min(math.dist(truth[0], p) for p in loop), 1)
bins = {"within_20_m": [0, 0], "20_to_30_m": [0, 0], "beyond_30_m": [0, 0]}
fixed = False
for row, (x, y) in zip(rows, truth):
    fixed = fixed or row["status"] == "localized"
    if not fixed:
        continue
    d = min(math.hypot(x - a, y - b) for a, b in loop)
    key = "within_20_m" if d <= 20 else "20_to_30_m" if d <= 30 else "beyond_30_m"
    bins[key][0] += row["status"] == "localized"
    bins[key][1] += 1
out["localized_after_first_fix_by_distance_from_loop"] = {
    k: {"scans": n, "localized": round(l / n, 3)} for k, (l, n) in bins.items() if n}
print(json.dumps(out))
PY
done
