"""ridi.read, ridi.read_any, ridi.read_list and ridi.Sequence: arrays, metadata, and every
bad input refused with a message naming the file, line and field, or the array and frame."""

import gzip
import json
import shutil
import subprocess

import numpy as np
import pytest

import ridi
from conftest import RIDI_BIN, SAMPLE, arrays_of

RUN = SAMPLE / "Thibaud_Nexus5_NoDist_Texting"


def test_read_gives_numpy_arrays_and_metadata(seq, ridi_bin):
    n = len(seq)
    assert seq.name == "Thibaud_Nexus5_NoDist_Texting"
    assert seq.format == "ridi-csv"
    assert seq.time.shape == (n,) and seq.time.dtype == np.float64
    for a in (seq.gyro, seq.acce, seq.linacce, seq.gravity, seq.ground_truth_position):
        assert a.shape == (n, 3) and a.dtype == np.float64
    for q in (seq.orientation, seq.ground_truth_orientation):
        assert q.shape == (n, 4)
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-9)
    # What `ridi inspect` says of the same recording.
    inspected = json.loads(ridi_bin("inspect", RUN, "--json"))
    assert inspected["frames"] == n
    assert inspected["duration_s"] == pytest.approx(seq.duration)
    assert inspected["rate_hz"] == pytest.approx(seq.rate_hz)
    assert abs(seq.median_rate_hz - 200.0) < 20.0
    assert (seq.device, seq.device_imu_rate_hz) == (inspected["device"], inspected["device_imu_rate_hz"])
    # The sample's sidecar: a Nexus 5 and its rotation vector (the Tyrex runs recorded that).
    assert (seq.device, seq.orientation_source) == ("Nexus 5", "rotation-vector")
    assert (seq.magnet, seq.steps) == (None, None)
    assert "Thibaud_Nexus5_NoDist_Texting" in repr(seq)


def test_read_any_and_a_forced_format(seq):
    [same] = ridi.read_any(RUN, format="ridi-csv")
    np.testing.assert_array_equal(same.gyro, seq.gyro)
    with pytest.raises(ValueError, match="not an Indoor Location Competition path file"):
        ridi.read(RUN, format="ilc")
    with pytest.raises(ValueError, match="`format` is 'csv'; expected one of"):
        ridi.read(RUN, format="csv")


def test_read_list_labels_and_checks(tmp_path):
    seqs = ridi.read_list(SAMPLE / "list_test.txt", placement_map="tyrex4", purpose="evaluation")
    assert len(seqs) == 10
    assert {s.placement for s in seqs} == {"hand", "pocket", "running", "swing"}
    assert {s.device for s in seqs} == {"Nexus 5", "iPhone 4S"}
    raw = ridi.read_list([SAMPLE / "list_test.txt"])
    assert [s.placement for s in raw][:2] == ["AR", "BackPocket"]
    bad = tmp_path / "list.txt"
    bad.write_text(f"{RUN},Texting\n{RUN},Swingin\n")
    with pytest.raises(ValueError, match=r"list.txt:2: field `placement`: placement `Swingin`"):
        ridi.read_list(bad, placement_map="tyrex4")
    bad.write_text(f"# runs\n{tmp_path / 'nowhere'},Texting\n")
    with pytest.raises(ValueError, match=r"list.txt:2: field `path`: .*nowhere` does not exist"):
        ridi.read_list(bad)
    with pytest.raises(ValueError, match="`purpose` is 'testing'"):
        ridi.read_list(bad, purpose="testing")
    with pytest.raises(TypeError):
        ridi.read_list(42)


def test_a_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        ridi.read(tmp_path / "nowhere" / "data.csv")


