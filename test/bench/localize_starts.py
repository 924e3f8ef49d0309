#!/usr/bin/env python3
"""How soon the sensor is found, started anywhere: a recording localized from every EVERY-th
scan on (each run 10 s of it, --start S --end S+99), in a map of the town loop, with its
truth. Each start that lies at least 50 m from the loop's first pose is run; each prints a
JSON line: the start, how far its true position lies from the map's nearest keyframe (the
search matches keyframes: a place the map's path never came near is found once the sensor
gets near it), the first fix's time after the start, how it was found, and its error.

    localize_starts.py WORK PATH [EVERY]    (WORK as for localize_town.sh; EVERY 100)

FEATSENSE names the program (default: build/app/featsense).
"""
import json
import math
import os
import subprocess
import sys


def tum(path):
    poses = []
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        f = line.split()
        poses.append((round(float(f[0]) * 1e9), [float(v) for v in f[1:4]]))
    return poses


def main():
    work, path = sys.argv[1], sys.argv[2]
    every = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    featsense = os.environ.get("FEATSENSE", "build/app/featsense")
    recording = os.path.join(work, "town_" + path)
    truth = dict(tum(os.path.join(recording, "gt_trajectory.tum")))
    loop = tum(os.path.join(work, "town_loop", "gt_trajectory.tum"))
    keyframes = [p for _, p in tum(os.path.join(work, "loop_map", "trajectory.tum"))]
    loop_start = loop[0][1]
    stamps = []
    for line in open(os.path.join(recording, "sequence.yaml")):
        if "stamp_ns:" in line:
            stamps.append(int(line.split("stamp_ns:")[1].strip().rstrip("}")))
    for start in range(0, len(stamps) - 50, every):
        where = truth.get(stamps[start])
        if where is None or math.dist(where[:2], loop_start[:2]) < 50.0:
            continue
        out = os.path.join(work, "starts_%s_%d" % (path, start))
        subprocess.run([featsense, "localize", "--quiet", "--no-plan",
                        os.path.join(work, "loop_map", "map.h5"), recording, "-o", out,
                        "--start", str(start), "--end", str(start + 99), "--gt",
                        os.path.join(recording, "gt_trajectory.tum")],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        report = json.load(open(os.path.join(out, "report.json")))
        loc = report["localization"]
        fix = loc.get("first_fix", {})
        errors = report.get("eval", {}).get("localized", {}).get("translation_m") or {}
        print(json.dumps({
            "path": path, "start": start,
            "from_loop_start_m": round(math.dist(where[:2], loop_start[:2]), 1),
            "nearest_keyframe_m": round(min(math.dist(where, k) for k in keyframes), 1),
            "first_fix_s": fix.get("seconds_in"), "found_by": fix.get("found_by"),
            "localized": loc["scans"]["localized"], "odometry": loc["scans"]["odometry"],
            "lost": loc["scans"]["lost"],
            "max_error_m": errors.get("max"),
            "over_0_5_m": report.get("eval", {}).get("localized_over_0_5_m"),
            "search_s": report["timings"]["search_total_s"]}), flush=True)


if __name__ == "__main__":
    main()
