"""How well the gyro and the orientation agree in direction on real recordings: the bounds
behind `ridi_data::MIN_GYRO_AGREEMENT`.

For each sequence the readers give, the agreement of the gyro with the rotation rate of the
recorded orientation, as `Validation::check_gyro_scale` computes it (the sum over steps of the
two rate vectors' dot product over the sum of their magnitudes' product, the steps of
orientation jumps left out), as recorded, with the gyro's sign flipped, and with the
quaternion's components read in the other orders a user may give (x, y, z, w read as
w, x, y, z, and the reverse). Needs the Python package (`pip install ./crates/ridi-py`).

    python benchmarks/gyro_direction.py ../shared/data/raw/tyrex-attitude-smartphones/datasets/*/* \
        ../shared/data/raw/indoor-location-competition-20/data/*/*/path_data_files/*
"""
import sys
import warnings

import numpy as np

import ridi

JUMP_RATE = 5.0  # ridi_data::ORIENTATION_JUMP_RATE


def qmul(a, b):
    w1, x1, y1, z1 = a.T
    w2, x2, y2, z2 = b.T
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2], axis=1)


def agreement(t, gyro, q):
    """The check's agreement, or NaN where the orientation hardly turns."""
    step = qmul(q[:-1] * np.array([1, -1, -1, -1]), q[1:])  # q_{k-1}^-1 q_k, device frame
    step *= np.where(step[:, :1] < 0, -1.0, 1.0)
    v = step[:, 1:]
    s = np.linalg.norm(v, axis=1)
    angle = 2 * np.arctan2(s, step[:, 0])
    dt = np.diff(t)
    rate = v / np.maximum(s, 1e-300)[:, None] * (angle / dt)[:, None]
    g = 0.5 * (gyro[1:] + gyro[:-1])
    w, gn = angle / dt, np.linalg.norm(g, axis=1)
    jump = w - gn > JUMP_RATE
    keep = ~jump if jump.mean() <= 0.05 else np.ones_like(jump)
    return np.sum(np.sum(g * rate, axis=1)[keep]) / np.sum((gn * w)[keep])


def main(paths):
    warnings.simplefilter("ignore")
    rows = []
    for path in paths:
        try:
            seqs = ridi.read_any(path)
        except Exception as e:  # a folder without motion capture, say
            print(f"skipped {path}: {str(e).splitlines()[0][:100]}", file=sys.stderr)
            continue
        for s in seqs:
            t, g, q = s.time, s.gyro, s.orientation
            row = (agreement(t, g, q), agreement(t, -g, q),
                   agreement(t, g, q[:, [1, 2, 3, 0]]), agreement(t, g, q[:, [3, 0, 1, 2]]))
            rows.append(row)
            print(f"{s.name:48s} " + " ".join(f"{x:+.2f}" for x in row))
    a = np.array(rows)
    print(f"\n{len(rows)} sequences: as recorded {a[:, 0].min():+.2f}..{a[:, 0].max():+.2f}; "
          f"sign flipped {a[:, 1].min():+.2f}..{a[:, 1].max():+.2f}; other quaternion orders "
          f"{a[:, 2:].min():+.2f}..{a[:, 2:].max():+.2f}, "
          f"{np.mean(np.abs(a[:, 2:]) < 0.5):.0%} of them under 0.5 in size")


if __name__ == "__main__":
    main(sys.argv[1:])