def test_control_characters_in_names_are_escaped_as_the_cli_escapes_them(tmp_path, seq):
    data = tmp_path / "line\nbreak\x1b[2J" / "data.csv"
    with pytest.raises(FileNotFoundError) as raised:
        ridi.read(data)
    message = str(raised.value)
    assert "\n" not in message and "\x1b" not in message, message
    assert "line\\nbreak\\u{1b}[2J" in message
    cli = subprocess.run([str(RIDI_BIN), "inspect", str(data)], capture_output=True, text=True)
    assert cli.returncode != 0 and cli.stderr == f"error: {message}\n"
    with pytest.raises(FileNotFoundError, match=r"cannot load model .*line\\nbreak\\u\{1b\}"):
        ridi.load(data.parent / "m.ridi")
    args = arrays_of(seq)
    args["gyro"][7, 1] = np.nan
    args["name"] = "walk\x1b]0;x\x07"
    with pytest.raises(ValueError, match=r"sequence `walk\\u\{1b\}\]0;x\\u\{7\}`: `gyro`"):
        ridi.Sequence(**args)
    named = ridi.Sequence(seq.time, seq.gyro, seq.acce, name="walk\n\x1b[31m", placement="hand\x07")
    assert "walk\\n\\u{1b}[31m" in repr(named) and "'hand\\u{7}'" in repr(named), repr(named)


def test_reader_warnings_are_escaped_as_the_cli_prints_them(tmp_path):
    # A Tyrex run (no motion capture) under a folder named with a line break and an escape
    # sequence: a flat phone turning about z at 0.3 rad/s, 40 s at 200 Hz, gyro lost for 1 s.
    run = tmp_path / "ty\nrex\x1b[2J" / "datasets" / "android" / "Ann_Nexus5_NoDist_Texting"
    run.mkdir(parents=True)
    t = 0.003 + np.arange(8000) / 200.0

    def rows(cols):
        return "".join(" ".join(f"{v:.9f}" for v in r) + "\n" for r in cols)

    half = 0.15 * t
    (run / "accelerometer.txt").write_text(
        rows(np.c_[t, 0.1 * np.sin(t), np.zeros_like(t), np.full_like(t, 9.80665)]))
    kept = (t < 19.5) | (t >= 20.5)
    (run / "gyroscope-calibrated.txt").write_text(
        rows(np.c_[t + 0.001, np.zeros_like(t), np.zeros_like(t), np.full_like(t, 0.3)][kept]))
    (run / "rotation-vector.txt").write_text(rows(np.c_[
        t, np.zeros_like(t), np.zeros_like(t), np.sin(half), np.cos(half), np.full_like(t, 0.17)]))
    (run / "record.properties").write_text(
        "[Device]\nManufacturer = LGE\nModel = Nexus 5\n[Time]\nStartTime = 1")
    with pytest.warns(UserWarning) as caught:
        parts = ridi.read_any(run)
    assert len(parts) == 2
    messages = [str(w.message) for w in caught]
    gap = [m for m in messages if "gap of" in m]
    assert gap, messages
    assert "ty\\nrex\\u{1b}[2J" in gap[0] and not any(c in gap[0] for c in "\n\x1b"), gap[0]


