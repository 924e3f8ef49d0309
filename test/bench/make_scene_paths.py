#!/usr/bin/env python3
"""Sensor paths (TUM) through the two real places of ../shared/data/scenes, for mapping them
with `featsense simulate --scene MESH --trajectory PATH.tum`:
  small_house.tum   a drone loop 1.5 m above the 3 m walls of the house (it has no ceiling),
                    pitched 15 deg down so the rooms' floors come into view, 1.5 m/s;
  gas_station.tum   a car loop round the shop, pumps and sign at 1.8 m, 4 m/s.
Corners are rounded (3 m radius) so that the yaw turns smoothly. Usage: make_scene_paths.py DIR
"""
import math
import os
import sys


def loop(x0, y0, x1, y1, radius, step):
    """Points and headings along a rectangle with rounded corners, counter-clockwise."""
    corners = [(x1 - radius, y0 + radius, -math.pi / 2), (x1 - radius, y1 - radius, 0.0),
               (x0 + radius, y1 - radius, math.pi / 2), (x0 + radius, y0 + radius, math.pi)]
    starts = [(x0 + radius, y0), (x1, y0 + radius), (x1 - radius, y1), (x0, y1 - radius)]
    ends = [(x1 - radius, y0), (x1, y1 - radius), (x0 + radius, y1), (x0, y0 + radius)]
    headings = [0.0, math.pi / 2, math.pi, -math.pi / 2]
    points = []
    for side in range(4):
        (ax, ay), (bx, by) = starts[side], ends[side]
        length = math.hypot(bx - ax, by - ay)
        n = max(1, int(length / step))
        for i in range(n):
            f = i / n
            points.append((ax + f * (bx - ax), ay + f * (by - ay), headings[side]))
        cx, cy, a0 = corners[side]
        n = max(1, int(radius * math.pi / 2 / step))
        for i in range(n):
            a = a0 + (i / n) * math.pi / 2
            points.append((cx + radius * math.cos(a), cy + radius * math.sin(a), headings[side] + (i / n) * math.pi / 2))
    points.append(points[0])
    return points


def quaternion(yaw, pitch):
    """q = Rz(yaw) * Ry(pitch) as (x, y, z, w)."""
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    return (-sy * sp, cy * sp, sy * cp, cy * cp)


def write(path, points, z, speed, pitch_deg, start_s=1700000000.0):
    pitch = math.radians(pitch_deg)
    t = start_s
    with open(path, "w") as out:
        out.write("# timestamp tx ty tz qx qy qz qw\n")
        previous = None
        for x, y, yaw in points:
            if previous is not None:
                t += math.hypot(x - previous[0], y - previous[1]) / speed
            qx, qy, qz, qw = quaternion(yaw, pitch)
            out.write(f"{t:.9f} {x:.6f} {y:.6f} {z:.6f} {qx:.9f} {qy:.9f} {qz:.9f} {qw:.9f}\n")
            previous = (x, y)


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(folder, exist_ok=True)
    write(os.path.join(folder, "small_house.tum"), loop(-7.5, -3.5, 7.5, 3.5, 3.0, 0.1), 4.5, 1.5, 15.0)
    write(os.path.join(folder, "gas_station.tum"), loop(-16.0, -30.0, 16.0, 12.0, 3.0, 0.2), 1.8, 4.0, 0.0)


if __name__ == "__main__":
    main()
