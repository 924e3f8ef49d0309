#!/usr/bin/env python3
"""A kidnapped sensor, made from a simulated recording: scans FIRST..LAST of a `featsense
simulate` folder followed at once by scans RESUME..END, as if the sensor had been carried from
one place to the other between two sweeps. The stamps run on at the recording's rate; the truth
(gt_trajectory.tum) and the IMU (imu.csv, shifted likewise) follow the scans; the frames are
links to the source's files.

    splice_recording.py SOURCE DEST FIRST:LAST RESUME:END
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
    source, dest, first_part, second_part = sys.argv[1:5]
    first, last = map(int, first_part.split(":"))
    resume, end = map(int, second_part.split(":"))
    header, frames = read_frames(source)
    period = frames[1][1] - frames[0][1]
    # Each kept scan's source stamp -> its stamp in the splice.
    shift = {}
    for i in range(first, last + 1):
        shift[frames[i][1]] = 0
    jump = frames[last][1] + period - frames[resume][1]
    for i in range(resume, end + 1):
        shift[frames[i][1]] = jump
    os.makedirs(dest, exist_ok=True)
    with open(os.path.join(dest, "sequence.yaml"), "w") as out:
        out.writelines(header)
        out.write("frames:\n")
        for i in list(range(first, last + 1)) + list(range(resume, end + 1)):
            name, stamp = frames[i]
            link = os.path.join(dest, name)
            if not os.path.lexists(link):
                os.symlink(os.path.abspath(os.path.join(source, name)), link)
            out.write("  - {file: %s, stamp_ns: %d}\n" % (name, stamp + shift[stamp]))
    first_ns, last_ns = frames[first][1], frames[last][1] + period // 2
    resume_ns, end_ns = frames[resume][1] - period // 2, frames[end][1] + period
    with open(os.path.join(source, "gt_trajectory.tum")) as src, \
            open(os.path.join(dest, "gt_trajectory.tum"), "w") as out:
        for line in src:
            if line.startswith("#"):
                out.write(line)
                continue
            fields = line.split()
            stamp = round(float(fields[0]) * 1e9)
            if stamp in shift:
                t = (stamp + shift[stamp]) * 1e-9
                out.write("%.9f %s\n" % (t, " ".join(fields[1:])))
    imu = os.path.join(source, "imu.csv")
    if os.path.exists(imu):
        with open(imu) as src, open(os.path.join(dest, "imu.csv"), "w") as out:
            out.write(src.readline())
            for line in src:
                stamp = int(line.split(",", 1)[0])
                if first_ns <= stamp < last_ns:
                    out.write(line)
                elif resume_ns <= stamp <= end_ns:
                    out.write("%d,%s" % (stamp + jump, line.split(",", 1)[1]))


if __name__ == "__main__":
    main()