def test_a_corrupt_cell_is_named_by_file_line_and_field(tmp_path):
    folder = tmp_path / "run" / "processed"
    folder.mkdir(parents=True)
    with gzip.open(RUN / "processed" / "data.csv.gz", "rt") as f:
        lines = f.read().splitlines()
    cells = lines[5].split(",")
    header = lines[0].split(",")
    column = header.index("gyro_x")
    cells[column] = "abc"
    lines[5] = ",".join(cells)
    (folder / "data.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"data.csv:6: field `gyro_x`"):
        ridi.read(folder / "data.csv")


def test_sequence_from_arrays_equals_the_one_read(seq, model):
    built = ridi.Sequence(**arrays_of(seq))
    for name in ("time", "gyro", "acce", "linacce", "gravity", "orientation",
                 "ground_truth_position", "ground_truth_orientation"):
        np.testing.assert_array_equal(getattr(built, name), getattr(seq, name))
    assert (built.name, built.placement, built.format) == (seq.name, seq.placement, None)
    a = ridi.track(seq, model)
    b = ridi.track(built, model)
    np.testing.assert_array_equal(a.position, b.position)


def test_any_layout_is_read_in_place(seq):
    n = len(seq)
    args = arrays_of(seq)
    # Fortran order, a strided view of a wider array, and a reversed-stride view.
    args["gyro"] = np.asfortranarray(seq.gyro)
    wide = np.zeros((n, 6))
    wide[:, ::2] = seq.acce
    args["acce"] = wide[:, ::2]
    assert not args["acce"].flags.c_contiguous
    flipped = np.ascontiguousarray(seq.gravity[::-1])
    args["gravity"] = flipped[::-1]
    sparse_time = np.zeros(2 * n)
    sparse_time[::2] = seq.time
    args["time"] = sparse_time[::2]
    built = ridi.Sequence(**args)
    np.testing.assert_array_equal(built.gyro, seq.gyro)
    np.testing.assert_array_equal(built.acce, seq.acce)
    np.testing.assert_array_equal(built.gravity, seq.gravity)
    np.testing.assert_array_equal(built.time, seq.time)


def test_record_fields_and_unaligned_views_are_read_by_value(seq):
    # A float64 field of a record array (strides of 9 bytes: not a multiple of 8) and a
    # float64 view at an odd byte offset (unaligned) are read as the numbers they show.
    n = len(seq)
    args = arrays_of(seq)
    rec = np.zeros(n, dtype=[("t", "f8"), ("ok", "?")])
    rec["t"] = seq.time
    assert rec["t"].strides == (9,)
    args["time"] = rec["t"]
    raw = np.zeros(n * 3 * 8 + 1, dtype=np.uint8)
    raw[1:] = np.frombuffer(np.ascontiguousarray(seq.acce).tobytes(), dtype=np.uint8)
    odd = np.frombuffer(raw.tobytes(), dtype="f8", offset=1).reshape(n, 3)
    assert odd.ctypes.data % 8 != 0
    args["acce"] = odd
    built = ridi.Sequence(**args)
    np.testing.assert_array_equal(built.time, seq.time)
    np.testing.assert_array_equal(built.acce, seq.acce)


def test_views_of_more_frames_than_memory_holds_are_a_memory_error():
    # A broadcast costs numpy nothing; its copy would be 24 PB, beyond any address space: a
    # MemoryError, not an aborted interpreter.
    huge = 10**15
    time = np.broadcast_to(0.0, (huge,))
    rows = np.broadcast_to(np.zeros(3), (huge, 3))
    with pytest.raises(MemoryError, match=r"`gyro` has 1000000000000000 frames, more than memory"):
        ridi.Sequence(time, rows, rows)


def test_arrays_of_other_real_dtypes_and_array_likes_read_as_float64(seq):
    # float32 sensors, integer counts, lists, an object with __array__ (a pandas column):
    # each converted as np.asarray(x, dtype=np.float64) would, so the sequence is the one
    # built from those float64 arrays.
    args = arrays_of(seq)

    class Column:
        def __init__(self, values):
            self.values = values

        def __array__(self, dtype=None, copy=None):
            return self.values

    given = dict(args, gyro=args["gyro"].astype(np.float32), acce=args["acce"].tolist(),
                 gravity=Column(args["gravity"]), linacce=np.asfortranarray(args["linacce"]),
                 time=tuple(args["time"]))
    expected = dict(args, gyro=args["gyro"].astype(np.float32).astype(np.float64))
    built, reference = ridi.Sequence(**given), ridi.Sequence(**expected)
    for key in ("time", "gyro", "acce", "gravity", "linacce", "orientation"):
        np.testing.assert_array_equal(getattr(built, key), getattr(reference, key), err_msg=key)
    # Objects that are numbers (a pandas nullable column's values), array.array: as numpy reads.
    import array
    boxed = ridi.Sequence(**dict(args, gyro=args["gyro"].astype(object),
                                 time=array.array("d", args["time"])))
    np.testing.assert_array_equal(boxed.gyro, args["gyro"])
    np.testing.assert_array_equal(boxed.time, args["time"])
    # Integers convert exactly.
    whole = np.round(args["acce"]).astype(np.int32)
    rounded = ridi.Sequence(**dict(args, acce=whole))
    np.testing.assert_array_equal(rounded.acce, whole.astype(np.float64))


def test_linacce_defaults_to_acce_minus_gravity(seq):
    args = arrays_of(seq)
    del args["linacce"]
    built = ridi.Sequence(**args)
    np.testing.assert_allclose(built.linacce, seq.acce - seq.gravity)


@pytest.mark.parametrize(
    "change, error, message",
    [
        (lambda a: a.update(time=a["time"].astype(np.float32)), TypeError,
         r"`time` has dtype float32; ridi takes float64 \(its bits have rounded the timestamps"),
        (lambda a: a.update(gyro=a["gyro"] > 0), TypeError,
         r"`gyro` has dtype bool; ridi takes float64 \(an array of real numbers\)"),
        (lambda a: a.update(acce=a["acce"].astype(str)), TypeError, r"`acce` has dtype <U"),
        (lambda a: a.update(time=(a["time"] * 1e9).astype("timedelta64[ns]")), TypeError,
         r"`time` has dtype timedelta64\[ns\]; ridi takes float64 \(seconds as float64: "
         r"time / np.timedelta64\(1, 's'\)\)"),
        (lambda a: a.update(time=np.datetime64("2026-11-27") + (a["time"] * 1e9).astype(
            "timedelta64[ns]")), TypeError,
         r"`time` has dtype datetime64\[ns\]; ridi takes float64 \(seconds as float64: "
         r"\(time - time\[0\]\) / np.timedelta64\(1, 's'\)\)"),
        (lambda a: a.update(gyro=np.ma.masked_greater(a["gyro"], 1.0)), TypeError,
         r"`gyro` is a masked array with masked values: fill them"),
        (lambda a: a.update(gyro=(a["gyro"] * 1e9).astype("timedelta64[ns]")), TypeError,
         r"`gyro` has dtype timedelta64\[ns\]; ridi takes float64 \(dates and durations are "
         r"for `time`"),
        (lambda a: a.update(acce="acce.csv"), TypeError,
         r"`acce` must be an array of numbers \(a numpy array, a list of numbers or a pandas "
         r"column\), not str of length 8"),
        (lambda a: a.update(acce=[[0.0, 1.0, 2.0], [3.0]]), TypeError,
         r"`acce` must be an array of numbers .*not list of length 2 \(numpy: .*inhomogeneous"),
        (lambda a: a.update(acce=np.array([["x", 1.0, 2.0]] * len(a["time"]), dtype=object)),
         TypeError, r"`acce` has dtype object and holds text \(str\): parse the numbers first"),
        (lambda a: a.update(acce=a["acce"].astype(str).astype(object)), TypeError,
         r"`acce` has dtype object and holds text"),
        (lambda a: a.update(gyro=(a["gyro"] > 0).astype(object)), TypeError,
         r"`gyro` has dtype object and holds bools"),
        (lambda a: a.update(acce=np.array([[{}, 1.0, 2.0]] * len(a["time"]), dtype=object)),
         TypeError,
         r"`acce` has dtype object and values that are not real numbers \(numpy: "),
        (lambda a: a.update(time=np.array(list(a["time"].astype(np.float32)), dtype=object)),
         TypeError, r"`time` has dtype object and holds numpy float32 values, whose bits have "
         r"rounded"),
        (lambda a: a.update(gyro=a["gyro"][:, :2]), ValueError,
         r"`gyro` must have shape \(\d+, 3\), one row per frame of `time`; it has shape \(\d+, 2\)"),
        (lambda a: a.update(gravity=a["gravity"][:-1]), ValueError,
         r"`gravity` must have shape"),
        (lambda a: a.update(time=a["time"][:, None]), ValueError,
         r"`time` must have shape \(N,\); it has shape \(\d+, 1\)"),
        (lambda a: a["gyro"].__setitem__((7, 1), np.nan), ValueError,
         r"sequence `Thibaud_Nexus5_NoDist_Texting`: `gyro` is not finite at frame 7"),
        (lambda a: a["time"].__setitem__(9, np.inf), ValueError,
         r"`time` is not finite at frame 9"),
        (lambda a: a["orientation"].__setitem__(3, [2.0, 0.0, 0.0, 0.0]), ValueError,
         r"`orientation` at frame 3"),
        (lambda a: a["time"].__setitem__(4, a["time"][2]), ValueError,
         r"time does not increase at frame 4: .*: time goes back; if the rows are merely out of "
         r"order, sort every array by `np.argsort\(time, kind=\"stable\"\)` first"),
        (lambda a: a["time"].__setitem__(4, a["time"][3]), ValueError,
         r"a repeated timestamp; drop the repeated rows first \(`keep = np.r_\[True, "),
        (lambda a: a.update(time=a["time"] + np.where(np.arange(len(a["time"])) >= 1000, 1.5, 0)),
         ValueError, r"gap of 1.50\d s before frame 1000 .* exceeds 1 s: build a Sequence of each "
         r"side \(the arrays before that frame and from it on\)"),
        (lambda a: a.update(gyro=-a["gyro"]), ValueError,
         r"the gyro turns against the orientation: their rotation rates agree in direction by "
         r"-0.9\d+ .*sign flipped"),
        (lambda a: a.update(orientation=a["orientation"][:, [1, 2, 3, 0]], gravity=None,
                            linacce=None), ValueError,
         r"the gyro turns against the orientation: .*another component order"),
        (lambda a: a.update(ground_truth_orientation=None), ValueError,
         r"ground truth needs both"),
        (lambda a: a.update(acce=a["acce"] / 9.81, linacce=None), ValueError,
         r"accelerometer in g"),
        (lambda a: a.update(device=None), ValueError,
         r"`device_imu_rate_hz` without `device`: name the phone"),
        (lambda a: a.update(orientation_source="compass"), ValueError,
         r"`orientation_source` is 'compass'"),
        (lambda a: a.update(time=a["time"] * 1000), ValueError,
         r"time in milliseconds instead of seconds \(divide by 1000\)"),
        (lambda a: a.update(time=a["time"] * 1e9), ValueError,
         r"time in nanoseconds instead of seconds \(divide by 1e9\)"),
        (lambda a: a["ground_truth_position"].__setitem__((5, 0), np.nan), ValueError,
         r"`ground_truth_position` is not finite at frame 5"),
        (lambda a: a.update(orientation=a["orientation"][:, [1, 2, 3, 0]]), ValueError,
         r"a quaternion's components in another order \(\[x, y, z, w\] for \[w, x, y, z\]"),
    ],
)
def test_bad_arrays_are_refused_by_name(seq, change, error, message):
    args = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in arrays_of(seq).items()}
    change(args)
    with pytest.raises(error, match=message):
        ridi.Sequence(**args)


