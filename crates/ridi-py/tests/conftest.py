"""Shared fixtures: the bundled sample, the `ridi` binary the results are compared with, and
one model trained once per session (fixed C and epsilon, as `ridi demo` trains: seconds)."""

import os
import subprocess
from pathlib import Path

import pytest

import ridi

ROOT = Path(__file__).resolve().parents[3]
SAMPLE = ROOT / "datasets" / "sample"
# `cargo test --workspace` builds it; RIDI_BIN points elsewhere (a release build, say).
RIDI_BIN = Path(os.environ.get("RIDI_BIN", ROOT / "target" / "debug" / "ridi"))


@pytest.fixture(scope="session")
def ridi_bin():
    """Runs the `ridi` command line: `ridi_bin("track", ...)` returns its stdout."""
    if not RIDI_BIN.is_file():
        pytest.fail(
            f"the ridi binary is missing at {RIDI_BIN}: build it with "
            "`cargo build -p ridi-cli` (cargo test --workspace builds it) or set RIDI_BIN"
        )

    def run(*args):
        done = subprocess.run(
            [str(RIDI_BIN), *map(str, args)], capture_output=True, text=True
        )
        if done.returncode != 0:
            pytest.fail(f"ridi {' '.join(map(str, args))} failed: {done.stderr}")
        return done.stdout

    return run


@pytest.fixture(scope="session")
def model():
    """Trained on one person of the sample, grouped as the demo groups placements."""
    return ridi.train(SAMPLE / "list_Guillaume.txt", grid="none", placement_map="tyrex4")


@pytest.fixture(scope="session")
def recorded_model():
    """As `model`, on the recorded orientation: its live tracker takes the phone's own."""
    return ridi.train(SAMPLE / "list_Guillaume.txt", grid="none", placement_map="tyrex4",
                      orientation="recorded")


@pytest.fixture(scope="session")
def model_file(model, tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "model.ridi"
    model.save(path)
    return path


@pytest.fixture(scope="session")
def seq():
    """A held-out run (another person than the model's)."""
    return ridi.read(SAMPLE / "Thibaud_Nexus5_NoDist_Texting")


def arrays_of(s):
    """The constructor arguments that rebuild sequence `s`."""
    return dict(
        time=s.time,
        gyro=s.gyro,
        acce=s.acce,
        gravity=s.gravity,
        orientation=s.orientation,
        linacce=s.linacce,
        name=s.name,
        placement=s.placement,
        magnet=s.magnet,
        ground_truth_position=s.ground_truth_position,
        ground_truth_orientation=s.ground_truth_orientation,
        steps=s.steps,
        orientation_source=s.orientation_source,
        device=s.device,
        device_imu_rate_hz=s.device_imu_rate_hz,
    )
