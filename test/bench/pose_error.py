"""Poses of a TUM file against the truth at the same stamps, without alignment: position and
rotation error, mean and max. Usage: pose_error.py ESTIMATE.tum TRUTH.tum [label]"""
import math
import sys


def read_tum(path):
    rows = {}
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        rows[round(v[0], 4)] = v
    return rows


def rotation_deg(qa, qb):
    # angle of qa * qb^-1
    dot = abs(sum(a * b for a, b in zip(qa, qb)))
    return 2.0 * math.degrees(math.acos(min(1.0, dot)))


estimate = read_tum(sys.argv[1])
truth = read_tum(sys.argv[2])
pos, rot = [], []
for stamp, e in sorted(estimate.items()):
    t = truth.get(stamp)
    if t is None:
        continue
    pos.append(math.dist(e[1:4], t[1:4]))
    rot.append(rotation_deg(e[4:8], t[4:8]))
label = sys.argv[3] if len(sys.argv) > 3 else sys.argv[1]
if not pos:
    print(label, ": no common stamps")
else:
    print("%s: %d poses, position error mean %.3f max %.3f m, rotation error mean %.3f max %.3f deg"
          % (label, len(pos), sum(pos) / len(pos), max(pos), sum(rot) / len(rot), max(rot)))