def test_arrays_without_orientation_are_checked_before_the_estimate(seq):
    gyro = seq.gyro.copy()
    gyro[100, 1] = np.nan
    with pytest.raises(ValueError, match=r"`Thibaud_Nexus5_NoDist_Texting`: `gyro` is not finite at "
                                         r"frame 100$"):
        ridi.Sequence(seq.time, gyro, seq.acce, name=seq.name)
    with pytest.raises(ValueError, match=r"time does not increase at frame 1: .*time goes back"):
        ridi.Sequence(seq.time[::-1].copy(), seq.gyro, seq.acce)


def test_resampling_refuses_rates_and_gap_limits_no_sequence_may_have(seq):
    with pytest.raises(ValueError, match=r"cannot resample to 0.5 Hz .*from 1.001 to 9990 Hz"):
        seq.resampled(0.5)
    # The rate as given, not rounded onto the bound it misses.
    with pytest.raises(ValueError, match=r"cannot resample to 1.0009 Hz"):
        seq.resampled(1.0009)
    for gap in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match=r"the gap limit a number above 0"):
            seq.resampled(100.0, max_gap_s=gap)
    assert len(seq.resampled(100.0, max_gap_s=float("inf"))) == pytest.approx(len(seq) / 2, abs=1)
    # Below the frame interval every frame is a gap: said so, rather than advising a split.
    with pytest.raises(ValueError, match=r"`max_gap_s` is 0.000001 s, below the median frame interval "
                                         r"of sequence `Thibaud_Nexus5_NoDist_Texting` \(0.005"):
        seq.resampled(200.0, max_gap_s=1e-6)


