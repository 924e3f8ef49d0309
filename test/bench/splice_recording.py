#!/usr/bin/env python3
"""Recordings spliced from simulated ones (`featsense simulate` folders of one sensor): the
scans of each PIECE one after the other, the stamps running on at the first recording's rate,
as if the sensor had been carried from the end of one piece to the start of the next between
two sweeps (a kidnapped sensor), or for a long run made of shorter ones. The truth
(gt_trajectory.tum) and the IMU (imu.csv) follow the scans; the frames are links to the
sources' files.

    splice_recording.py DEST SOURCE:FIRST:LAST [SOURCE:FIRST:LAST ...]
"""
import os
import sys


def read_frames(folder):
    header, frames = [], []
    for line in open(os.path.join(folder, "sequence.yaml")):
        if line.lstrip().startswith("- {file:"):
            body = line.strip()[3:-1]
            fields = dict(part.split(": ") for part in body.split(", "))
            frames.append((fields["file"], int(fields["stamp_ns"])))
        elif not line.startswith("frames:"):
            header.append(line)
    return header, frames


def main():
    dest, pieces = sys.argv[1], sys.argv[2:]
    if not pieces:
        sys.exit(__doc__)
    os.makedirs(dest, exist_ok=True)
    header = None
    period = None
    next_ns = None  # the stamp the next piece's first scan gets
    lines, truth, imu = [], [], []
    for k, piece in enumerate(pieces):
        source, first, last = piece.rsplit(":", 2)
        first, last = int(first), int(last)
        piece_header, frames = read_frames(source)
        if header is None:
            header, period = piece_header, frames[1][1] - frames[0][1]
            next_ns = frames[first][1]
        shift = next_ns - frames[first][1]
        for i in range(first, last + 1):
            name, stamp = frames[i]
            # Pieces of several recordings share file names: each piece's own prefix.
            linked = "p%d_%s" % (k, name)
            link = os.path.join(dest, linked)
            if not os.path.lexists(link):
                os.symlink(os.path.abspath(os.path.join(source, name)), link)
            lines.append("  - {file: %s, stamp_ns: %d}\n" % (linked, stamp + shift))
        from_ns, to_ns = frames[first][1] - period // 2, frames[last][1] + period // 2
        with open(os.path.join(source, "gt_trajectory.tum")) as src:
            for line in src:
                if line.startswith("#"):
                    continue
                fields = line.split()
                stamp = round(float(fields[0]) * 1e9)
                if from_ns <= stamp <= to_ns:
                    seconds, nanoseconds = divmod(stamp + shift, 10**9)
                    truth.append("%d.%09d %s\n" % (seconds, nanoseconds, " ".join(fields[1:])))
        imu_path = os.path.join(source, "imu.csv")
        if os.path.exists(imu_path):
            with open(imu_path) as src:
                imu_header = src.readline()
                for line in src:
                    stamp = int(line.split(",", 1)[0])
                    if from_ns <= stamp < to_ns:
                        imu.append("%d,%s" % (stamp + shift, line.split(",", 1)[1]))
        next_ns = frames[last][1] + shift + period
    with open(os.path.join(dest, "sequence.yaml"), "w") as out:
        out.writelines(header)
        out.write("frames:\n")
        out.writelines(lines)
    with open(os.path.join(dest, "gt_trajectory.tum"), "w") as out:
        out.write("# timestamp tx ty tz qx qy qz qw\n")
        out.writelines(truth)
    if imu:
        with open(os.path.join(dest, "imu.csv"), "w") as out:
            out.write(imu_header)
            out.writelines(imu)


if __name__ == "__main__":
    main()
