"""`ridi demo` from Python: train on two people of the bundled sample, evaluate every method on
the third, print the demo's table, and plot one held-out trajectory against its ground truth.

    pip install ./crates/ridi-py matplotlib
    python examples/python_demo.py [--plot trajectory.png]

matplotlib is optional: without it the table is printed and the plot skipped.
"""

import argparse
import time
from pathlib import Path

import numpy as np

import ridi

SAMPLE = Path(__file__).resolve().parent.parent / "datasets" / "sample"


def print_table(report):
    """The summary `ridi demo` and `ridi eval` print."""
    # The report's warnings (a weakly determined alignment, say) came as Python warnings when
    # ridi.evaluate returned it; they are in report["warnings"] too.
    accuracy = report["placement_accuracy"]
    mse = report["velocity_mse"]
    print(
        f"\n{len(report['sequences'])} sequences; velocity MSE S-x {mse[0]:.3f} S-z {mse[1]:.3f}"
        f" (m/s)^2; placement accuracy {'-' if accuracy is None else f'{accuracy:.3f}'}"
    )
    def interval(figures):
        """`(low, high)` of a report's interval, or None where the runs were too few for one
        (its bounds are null, NaN in Rust)."""
        low, high = (figures or {}).get("low"), (figures or {}).get("high")
        return None if low is None or high is None else (low, high)

    bounded = any(interval(i.get("rte_5s_m")) for i in report["intervals"].values())
    print(f"{'method':<10} {'RTE 5 s m' + (' [95 %]' if bounded else ''):>26} {'ATE m':>9}"
          f" {'RTE 60 s m':>10} {'MPE m':>9} {'path length ratio':>17}")
    for key in report["methods"]:
        m = report["summary"][key]
        ratio = "-" if m["path_length_ratio"] is None else f"{m['path_length_ratio']:.3f}"
        bounds = interval(report["intervals"].get(key, {}).get("rte_5s_m"))
        rte = f"{m['rte_5s_m']:.3f}" + ("" if bounds is None else " [{:.3f}, {:.3f}]".format(*bounds))
        print(
            f"{key:<10} {rte:>26} {m['ate_m']:>9.3f} {m['rte_m']:>10.3f}"
            f" {m['mpe_m']:>9.3f} {ratio:>17}"
        )
    # RIDI's difference from PDR, paired over the sequences, as `ridi demo` prints it.
    difference = report["ridi_minus"].get("pdr", {}).get("rte_5s_m")
    if difference is not None:
        bounds = interval(difference)
        text = ("(too few runs for an interval)" if bounds is None
                else "[{:+.3f}, {:+.3f}]".format(*bounds))
        print(f"ridi - pdr, RTE 5 s: {difference['mean']:+.3f} m {text} (paired over sequences)")
    # Each device's mean RTE 5 s when the sequences span phones (`ridi::Report::per_device`).
    devices = sorted({s["device"] for s in report["sequences"] if s.get("device")})
    if len(devices) > 1:
        print("\nRTE 5 s per device (m):")
        for d in devices:
            runs = [s for s in report["sequences"] if s.get("device") == d]
            means = ", ".join(
                f"{key} {np.mean([s['methods'][key]['rte_5s_m'] for s in runs]):.3f}"
                for key in report["methods"]
            )
            plural = "" if len(runs) == 1 else "s"
            print(f"  {d} ({len(runs)} sequence{plural}): {means}")


def aligned(estimate, truth, t, seconds=10.0):
    """`estimate` (N, 2) turned and moved onto `truth` on the first `seconds` (2D rigid, no
    scale), as the evaluation and `ridi track --plot` align it."""
    first = t - t[0] <= seconds
    a, b = estimate[first], truth[first]
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    angle = np.arctan2(h[0, 1] - h[1, 0], h[0, 0] + h[1, 1])
    r = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return (estimate - ca) @ r.T + cb


def main():
    # The docstring's first paragraph (it spans two lines).
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--plot", default="trajectory.png", help="image to draw (matplotlib)")
    args = parser.parse_args()

    train = ridi.read_list(SAMPLE / "list_train.txt", placement_map="tyrex4", purpose="training")
    print(f"demo: training on {len(train)} sequences ({sum(s.duration for s in train):.0f} s)")
    started = time.perf_counter()
    model = ridi.train(train, grid="none")
    print(f"trained in {time.perf_counter() - started:.1f} s")
    print(model)
    report = ridi.evaluate(SAMPLE / "list_test.txt", model, placement_map="tyrex4")
    print_table(report)

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("\nmatplotlib is not installed: no plot (pip install matplotlib)")
        return
    seq = ridi.read(SAMPLE / "Thibaud_Nexus5_NoDist_Texting")
    track = ridi.track(seq, model)
    truth = seq.ground_truth_position[:, :2]
    estimate = aligned(track.position[:, :2], truth, seq.time)
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot(truth[:, 0], truth[:, 1], label="ground truth", color="black")
    ax.plot(estimate[:, 0], estimate[:, 1], label="ridi", color="tab:red")
    ax.set_title(seq.name)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend()
    fig.savefig(args.plot, dpi=120, bbox_inches="tight")
    print(f"\nplot: {args.plot}")


if __name__ == "__main__":
    main()
