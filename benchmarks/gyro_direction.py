"""How well the gyro and the orientation agree in direction on real recordings: the bounds
behind `ridi_data::MIN_GYRO_AGREEMENT`.

For each sequence the readers give, the agreement of the gyro with the rotation rate of the
recorded orientation, as `Validation::check_gyro_scale` computes it (the sum over steps of the
two rate vectors' dot product over the sum of their magnitudes' product, the steps of
orientation jumps left out), as recorded, with the gyro's sign flipped, with the
quaternion's components read in the other orders a user may give (x, y, z, w read as
w, x, y, z, and the reverse), and with its conjugate (device-from-world given for
world-from-device). With `--stream`, instead, streams started every 2 s into each
recording as `ridi::LiveTracker` sums them: the lowest agreement once 5 s and once 10 s
(`ridi::STREAM_GYRO_CHECK_S`) have passed, and how many of the reordered quaternions' streams
fall under `ridi::STREAM_MIN_GYRO_AGREEMENT` (0) after 10 s. With `--axes`, each gyro axis's
least-squares scale against the orientation's rotation rate about that device axis, where the
orientation turns about it at 0.1 rad/s RMS (`ridi_data::GYRO_SCALE_MIN_RATE`) and with a tenth
of its squared rate (`ridi_data::GYRO_AXIS_MIN_SHARE`): the bounds
behind `ridi_data::MIN_GYRO_AXIS_SCALE` (a dead axis reads 0). Sequences the reader refuses (the
whole-recording check included) are counted apart. Needs the Python package (`pip install
./crates/ridi-py`).

    python benchmarks/gyro_direction.py [--stream | --axes] \
        ../shared/data/raw/tyrex-attitude-smartphones/datasets/{android,ios}/* \
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


def step_vectors(t, gyro, q):
    """Per step: the orientation's and the gyro's rotation-rate vectors in the device frame,
    and whether the step is no orientation jump."""
    step = qmul(q[:-1] * np.array([1, -1, -1, -1]), q[1:])  # q_{k-1}^-1 q_k, device frame
    step *= np.where(step[:, :1] < 0, -1.0, 1.0)
    v = step[:, 1:]
    s = np.linalg.norm(v, axis=1)
    angle = 2 * np.arctan2(s, step[:, 0])
    dt = np.diff(t)
    rate = v / np.maximum(s, 1e-300)[:, None] * (angle / dt)[:, None]
    g = 0.5 * (gyro[1:] + gyro[:-1])
    return rate, g, ~(angle / dt - np.linalg.norm(g, axis=1) > JUMP_RATE)


def step_sums(t, gyro, q):
    """Per step: the rate vectors' dot product, the magnitudes' product, the orientation rate
    squared, and whether the step is no orientation jump."""
    rate, g, kept = step_vectors(t, gyro, q)
    w, gn = np.linalg.norm(rate, axis=1), np.linalg.norm(g, axis=1)
    return np.sum(g * rate, axis=1), gn * w, w * w, kept


def axis_scales(t, gyro, q):
    """Per device axis: whether `Validation::check_gyro_scale` judges it (the orientation
    turning about it at 0.1 rad/s RMS, with a tenth of its squared rate:
    `ridi_data::GYRO_AXIS_MIN_SHARE`), and the gyro's least-squares scale against it."""
    rate, g, kept = step_vectors(t, gyro, q)
    keep = kept if (~kept).mean() <= 0.05 else np.ones_like(kept)
    r, g = rate[keep], g[keep]
    ww = np.sum(r * r, axis=0)
    judged = (np.sqrt(ww / len(r)) >= 0.1) & (ww >= 0.1 * ww.sum())
    return judged, np.sum(g * r, axis=0) / ww


def agreement(t, gyro, q):
    """The whole recording's agreement, as `Validation::check_gyro_scale` sums it."""
    dot, gw, _, kept = step_sums(t, gyro, q)
    keep = kept if (~kept).mean() <= 0.05 else np.ones_like(kept)
    return np.sum(dot[keep]) / np.sum(gw[keep])


