"""Tracking from Python against the `ridi` command line on the same run: a benchmark, not a test.

    python crates/ridi-py/bench/track_speed.py [--ridi target/release/ridi] [--repeat 9]

Both sides do the whole job of `ridi track`: load the model, read the recording, track it
(batch, then online) and write the trajectory CSV; the command's time includes starting its
process. Prints the median of each, their ratio, and the tracking alone from Python. Build the
extension with the same profile as the binary (`pip install ./crates/ridi-py` and a release
binary, or `maturin develop` and target/debug/ridi).
"""

import argparse
import os
import platform
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import ridi

ROOT = Path(__file__).resolve().parents[3]
SAMPLE = ROOT / "datasets" / "sample"
RUN = SAMPLE / "Thibaud_Nexus5_NoDist_Texting"


def seconds(job):
    started = time.perf_counter()
    job()
    return time.perf_counter() - started


def medians(jobs, repeat):
    """The median time of each job, run in turn `repeat` times (so that a change in the
    machine's load hits them alike)."""
    times = [[] for _ in jobs]
    for _ in range(repeat):
        for t, job in zip(times, jobs):
            t.append(seconds(job))
    return [statistics.median(t) for t in times]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ridi", default=os.environ.get("RIDI_BIN", ROOT / "target/release/ridi"))
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        model_file = tmp / "model.ridi"
        ridi.train(SAMPLE / "list_train.txt", grid="none", placement_map="tyrex4").save(model_file)
        print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
              f"Python {platform.python_version()}; run: {RUN.name}")
        for online in (False, True):
            flags = ["--online"] if online else []

            def cli():
                subprocess.run(
                    [str(args.ridi), "track", str(RUN), "--model", str(model_file),
                     "--out", str(tmp / "cli.csv"), *flags],
                    check=True, capture_output=True,
                )

            def python():
                model = ridi.load(model_file)
                track = ridi.track(ridi.read(RUN), model, online=online)
                track.write_csv(tmp / "py.csv")

            seq, model = ridi.read(RUN), ridi.load(model_file)
            cli(), python()  # warm the page cache
            t_cli, t_py, t_track = medians(
                [cli, python, lambda: ridi.track(seq, model, online=online)], args.repeat
            )
            same = (tmp / "cli.csv").read_bytes() == (tmp / "py.csv").read_bytes()
            mode = "online" if online else "batch"
            print(f"{mode:>6}: ridi track {t_cli * 1e3:7.1f} ms, Python {t_py * 1e3:7.1f} ms "
                  f"(ratio {t_py / t_cli:.3f}; ridi.track alone {t_track * 1e3:.1f} ms); "
                  f"same CSV: {same}")


if __name__ == "__main__":
    main()