def test_with_placement_and_len(seq):
    other = seq.with_placement("hand")
    assert other.placement == "hand" and seq.placement != "hand"
    assert len(other) == len(seq)
    assert other.with_placement(None).placement is None


def test_a_copied_folder_reads_the_same(seq, tmp_path):
    copy = tmp_path / seq.name
    shutil.copytree(RUN, copy)
    again = ridi.read(str(copy))
    np.testing.assert_array_equal(again.orientation, seq.orientation)


def test_the_docstring_examples_run():
    import doctest

    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    finder = doctest.DocTestFinder(exclude_empty=True)
    for obj in (ridi.Sequence,):
        for test in finder.find(obj, obj.__name__, module=False, globs={"ridi": ridi}):
            runner.run(test)
    assert runner.tries > 0 and runner.failures == 0


def test_a_gap_ridi_track_refuses_is_split_into_parts_that_track(seq):
    args = arrays_of(seq)
    args["time"] = seq.time + np.where(np.arange(len(seq)) >= 2000, 0.3, 0.0)
    gappy = ridi.Sequence(**args)
    with pytest.raises(ValueError, match=r"a gap of 0\.30\d s between frames 1999 and 2000"):
        ridi.track(gappy, ridi.bundled_model())
    parts = gappy.split_at_gaps(0.1)
    assert [p.name for p in parts] == [f"{seq.name}_part1", f"{seq.name}_part2"]
    assert [len(p) for p in parts] == [2000, len(seq) - 2000]
    np.testing.assert_array_equal(parts[1].gyro, seq.gyro[2000:])
    assert parts[1].placement == seq.placement
    for p in parts:
        assert len(ridi.track(p, ridi.bundled_model())) == len(p)
    assert [p.name for p in gappy.split_at_gaps(0.5)] == [seq.name]
    with pytest.raises(ValueError, match="cannot split at gaps longer than NaN s into parts"):
        gappy.split_at_gaps(float("nan"))
    # Parts shorter than asked go; one left keeps the plain name.
    # (10 s and 14 s long)
    (only,) = gappy.split_at_gaps(0.1, min_duration_s=12.0)
    assert (only.name, len(only)) == (seq.name, len(seq) - 2000)


