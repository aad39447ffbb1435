#!/usr/bin/env python3
"""Dev-only side-by-side timing with scikit-learn (libsvm) on data exported by

    cargo run --release -p ridi-regress --example svr_timing -- export <n> <dir>

Usage: python3 compare_sklearn.py <dir> [svr|svc|grid|query] [--c C] [--eps E] [--threads T]
Needs numpy and scikit-learn (pip install numpy scikit-learn). Not used by the Rust build.
"""
import argparse
import os
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("task", choices=["svr", "svc", "grid", "query"])
    ap.add_argument("--c", type=float, default=10.0)
    ap.add_argument("--eps", type=float, default=0.01)
    ap.add_argument("--n", type=int, default=0, help="use only the first n samples")
    ap.add_argument("--cache-mb", type=float, default=2048)
    a = ap.parse_args()
    from sklearn.svm import SVR, SVC
    from sklearn.model_selection import GridSearchCV, GroupKFold, PredefinedSplit

    n, d = map(int, open(os.path.join(a.dir, "shape.txt")).read().split())
    x = np.fromfile(os.path.join(a.dir, "x.f32"), dtype="<f4").reshape(n, d).astype(np.float64)
    y = np.fromfile(os.path.join(a.dir, "y.f32"), dtype="<f4").reshape(n, 2).astype(np.float64)
    lab = np.fromfile(os.path.join(a.dir, "placement.u32"), dtype="<u4")
    grp = np.fromfile(os.path.join(a.dir, "group.u32"), dtype="<u4")
    fold_path = os.path.join(a.dir, "fold.u32")
    fold = np.fromfile(fold_path, dtype="<u4") if os.path.exists(fold_path) else None
    if a.n:
        x, y, lab, grp = x[: a.n], y[: a.n], lab[: a.n], grp[: a.n]
        fold = None
        n = a.n
    gamma = 1.0 / d
    if a.task == "svr":
        m = SVR(C=a.c, epsilon=a.eps, gamma=gamma, cache_size=a.cache_mb)
        t = time.perf_counter()
        m.fit(x, y[:, 1])
        fit = time.perf_counter() - t
        mse = np.mean((m.predict(x) - y[:, 1]) ** 2)
        print(f"sklearn svr n={n} C={a.c} eps={a.eps}: fit {fit:.2f} s, {m.n_iter_} iterations, "
              f"{len(m.support_)} SV, train MSE {mse:.5f}, rho {-m.intercept_[0]:.6f}")
    elif a.task == "svc":
        m = SVC(C=a.c, gamma=gamma, cache_size=a.cache_mb)
        t = time.perf_counter()
        m.fit(x, lab)
        fit = time.perf_counter() - t
        acc = np.mean(m.predict(x) == lab)
        print(f"sklearn svc n={n} C={a.c}: fit {fit:.2f} s, {len(m.support_)} SV, train accuracy {acc:.4f}")
    elif a.task == "grid":
        grid = {"C": [0.1, 1, 10, 100], "epsilon": [0.001, 0.01, 0.1, 1.0]}
        t0 = time.perf_counter()
        for p in np.unique(lab):
            sel = lab == p
            for ch in range(2):
                t = time.perf_counter()
                # Identical folds to ridi-regress when the export has them.
                cv = PredefinedSplit(fold[sel]) if fold is not None else GroupKFold(n_splits=3)
                gs = GridSearchCV(SVR(gamma=gamma, cache_size=a.cache_mb), grid,
                                  cv=cv, scoring="neg_mean_squared_error", n_jobs=1)
                gs.fit(x[sel], y[sel, ch], groups=grp[sel])
                print(f"placement {p} channel {ch}: best {gs.best_params_} CV MSE {-gs.best_score_:.6f} "
                      f"({time.perf_counter() - t:.1f} s)", flush=True)
        print(f"sklearn grid total {time.perf_counter() - t0:.1f} s")
    else:
        clf = SVC(C=10, gamma=gamma).fit(x, lab)
        regs = {}
        for p in np.unique(lab):
            sel = lab == p
            regs[p] = [SVR(C=a.c, epsilon=a.eps, gamma=gamma).fit(x[sel], y[sel, ch]) for ch in range(2)]
        t = time.perf_counter()
        q = 200
        for i in range(q):
            row = x[i : i + 1]
            p = clf.predict(row)[0]
            regs[p][0].predict(row)
            regs[p][1].predict(row)
        print(f"sklearn one query (classify + 2 regressions): {(time.perf_counter() - t) / q * 1e3:.3f} ms")


if __name__ == "__main__":
    main()
