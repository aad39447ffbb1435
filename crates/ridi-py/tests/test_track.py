"""ridi.track, ridi.regress and ridi.LiveTracker: the trajectory of `ridi track` (batch and
online) within 1e-9, the live tracker's poses equal to online tracking, the GIL released, and
refused inputs."""

import collections
import itertools
import subprocess
import threading

import numpy as np
import pytest

import ridi
from conftest import RIDI_BIN, SAMPLE, arrays_of

RUN = SAMPLE / "Thibaud_Nexus5_NoDist_Texting"
COLUMNS = "time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x,bias_y,bias_z"


def cli_track(ridi_bin, model_file, out, *flags):
    ridi_bin("track", RUN, "--model", model_file, "--out", out, *flags)
    text = out.read_text().splitlines()
    assert text[0] == COLUMNS
    rows = [line.split(",") for line in text[1:]]
    numbers = np.array([[float(c) for i, c in enumerate(r) if i != 7] for r in rows])
    return numbers, [r[7] for r in rows]


@pytest.mark.parametrize("online", [False, True])
def test_track_equals_the_cli_trajectory(seq, model, model_file, ridi_bin, tmp_path, online):
    numbers, placements = cli_track(
        ridi_bin, model_file, tmp_path / "cli.csv", *(["--online"] if online else [])
    )
    track = ridi.track(seq, model, online=online)
    assert len(track) == len(seq) == len(numbers)
    mine = np.column_stack([track.time, track.position, track.velocity, track.bias])
    np.testing.assert_allclose(mine, numbers, rtol=0, atol=1e-9)
    # The CSV's placement column: the latest regression's, empty before the first.
    regs = track.regressions
    expected = [""] * len(seq)
    for frame, label in zip(regs.frame, regs.placement):
        expected[frame:] = [label] * (len(seq) - frame)
    assert placements == expected
    # And the same file, byte for byte.
    track.write_csv(tmp_path / "py.csv")
    same = (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    assert same, "write_csv differs from `ridi track`'s CSV"


def test_track_options_reach_the_cli_flags(seq, model, model_file, ridi_bin, tmp_path):
    numbers, _ = cli_track(
        ridi_bin, model_file, tmp_path / "cli.csv", "--regress-every", "25", "--lambda", "0.5",
        "--estimate-initial-velocity", "--placement-window", "0",
    )
    track = ridi.track(seq, model, regress_every=25, lambda_=0.5,
                       estimate_initial_velocity=True, placement_window=0)
    np.testing.assert_allclose(track.position, numbers[:, 1:4], rtol=0, atol=1e-9)


def test_heading_gyro_is_the_cli_flag_and_what_a_live_tracker_without_orientation_gives(
    seq, model, model_file, ridi_bin, tmp_path
):
    numbers, _ = cli_track(ridi_bin, model_file, tmp_path / "cli.csv", "--heading", "gyro")
    gyro = ridi.track(seq, model, heading="gyro")
    np.testing.assert_allclose(gyro.position, numbers[:, 1:4], rtol=0, atol=1e-9)
    # The default corrects the gyro's heading by the recorded orientation's: another track.
    assert np.abs(ridi.track(seq, model).position - gyro.position).max() > 1e-6
    online = ridi.track(seq, model, online=True, heading="gyro")
    live = ridi.LiveTracker(model, heading="gyro")
    updates = []
    for i in range(len(seq)):
        updates += live.push(seq.time[i], seq.gyro[i], seq.acce[i])
    updates += live.finish()
    np.testing.assert_array_equal(np.array([u.position for u in updates]), online.position)
    assert repr(live).startswith("LiveTracker(placements=[") and repr(live).endswith(
        f"], {len(online.regressions.frame)} regressions so far)")
    # The orientation alone corrects the heading as the whole recorded triple does.
    corrected = ridi.track(seq, model, online=True)
    live = ridi.LiveTracker(model)
    updates = []
    for i in range(len(seq)):
        updates += live.push(seq.time[i], seq.gyro[i], seq.acce[i], orientation=seq.orientation[i])
    updates += live.finish()
    np.testing.assert_array_equal(np.array([u.position for u in updates]), corrected.position)


def test_regress_is_what_track_corrects_with(seq, model):
    track = ridi.track(seq, model)
    regs = ridi.regress(seq, model)
    np.testing.assert_array_equal(regs.frame, track.regressions.frame)
    np.testing.assert_array_equal(regs.velocity, track.regressions.velocity)
    assert regs.placement == track.regressions.placement
    assert regs.velocity.shape == (len(regs), 2) and regs.frame.dtype == np.int64
    assert set(regs.placement) <= set(model.placement_names)
    assert track.placement_names == model.placement_names
    assert "frames" in repr(track)


def test_updates_pickle(seq, model):
    import pickle

    live = ridi.LiveTracker(model)
    for i in range(450):
        updates = live.push(seq.time[i], seq.gyro[i], seq.acce[i], orientation=seq.orientation[i])
    assert updates
    back = pickle.loads(pickle.dumps(updates))
    assert [(u.frame, u.time, u.position, u.velocity, u.bias, u.restarted) for u in back] == [
        (u.frame, u.time, u.position, u.velocity, u.bias, u.restarted) for u in updates]


def test_live_tracker_gives_the_online_poses(seq, model):
    online = ridi.track(seq, model, online=True)
    live = ridi.LiveTracker(model)
    t, g, a = seq.time, seq.gyro, seq.acce
    q, grav, lin = seq.orientation, seq.gravity, seq.linacce
    updates = []
    for i in range(len(seq)):
        updates += live.push(t[i], g[i], a[i], orientation=q[i], gravity=grav[i], linacce=lin[i])
    updates += live.finish()
    assert [u.frame for u in updates] == list(range(len(seq)))
    np.testing.assert_array_equal(np.array([u.position for u in updates]), online.position)
    np.testing.assert_array_equal(np.array([u.bias for u in updates]), online.bias)
    assert not any(u.restarted for u in updates)
    np.testing.assert_array_equal(live.regressions.velocity, online.regressions.velocity)
    assert "Update(frame=0" in repr(updates[0])


def test_a_clock_that_jumped_ahead_is_named_when_the_stream_goes_back(seq, model):
    # A timestamp glitch ahead is taken for a pause (a new segment); every sample after it
    # then goes back, and the error says why and what to do.
    live = ridi.LiveTracker(model)
    t, g, a, q = seq.time, seq.gyro, seq.acce, seq.orientation
    for i in range(300):
        live.push(t[i], g[i], a[i], orientation=q[i])
    live.push(t[300] + 1000.0, g[300], a[300], orientation=q[300])
    with pytest.raises(ValueError, match=r"which came 100\d.\d+ s after the one before it \(taken "
                       r"for a pause, .*if that timestamp was a glitch, start a new tracker"):
        live.push(t[301], g[301], a[301], orientation=q[301])


def test_live_tracker_refuses_a_gyro_turning_against_the_orientation(seq, model):
    # The gyro's sign flipped: it turns against the orientation pushed with it; refused once
    # 10 s of samples came with one (here from the second second on), and from then on.
    live = ridi.LiveTracker(model)
    t, g, a, q = seq.time, -seq.gyro, seq.acce, seq.orientation
    for i in range(len(seq)):
        try:
            live.push(t[i], g[i], a[i], orientation=q[i] if i >= 200 else None)
        except ValueError as e:
            assert "the stream's 10" in str(e) and "sign flipped" in str(e)
            assert t[i] - t[200] == pytest.approx(10.0, abs=0.01)
            break
    else:
        pytest.fail("no sample refused")
    with pytest.raises(ValueError, match="the gyro turns against the orientation"):
        live.push(t[i + 1], g[i + 1], a[i + 1], orientation=q[i + 1])
    # A whole sequence that passed its checks is not judged again in stretches.
    ridi.track(seq, model, online=True)


def test_live_tracker_refuses_bad_samples_and_stays_usable(seq, recorded_model):
    live = ridi.LiveTracker(recorded_model)
    recorded = dict(orientation=seq.orientation[0], gravity=seq.gravity[0],
                    linacce=seq.linacce[0])
    with pytest.raises(ValueError, match="trained on the recorded orientation"):
        live.push(seq.time[0], seq.gyro[0], seq.acce[0])
    with pytest.raises(ValueError, match="together"):
        live.push(seq.time[0], seq.gyro[0], seq.acce[0], orientation=seq.orientation[0])
    with pytest.raises(ValueError, match=r"`orientation` at t = "):
        live.push(seq.time[0], seq.gyro[0], seq.acce[0], orientation=[2.0, 0, 0, 0],
                  gravity=seq.gravity[0], linacce=seq.linacce[0])
    with pytest.raises(ValueError, match=r"gyro"):
        live.push(seq.time[0], [1e6, 0.0, 0.0], seq.acce[0], **recorded)
    [first] = live.push(seq.time[0], seq.gyro[0], seq.acce[0], **recorded)
    assert first.frame == 0 and first.time == seq.time[0]
    with pytest.raises(ValueError, match="tracking"):
        live.push(seq.time[0], seq.gyro[0], seq.acce[0], **recorded)
    [second] = live.push(seq.time[1], seq.gyro[1], seq.acce[1], orientation=seq.orientation[1],
                         gravity=seq.gravity[1], linacce=seq.linacce[1])
    assert second.frame == 1
    with pytest.raises(ValueError, match="`regress_every` is 0"):
        ridi.LiveTracker(recorded_model, regress_every=0)
    with pytest.raises(ValueError, match="`regress_every` is -5"):
        ridi.LiveTracker(recorded_model, regress_every=-5)
    # What a chunk of samples or a missing one gets: the argument and what it wants.
    with pytest.raises(TypeError, match=r"`gyro` must be 3 numbers .* not NoneType"):
        live.push(seq.time[2], None, seq.acce[2], **recorded)
    with pytest.raises(TypeError, match=r"`time` must be one number.*ndarray of shape \(5,\)"):
        live.push(seq.time[2:7], seq.gyro[2:7], seq.acce[2:7], **recorded)
    # Numbers of another count are a wrong value, as a wrong shape is for `Sequence`.
    with pytest.raises(ValueError, match=r"`gravity` must be 3 numbers .* list of length 2"):
        live.push(seq.time[2], seq.gyro[2], seq.acce[2], orientation=seq.orientation[2],
                  gravity=[0.0, 9.8], linacce=seq.linacce[2])
    with pytest.raises(ValueError, match=r"`gyro` must be 3 numbers .* of shape \(5, 3\)"):
        live.push(seq.time[2], seq.gyro[2:7], seq.acce[2], **recorded)
    # One number is a wrong type, whether a Python float or a numpy scalar.
    with pytest.raises(TypeError, match=r"`gyro` must be 3 numbers .* not float64"):
        live.push(seq.time[2], np.float64(1.0), seq.acce[2], **recorded)
    # Judged by a look, not a copy (a copy of this view would be 8 PB).
    with pytest.raises(ValueError, match=r"`gyro` must be 3 numbers .* \(1000000000000000,\)"):
        live.push(seq.time[2], np.broadcast_to(0.0, (10**15,)), seq.acce[2], **recorded)
    # What numbers would read but a sample cannot hold: bools, a float32 time.
    with pytest.raises(TypeError, match=r"`gyro` holds bools"):
        live.push(seq.time[2], [True, False, True], seq.acce[2], **recorded)
    with pytest.raises(TypeError, match=r"`gyro` holds bools"):
        live.push(seq.time[2], np.array([True, 0.0, 0.0], dtype=object), seq.acce[2], **recorded)
    with pytest.raises(TypeError, match=r"`time` holds bools"):
        live.push(True, seq.gyro[2], seq.acce[2], **recorded)
    # Any sequence is looked into (a deque); an endless iterable is refused, not walked for ever.
    with pytest.raises(TypeError, match=r"`gyro` holds bools"):
        live.push(seq.time[2], collections.deque([True, 0.0, 0.0]), seq.acce[2], **recorded)
    with pytest.raises(TypeError, match=r"`gyro` must be 3 numbers"):
        live.push(seq.time[2], itertools.repeat(0.0), seq.acce[2], **recorded)
    with pytest.raises(TypeError, match=r"`time` is a float32: its bits have rounded"):
        live.push(np.float32(seq.time[2]), seq.gyro[2], seq.acce[2], **recorded)
    with pytest.raises(ValueError, match=r"`time` of sample 2 is NaN"):
        live.push(float("nan"), seq.gyro[2], seq.acce[2], **recorded)
    live.finish()
    with pytest.raises(ValueError, match="finished"):
        live.push(seq.time[2], seq.gyro[2], seq.acce[2], **recorded)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda t, g, a: (t[::4], g[::4], a[::4]), r"a rate of 50.0 Hz .* resample the stream"),
        (lambda t, g, a: (t * 1000, g, a), r"time in milliseconds instead of seconds"),
        (lambda t, g, a: (t, np.degrees(g) + 1, a), r"gyroscope in deg/s instead of rad/s"),
        (lambda t, g, a: (t, g, a / 9.81), r"accelerometer in g instead of m/s\^2"),
    ],
)
def test_a_live_stream_at_a_wrong_rate_or_unit_is_refused_within_a_second(seq, model, change,
                                                                         message):
    t, g, a = change(seq.time, seq.gyro, seq.acce)
    live = ridi.LiveTracker(model)
    with pytest.raises(ValueError, match=r"the stream's last 200 samples: .*" + message):
        for i in range(len(t)):
            live.push(t[i], g[i], a[i], orientation=seq.orientation[i])
    assert i == 200 and len(live.regressions) == 0