def test_gravity_and_orientation_left_out_are_derived_or_estimated(seq, model):
    args = arrays_of(seq)
    # The orientation alone: gravity is its up axis, as the readers derive it.
    no_gravity = ridi.Sequence(**{**args, "gravity": None, "linacce": None})
    np.testing.assert_allclose(no_gravity.gravity, seq.gravity, atol=1e-3)
    # Neither: both from gyro and accelerometer, as the model on the estimated orientation
    # makes them, and tracked with the gyro's heading alone.
    bare = ridi.Sequence(seq.time, seq.gyro, seq.acce, name=seq.name)
    assert bare.orientation_source == "estimated"
    tilt = np.degrees(np.arccos(np.clip(
        np.sum(bare.gravity * seq.gravity, axis=1)
        / np.linalg.norm(bare.gravity, axis=1) / np.linalg.norm(seq.gravity, axis=1), -1, 1)))
    assert np.median(tilt) < 5.0
    np.testing.assert_allclose(ridi.track(bare, model).position,
                               ridi.track(seq, model, heading="gyro").position, atol=1e-6)
    with pytest.raises(ValueError, match="`gravity` without `orientation`"):
        ridi.Sequence(seq.time, seq.gyro, seq.acce, seq.gravity)
    with pytest.raises(ValueError, match="names a recorded orientation, but none was given"):
        ridi.Sequence(seq.time, seq.gyro, seq.acce, orientation_source="rotation-vector")
    with pytest.raises(ValueError, match="time in milliseconds"):
        ridi.Sequence(seq.time * 1000, seq.gyro, seq.acce)


def test_a_data_csv_of_gyro_and_accelerometer_alone_reads_with_the_estimate(seq, tmp_path):
    # A recorder that logs only the two sensors: the orientation estimated as from arrays.
    ns = np.round(seq.time * 1e9).astype(np.int64)
    lines = ["time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z"] + [
        ",".join([str(t), *map(repr, g), *map(repr, a)])
        for t, g, a in zip(ns.tolist(), seq.gyro.tolist(), seq.acce.tolist())
    ]
    (tmp_path / "data.csv").write_text("\n".join(lines) + "\n")
    read = ridi.read(tmp_path / "data.csv")
    bare = ridi.Sequence(read.time, seq.gyro, seq.acce)
    assert read.orientation_source == "estimated"
    for key in ("orientation", "gravity", "linacce"):
        np.testing.assert_array_equal(getattr(read, key), getattr(bare, key), err_msg=key)
    (tmp_path / "data.csv.meta").write_text("orientation_source = game-rotation-vector\n")
    with pytest.raises(ValueError, match=r"data.csv.meta:1: field `orientation_source`: names"):
        ridi.read(tmp_path / "data.csv")

