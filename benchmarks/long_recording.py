#!/usr/bin/env python3
"""Writes a synthetic RIDI processed data.csv of N rows at 200 Hz: a phone lying still but
shaking a little (valid for every reader check), for memory benchmarks of `ridi track --online`
and `ridi inspect`. Usage: long_recording.py ROWS OUT.csv"""
import math
import sys

rows, out = int(sys.argv[1]), sys.argv[2]
header = ",time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z,linacce_x,linacce_y,linacce_z," \
         "grav_x,grav_y,grav_z,rv_w,rv_x,rv_y,rv_z\n"
# One period of 1000 distinct rows; the time stamps make every row different.
body = []
for i in range(1000):
    s, c = math.sin(i * 0.0628), math.cos(i * 0.0377)
    gyro = (0.02 * s, 0.03 * c, 0.01 * s * c)
    lin = (0.3 * s, 0.2 * c, 0.1 * s)
    grav = (0.0, 9.8, 0.0)
    acce = tuple(g + l for g, l in zip(grav, lin))
    vals = gyro + acce + lin + grav
    body.append(",".join(f"{v:.4f}" for v in vals) + ",1,0,0,0\n")
with open(out, "w") as f:
    f.write(header)
    t0 = 1_000_000_000
    for i in range(rows):
        f.write(f"{i},{t0 + 5_000_000 * i},{body[i % 1000]}")