def test_untrackable_sequences_are_named(seq, model):
    args = arrays_of(seq)
    short = {k: (v[:150] if isinstance(v, np.ndarray) else v) for k, v in args.items()}
    # Named once, by the sequence's own error.
    named = r"^sequence `Thibaud_Nexus5_NoDist_Texting`: has 150 frames"
    for f in (ridi.track, ridi.regress):
        with pytest.raises(ValueError, match=named + r".*at least 201 frames are needed"):
            f(ridi.Sequence(**short), model)
    slow = ridi.Sequence(**{k: (v[::2] if isinstance(v, np.ndarray) else v)
                            for k, v in args.items()})
    for f in (ridi.track, ridi.regress):
        with pytest.raises(ValueError, match=r"rate of 100.0 Hz.*`resampled`"):
            f(slow, model)
    # Resampled to the models' rate it tracks, close to the recording at 200 Hz.
    again = slow.resampled(ridi.RATE_HZ)
    assert abs(again.median_rate_hz - ridi.RATE_HZ) < 1e-6
    assert (again.name, again.placement) == (seq.name, seq.placement)
    end = ridi.track(again, model).position[-1]
    assert np.linalg.norm(end - ridi.track(seq, model).position[-1]) < 1.0


def test_resampling_refuses_to_fill_a_gap(seq):
    args = arrays_of(seq)
    t = args["time"].copy()
    t[3000:] += 0.5
    gappy = ridi.Sequence(**{**args, "time": t})
    with pytest.raises(ValueError, match=r"gap of 0.505 s.*exceeds 0.025 s: cut it there first \(`split_at_gaps\(0.02"):
        gappy.resampled(100.0)
    assert len(gappy.resampled(100.0, max_gap_s=1.0)) == pytest.approx(
        (t[-1] - t[0]) * 100, abs=1)
    with pytest.raises(ValueError, match="rate"):
        seq.resampled(-1.0)