def test_a_recording_paused_for_seconds_is_read_split_at_its_gaps(seq, tmp_path):
    ns = np.round(seq.time * 1e9).astype(np.int64)
    ns[2000:] += 3_000_000_000
    lines = ["time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z"] + [
        ",".join([str(t), *map(repr, g), *map(repr, a)])
        for t, g, a in zip(ns.tolist(), seq.gyro.tolist(), seq.acce.tolist())
    ]
    path = tmp_path / "data.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"data.csv:2002: field `time`: gap of 3.005 s.*in Python "
                                         r"`ridi.read_any\(path, split_at_gaps=0.1\)`"):
        ridi.read(path)
    with pytest.warns(UserWarning, match=r"split at 1 gap longer than 0.1 s; 2 parts kept"):
        first, second = ridi.read_any(path, split_at_gaps=0.1)
    assert (len(first), len(second)) == (2000, len(seq) - 2000)
    np.testing.assert_array_equal(second.gyro, seq.gyro[2000:])
    with pytest.raises(ValueError, match="holds 2 sequences"), pytest.warns(UserWarning):
        ridi.read(path, split_at_gaps=0.1)
    with pytest.raises(ValueError, match="cannot split at gaps longer than -1 s"):
        ridi.read_any(path, split_at_gaps=-1.0)
    with pytest.raises(ValueError, match="the readers accept gaps of up to 1 s, so a split must"):
        ridi.read_any(path, split_at_gaps=1.0)
    # Cut at every step, no part is long enough: said, with what to do.
    with pytest.raises(ValueError, match=r"no part left once cut at its gaps, .*a larger "
                                         r"`split_at_gaps`"), pytest.warns(UserWarning):
        ridi.read(path, split_at_gaps=0.001)

def same_sequence(a, b):
    """Every constructor argument of `a` and `b` agrees (so a new argument the pickling misses
    fails here)."""
    import inspect

    for key in inspect.signature(ridi.Sequence).parameters:
        x, y = getattr(a, key), getattr(b, key)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=key)
        else:
            assert x == y, key


def test_every_kind_of_sequence_pickles(seq):
    import pickle

    bare = ridi.Sequence(seq.time, seq.gyro, seq.acce, name="bare")
    args = arrays_of(seq)
    n = len(seq)
    full = ridi.Sequence(**{**args, "magnet": np.tile([20.0, -5.0, 40.0], (n, 1)),
                            "steps": np.arange(n) / 100.0, "device": "Pixel 7",
                            "device_imu_rate_hz": 400.0, "orientation_source": "ekf"})
    # Resampled: slerped orientations, which must be unit to round-off to be rebuilt bit for bit
    # (slerp between rotations microradians apart strayed from unit norm by up to 1e-9).
    for s in (seq, bare, full, seq.resampled(150.0)):
        same_sequence(pickle.loads(pickle.dumps(s)), s)
    assert full.device == "Pixel 7" and full.device_imu_rate_hz == 400.0
    assert bare.orientation_source == "estimated"


@pytest.mark.parametrize("start", ["spawn", "fork"])
def test_sequences_pickle_for_other_processes(seq, model, start):
    import multiprocessing
    import pickle
    from concurrent.futures import ProcessPoolExecutor

    if start not in multiprocessing.get_all_start_methods():
        pytest.skip(f"no {start} on this platform")
    same_sequence(pickle.loads(pickle.dumps(seq)), seq)
    # This process has used ridi's worker threads already: a forked child has none of them,
    # and ridi starts its own there (it waited for ever on the parent's before). A model in
    # half precision decodes on worker threads too, as it arrives in the child.
    half = ridi.train(ridi.read_list(SAMPLE / "list_Guillaume.txt", placement_map="tyrex4")[:4],
                      grid="none", storage="half")
    here = [ridi.track(seq, m) for m in (model, half)]
    context = multiprocessing.get_context(start)
    with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
        far = [pool.submit(ridi.track, seq, m).result(timeout=120) for m in (model, half)]
        regressed = pool.submit(ridi.regress, seq, model).result(timeout=120)
    for a, b in zip(far, here):
        np.testing.assert_array_equal(a.position, b.position)
    np.testing.assert_array_equal(regressed.velocity, here[0].regressions.velocity)
    assert regressed.placement == here[0].regressions.placement
