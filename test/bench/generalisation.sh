#!/bin/bash
# The generalisation table: every built-in scene along paths the front end was not tuned on
# (the lab walk and the parking drive are the tuned ones), mapped with the default settings
# and estimated poses, ATE and mesh accuracy per run in one table.
#
# usage: test/bench/generalisation.sh FEATSENSE WORKDIR [SCENE:PATH ...]
#   FEATSENSE  the featsense program (e.g. build/app/featsense)
#   WORKDIR    simulated recordings are kept there (re-used), maps written below it
#   SCENE:PATH the runs (default: the list below); SCENE:PATH:STOP adds --stop STOP. A SCENE
#              that is a mesh file takes a TUM file as PATH (--trajectory), e.g. the paths of
#              test/bench/make_scene_paths.py
# Prints one JSON object per run, then a Markdown table; writes WORKDIR/generalisation.json.
set -euo pipefail
featsense=$(realpath "$1")
work=$2
shift 2
runs=("$@")
if [ ${#runs[@]} -eq 0 ]; then
  runs=(lab:walk lab:drive lab:drone corridor:walk corridor:drone parking:walk parking:drive
        parking:drone parking:drive:15,30)
fi
mkdir -p "$work"
results="$work/generalisation.jsonl"
: >"$results"
for run in "${runs[@]}"; do
  IFS=: read -r scene path stop <<<"$run"
  name="$(basename "${scene%.*}")_$(basename "${path%.*}")${stop:+_stop${stop//,/_}}"
  seq="$work/seq_$name"
  route=(--path "$path")
  [ -f "$scene" ] && route=(--trajectory "$path")
  if [ ! -f "$seq/gt_trajectory.tum" ]; then
    rm -rf "$seq"
    "$featsense" simulate --scene "$scene" "${route[@]}" ${stop:+--stop "$stop"} -o "$seq" \
      --quiet
  fi
  out="$work/map_$name"
  start=$(date +%s.%N)
  "$featsense" map "$seq" -o "$out" --overwrite --quiet
  end=$(date +%s.%N)
  python3 - "$out/report.json" "$name" "$(echo "$end - $start" | bc)" >>"$results" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
ev = report.get("eval", {})
def get(*keys):
    node = ev
    for k in keys:
        if not isinstance(node, dict) or k not in node:
            return None
        node = node[k]
    return node
mesh = get("mesh", "accuracy", "mean_abs")
row = {
    "run": sys.argv[2],
    "scans": report.get("frames"),
    "ate_mm": None if get("traj", "ape", "rmse") is None else 1000 * get("traj", "ape", "rmse"),
    "mesh_mean_mm": None if mesh is None else 1000 * mesh,
    "standing_scans": report["odometry"].get("standing", {}).get("scans"),
    "degenerate_scans": report["odometry"]["degenerate_scans"],
    "failed_scans": report["odometry"]["failed_scans"],
    "loops": report["loops"]["accepted"],
    "wall_s": float(sys.argv[3]),
}
print(json.dumps(row))
PY
  tail -1 "$results"
done
python3 - "$results" "$work/generalisation.json" <<'PY'
import json, sys
rows = [json.loads(line) for line in open(sys.argv[1])]
json.dump(rows, open(sys.argv[2], "w"), indent=1)
fmt = lambda v: "-" if v is None else (f"{v:.1f}" if isinstance(v, float) else str(v))
print("| run | scans | ATE mm | mesh mean mm | standing | degenerate | failed | loops | wall s |")
print("|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print("| " + " | ".join(fmt(r[k]) for k in ["run", "scans", "ate_mm", "mesh_mean_mm",
          "standing_scans", "degenerate_scans", "failed_scans", "loops", "wall_s"]) + " |")
PY