@pytest.mark.parametrize(
    "options, message",
    [
        (dict(regress_every=0), r"`regress_every` is 0; expected a whole number from 1 to 12000"),
        (dict(lambda_=-1.0), r"`lambda_` is -1"),
        (dict(placement_window=-2.0), r"`placement_window` is -2"),
        (dict(placement_window=float("nan")), r"`placement_window` is NaN"),
        (dict(heading="magnetic"), r"`heading` is 'magnetic'; expected one of 'corrected', 'gyro'"),
    ],
)
def test_bad_tracking_options_are_refused(seq, model, options, message):
    with pytest.raises(ValueError, match=message):
        ridi.track(seq, model, **options)


def test_tracking_releases_the_gil(seq, model):
    done = threading.Event()
    result = []

    def work():
        result.append(ridi.track(seq, model))
        done.set()

    worker = threading.Thread(target=work)
    spins = 0
    worker.start()
    while not done.is_set():
        spins += 1
    worker.join()
    # Held by the tracking, the GIL would let this loop run only before and after it.
    assert spins > 10_000 and len(result[0]) == len(seq)


def test_outputs_that_cannot_be_written_say_why_as_the_command_line(seq, model, ridi_bin,
                                                                   tmp_path):
    ridi_bin("--version")  # fails the test, saying why, without a binary
    track = ridi.track(seq, model)
    missing = tmp_path / "nodir" / "t.csv"
    cli = subprocess.run([str(RIDI_BIN), "track", str(RUN), "--out", str(missing)],
                         capture_output=True, text=True)
    assert cli.returncode == 1
    with pytest.raises(FileNotFoundError) as e:
        track.write_csv(missing)
    # The command's message after `error: `, once: no OS error number, no temporary file.
    assert str(e.value) in cli.stderr, (str(e.value), cli.stderr)
    assert str(e.value) == f"cannot write {missing}: the folder {missing.parent} does not exist"
    with pytest.raises(FileNotFoundError, match="does not exist"):
        model.save(tmp_path / "nodir" / "m.ridi")
    with pytest.raises(IsADirectoryError, match=r"t\.csv: it is a folder$"):
        (tmp_path / "t.csv").mkdir()
        track.write_csv(tmp_path / "t.csv")
    assert not list(tmp_path.glob("**/.ridi-tmp*"))


