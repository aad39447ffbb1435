#!/usr/bin/env python3
"""Writes a synthetic RIDI recording of N rows at 200 Hz: a phone held still upright (its y
axis up) but shaking a little (valid for every reader check), for memory benchmarks of `ridi track --online` and
`ridi inspect`. Usage: long_recording.py ROWS OUT.csv writes a processed data.csv;
long_recording.py --raw ROWS OUT writes a raw folder OUT (gyro.txt, acce.txt, linacce.txt,
gravity.txt, orientation.txt and a still pose.txt as the clock, ROWS records each)."""
import math
import os
import sys

raw = sys.argv[1] == "--raw"
rows, out = int(sys.argv[1 + raw]), sys.argv[2 + raw]
# One period of 1000 distinct frames; the time stamps make every row different.
frames = []
for i in range(1000):
    s, c = math.sin(i * 0.0628), math.cos(i * 0.0377)
    gyro = (0.02 * s, 0.03 * c, 0.01 * s * c)
    lin = (0.3 * s, 0.2 * c, 0.1 * s)
    grav = (0.0, 9.8, 0.0)
    acce = tuple(g + l for g, l in zip(grav, lin))
    frames.append((gyro, acce, lin, grav))
t0 = 1_000_000_000
# Upright: a turn by 90 degrees about x takes the y axis, along gravity, up.
r = math.sqrt(0.5)


def cells(values, sep):
    return sep.join(f"{v:.4f}" for v in values)


if not raw:
    header = ",time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z,linacce_x,linacce_y,linacce_z," \
             "grav_x,grav_y,grav_z,rv_w,rv_x,rv_y,rv_z\n"
    body = [cells(sum(f, ()), ",") + f",{r!r},{r!r},0,0\n" for f in frames]
    with open(out, "w") as f:
        f.write(header)
        for i in range(rows):
            f.write(f"{i},{t0 + 5_000_000 * i},{body[i % 1000]}")
    sys.exit()

os.makedirs(out, exist_ok=True)
for k, name in enumerate(["gyro.txt", "acce.txt", "linacce.txt", "gravity.txt"]):
    body = [cells(f[k], " ") + "\n" for f in frames]
    with open(os.path.join(out, name), "w") as f:
        f.write("# t x y z\n")
        for i in range(rows):
            f.write(f"{t0 + 5_000_000 * i} {body[i % 1000]}")
for name, header, values in [("orientation.txt", "# t x y z w", f"{r!r} 0 0 {r!r}"),
                             ("pose.txt", "# t tx ty tz qx qy qz qw", "1.5 -2 1.2 0 0 0 1")]:
    with open(os.path.join(out, name), "w") as f:
        f.write(header + "\n")
        for i in range(rows):
            f.write(f"{t0 + 5_000_000 * i} {values}\n")
