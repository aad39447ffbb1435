"""Whether a recording without an orientation can tell a wrong gyro from its accelerometer:
the measurement behind `docs/benchmarks.md`'s "a gyro judged by the accelerometer's tilt".

With no recorded orientation, the only reference for the gyro is the accelerometer, whose
direction is gravity's only while the phone does not accelerate. For each sequence the
readers give, a gravity direction is carried by the gyro and pulled towards the accelerometer's
direction (a complementary filter of time constant 1 s, at 25 Hz), and the RMS angle between
the two over the blocks whose mean |acce| is within 10 % of g is taken: with the gyro as
recorded, with its sign flipped, turned by 90 degrees about z, and with x and y swapped. A
check could refuse a gyro when one of those fits clearly better than the gyro as given: the
script prints, per transform, the ratio of its residual to the recorded gyro's.

    python benchmarks/gyro_tilt.py \
        ../shared/data/raw/tyrex-attitude-smartphones/datasets/{android,ios}/* \
        ../shared/data/raw/indoor-location-competition-20/data/*/*/path_data_files/* \
        datasets/sample/*_*
"""
import sys
import warnings

import numpy as np

import ridi

BLOCK = 8  # frames per filter step: 25 Hz at 200 Hz
TAU = 1.0  # seconds
G = 9.80665


def residual(t, gyro, acce):
    """RMS angle (radians) between the gyro-carried gravity direction and the accelerometer's,
    over blocks whose mean |acce| is within 10 % of g."""
    n = len(t) // BLOCK * BLOCK
    dt = np.median(np.diff(t))
    turn = (gyro[:n] * dt).reshape(-1, BLOCK, 3).sum(1)
    a = acce[:n].reshape(-1, BLOCK, 3).mean(1)
    norm = np.linalg.norm(a, axis=1)
    direction = a / norm[:, None]
    quiet = np.abs(norm - G) < 0.1 * G
    gain = BLOCK * dt / TAU
    u, total, count = direction[0].copy(), 0.0, 0
    for i in range(1, len(turn)):
        # A world-fixed direction seen from the device turns by -w: u' = u x w.
        u = u + np.cross(u, turn[i])
        u /= np.linalg.norm(u)
        if quiet[i]:
            total += np.arccos(np.clip(u @ direction[i], -1.0, 1.0)) ** 2
            count += 1
            u = u + gain * (direction[i] - u)
            u /= np.linalg.norm(u)
    return np.sqrt(total / max(count, 1))


TRANSFORMS = {
    "sign flipped": lambda g: -g,
    "turned 90 degrees about z": lambda g: np.c_[-g[:, 1], g[:, 0], g[:, 2]],
    "x and y swapped": lambda g: np.c_[g[:, 1], g[:, 0], g[:, 2]],
}

warnings.simplefilter("ignore")
names, given, wrong = [], [], {k: [] for k in TRANSFORMS}
for path in sys.argv[1:]:
    try:
        seqs = ridi.read_any(path)
    except (OSError, ValueError):
        continue  # licences, provenance notes, runs without motion capture
    for s in seqs:
        if len(s) < 2000:
            continue
        names.append(s.name)
        given.append(residual(s.time, s.gyro, s.acce))
        for key, f in TRANSFORMS.items():
            wrong[key].append(residual(s.time, f(s.gyro), s.acce))
given = np.array(given)
print(f"{len(given)} sequences; the recorded gyro's residual: median "
      f"{np.degrees(np.median(given)):.1f} degrees, at most {np.degrees(given.max()):.1f}")
for key, values in wrong.items():
    ratio = np.array(values) / given
    worst = int(ratio.argmin())
    print(f"{key}: residual over the recorded gyro's {ratio.min():.2f} (min, "
          f"{names[worst]}), {np.percentile(ratio, 5):.2f} (5 %), {np.median(ratio):.2f} (median)")
