#!/usr/bin/env python3
"""The real-data figures behind two validation bounds (docs/benchmarks.md, "Bounds of the
live stream check"): over every second (200 frames, every 20th window) of every recording, the
median |acce| in g, the median |gyro| and the median rate, which `ridi::STREAM_ACCE_G`, the
median gyro bound and the rate tolerance of `LiveTracker` must hold; the median angle between
gravity and the orientation's up axis (per recording and per second), which
`Validation::max_orientation_gravity_deg` (45 degrees) must hold; and per second the median
|gravity| and the linear acceleration's scale against accelerometer minus gravity (where its
RMS is at least 0.5 m/s^2), which `Validation::gravity_range` (8.5..11 m/s^2) and
`linacce_scale_range` (0.5..2) must hold for a stream's last second as for a recording.

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
up_second, gravity, scale = [], [], []
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
        up = up_angles(s)
        angle.append(np.median(up))
        up_second.append(seconds(up))
        gravity.append(seconds(np.linalg.norm(s.gravity, axis=1)))
        d = s.acce - s.gravity
        for i in range(0, len(s) - WINDOW + 1, STEP):
            dw, lw = d[i:i + WINDOW], s.linacce[i:i + WINDOW]
            if np.sqrt(np.mean(np.sum(dw * dw, axis=1))) >= 0.5:
                scale.append(np.sum(dw * lw) / np.sum(lw * lw))
acce, gyro, rate, up_second, gravity = (
    np.concatenate(v) for v in (acce, gyro, rate, up_second, gravity))
print(f"{n} sequences, {len(acce)} one-second windows")
print(f"median |acce| per second: {acce.min():.2f}..{acce.max():.2f} g")
print(f"median |gyro| per second: at most {gyro.max():.2f} rad/s")
print(f"median rate per second: {rate.min():.2f}..{rate.max():.2f} Hz")
print(f"median angle of gravity from the orientation's up axis per sequence: "
      f"at most {max(angle):.3f} degrees")
print(f"median angle of gravity from the orientation's up axis per second: "
      f"at most {up_second.max():.3f} degrees")
print(f"median |gravity| per second: {gravity.min():.3f}..{gravity.max():.3f} m/s^2")
print(f"linear acceleration's scale per second ({len(scale)} seconds with an RMS of at least "
      f"0.5 m/s^2): {min(scale):.3f}..{max(scale):.3f}")