def stream_minimum(t, gyro, q, after_s, every_s=2.0):
    """The lowest agreement of streams started every `every_s` seconds, as the live tracker
    sums it from its start, at every step once `after_s` seconds have passed and the
    orientation turns at 0.1 rad/s RMS: one value per start (NaN where never judged)."""
    dot, gw, ww, kept = step_sums(t, gyro, q)
    sums = [np.concatenate([[0.0], np.cumsum(x * kept)]) for x in (dot, gw, ww, np.ones_like(dot))]
    out = []
    for start in np.searchsorted(t, np.arange(t[0], t[-1] - after_s, every_s)):
        d, g, w, n = (c[start + 1:] - c[start] for c in sums)
        judged = (t[start + 1:] - t[start] >= after_s) & (np.sqrt(w / np.maximum(n, 1)) >= 0.1)
        judged &= g > 0
        out.append(np.min(d[judged] / g[judged]) if judged.any() else np.nan)
    return np.array(out)


def main(paths):
    warnings.simplefilter("ignore")
    stream, axes = "--stream" in paths, "--axes" in paths
    paths = [p for p in paths if p not in ("--stream", "--axes")]
    rows, refused = [], []
    for path in paths:
        try:
            seqs = ridi.read_any(path)
        except Exception as e:  # a folder without motion capture, or refused by the checks
            refused.append(f"{path}: {str(e).splitlines()[0][:200]}")
            continue
        for s in seqs:
            t, g, q = s.time, s.gyro, s.orientation
            if axes:
                judged, scale = axis_scales(t, g, q)
                rows.append((judged, scale))
                print(f"{s.name:48s} scale " + " ".join(
                    f"{x:5.2f}" if j else "    -" for j, x in zip(judged, scale)))
                continue
            if stream:
                row = (np.nanmin(stream_minimum(t, g, q, 5.0)),
                       np.nanmin(stream_minimum(t, g, q, 10.0)),
                       np.concatenate([stream_minimum(t, g, q[:, order], 10.0)
                                       for order in ([1, 2, 3, 0], [3, 0, 1, 2])]))
            else:
                row = (agreement(t, g, q), agreement(t, -g, q),
                       agreement(t, g, q[:, [1, 2, 3, 0]]), agreement(t, g, q[:, [3, 0, 1, 2]]),
                       agreement(t, g, q * np.array([1, -1, -1, -1])))
            rows.append(row)
            print(f"{s.name:48s} " + " ".join(f"{x:+.2f}" for x in row[:2])
                  + (f" reordered refused {np.mean(row[2][~np.isnan(row[2])] < 0):.0%}"
                     if stream else " " + " ".join(f"{x:+.2f}" for x in row[2:])))
    print(f"\n{len(refused)} paths refused by the reader:", *refused, sep="\n  ")
    if axes:
        judged = np.array([sc for j, scale in rows for k, sc in zip(j, scale) if k])
        print(f"{len(rows)} sequences, {len(judged)} of {3 * len(rows)} axes judged: gyro scale "
              f"{judged.min():.2f}..{judged.max():.2f}, 1 % under {np.percentile(judged, 1):.2f}")
        return
    if stream:
        low5, low10 = (np.nanmin([r[i] for r in rows]) for i in (0, 1))
        reordered = np.concatenate([r[2] for r in rows])
        reordered = reordered[~np.isnan(reordered)]
        print(f"{len(rows)} sequences, streams started every 2 s, lowest agreement from the "
              f"start: after 5 s {low5:+.2f}, after 10 s {low10:+.2f} (a flipped gyro: at most "
              f"{-low10:+.2f}); quaternions reordered: {np.mean(reordered < 0):.0%} of "
              f"{len(reordered)} streams under 0 after 10 s")
        return
    a = np.array(rows)
    refused_share = np.mean(a[:, 2:4] < 0.5)
    print(f"\n{len(rows)} sequences: as recorded {a[:, 0].min():+.2f}..{a[:, 0].max():+.2f}; "
          f"sign flipped {a[:, 1].min():+.2f}..{a[:, 1].max():+.2f}; other quaternion orders "
          f"{a[:, 2:4].min():+.2f}..{a[:, 2:4].max():+.2f}, {refused_share:.0%} of them under 0.5; "
          f"conjugate {a[:, 4].min():+.2f}..{a[:, 4].max():+.2f}, "
          f"{np.mean(a[:, 4] < 0.5):.0%} under 0.5")


if __name__ == "__main__":
    main(sys.argv[1:])