def test_placement_maps_that_are_not_there_are_named_as_missing(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"tyrex5: no such file or folder \(a placement "
                                                r"map is `tyrex4`"):
        ridi.read_list(SAMPLE / "list_test.txt", placement_map="tyrex5")
    with pytest.raises(FileNotFoundError, match=r"nolist\.txt: no such file or folder$"):
        ridi.read_list(tmp_path / "nolist.txt")


def test_tracks_pickle_bit_for_bit(seq, model):
    import pickle

    track = ridi.track(seq, model)
    back = pickle.loads(pickle.dumps(track))
    for key in ("time", "position", "velocity", "bias"):
        np.testing.assert_array_equal(getattr(back, key), getattr(track, key))
    np.testing.assert_array_equal(back.regressions.velocity, track.regressions.velocity)
    np.testing.assert_array_equal(back.regressions.frame, track.regressions.frame)
    assert back.regressions.placement == track.regressions.placement
    assert back.placement_names == track.placement_names
    with pytest.raises(ValueError, match="not the state of a pickled ridi.Track"):
        ridi.Track._from_state(b"\0" * 12, [])


@pytest.mark.parametrize(
    "call",
    [
        lambda s, m: s.resampled(True),
        lambda s, m: s.split_at_gaps(np.bool_(True), 0.0),
        lambda s, m: s.resampled(np.array(True)),
        lambda s, m: ridi.track(s, m, regress_every=True),
        lambda s, m: ridi.track(s, m, placement_window=False),
        lambda s, m: ridi.LiveTracker(m, lambda_=True),
    ],
)
def test_a_bool_is_no_number(seq, model, call):
    # `True` would read as 1 (an alignment on 1 s, a regression every frame): refused, the
    # argument named in the exception's notes.
    with pytest.raises(TypeError, match=r"expected a number, not a bool") as caught:
        call(seq, model)
    assert any("while processing" in n for n in getattr(caught.value, "__notes__", []))


def test_a_path_or_another_object_for_a_model_or_sequence_says_how_to_get_one(
        seq, model, model_file):
    with pytest.raises(TypeError, match=r"`model` is str of length \d+, not a ridi.Model: load a "
                                        r"model file with ridi.load\(path\)"):
        ridi.track(seq, str(model_file))
    with pytest.raises(TypeError, match=r"`model` is PosixPath, not a ridi.Model: .*ridi.load"):
        ridi.evaluate([seq], model_file)
    with pytest.raises(TypeError, match=r"`model` is NoneType, not a ridi.Model: train one "
                                        r"\(ridi.train\), .*ridi.bundled_model"):
        ridi.LiveTracker(None)
    with pytest.raises(TypeError, match=r"`sequence` is str of length 8, not a ridi.Sequence: "
                                        r"read a recording with ridi.read\(path\)"):
        ridi.regress("walk.csv", model)
