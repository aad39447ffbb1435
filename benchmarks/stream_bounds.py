#!/usr/bin/env python3
"""The real-data figures behind two validation bounds (docs/benchmarks.md, "Bounds of the
live stream check"): over every second (200 frames, every 20th window) of every recording, the
median |acce| in g, the median |gyro| and the median rate, which `ridi::STREAM_ACCE_G`, the
median gyro bound and the rate tolerance of `LiveTracker` must hold; and per recording the
median angle between gravity and the orientation's up axis, which
`Validation::max_orientation_gravity_deg` (45 degrees) must hold.

Usage: benchmarks/stream_bounds.py [SHARED]  (SHARED defaults to ../shared; needs the `ridi`
Python package: `pip install ./crates/ridi-py`). Reads the shared Tyrex runs (both phones),
the Indoor Location Competition walks and the bundled sample."""
import glob
import os
import sys
import warnings

import numpy as np

import ridi

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "..", "shared")
RAW = os.path.join(SHARED, "data", "raw")
WINDOW, STEP, G = 200, 20, 9.80665


def seconds(x):
    """The median of `x` over every WINDOW values, every STEP."""
    return np.array([np.median(x[i:i + WINDOW]) for i in range(0, len(x) - WINDOW + 1, STEP)])


def up_angles(s):
    """Degrees between gravity and the up axis of each frame's orientation (world-from-device
    [w, x, y, z]): the third row of the rotation matrix, seen from the device."""
    w, x, y, z = s.orientation.T
    up = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    g = s.gravity / np.linalg.norm(s.gravity, axis=1)[:, None]
    return np.degrees(np.arccos(np.clip(np.sum(up * g, axis=1), -1.0, 1.0)))


sources = (sorted(glob.glob(os.path.join(RAW, "tyrex-attitude-smartphones", "datasets", "android", "*")))
           + sorted(glob.glob(os.path.join(RAW, "tyrex-attitude-smartphones", "datasets", "ios", "*")))
           + sorted(glob.glob(os.path.join(RAW, "indoor-location-competition-20", "**", "*.txt"),
                              recursive=True))
           + sorted(glob.glob(os.path.join(ROOT, "datasets", "sample", "*_*"))))
acce, gyro, rate, angle, n = [], [], [], [], 0
warnings.simplefilter("ignore")
for path in sources:
    try:
        seqs = ridi.read_any(path)
    except (OSError, ValueError):
        continue  # licences, provenance notes, runs without motion capture
    for s in seqs:
        if len(s) <= WINDOW:
            continue
        n += 1
        acce.append(seconds(np.linalg.norm(s.acce, axis=1)) / G)
        gyro.append(seconds(np.linalg.norm(s.gyro, axis=1)))
        rate.append(1.0 / seconds(np.diff(s.time)))
        angle.append(np.median(up_angles(s)))
acce, gyro, rate = (np.concatenate(v) for v in (acce, gyro, rate))
print(f"{n} sequences, {len(acce)} one-second windows")
print(f"median |acce| per second: {acce.min():.2f}..{acce.max():.2f} g")
print(f"median |gyro| per second: at most {gyro.max():.2f} rad/s")
print(f"median rate per second: {rate.min():.2f}..{rate.max():.2f} Hz")
print(f"median angle of gravity from the orientation's up axis per sequence: "
      f"at most {max(angle):.3f} degrees")
