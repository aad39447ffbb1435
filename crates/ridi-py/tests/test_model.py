"""ridi.train, ridi.load, Model.save and the model's description: the same model file as
`ridi train` with the same options, progress, cancellation, and bad options and inputs."""

import _thread
import json
import os
import pickle
import subprocess
import sys
import time
import warnings

import pytest

import ridi
from conftest import SAMPLE

GUILLAUME = SAMPLE / "list_Guillaume.txt"


def test_train_gives_the_cli_model_bytes(model, ridi_bin, tmp_path):
    out = tmp_path / "cli.ridi"
    ridi_bin("train", "--list", GUILLAUME, "--out", out, "--grid", "none",
             "--placement-map", "tyrex4")
    # A bool, not the bytes: pytest's explanation of two differing models takes minutes.
    same = model.to_bytes() == out.read_bytes()
    assert same, "the model differs from the one `ridi train` writes"
    assert model.placement_names == ["hand", "pocket", "running", "swing"]
    assert (model.window, model.orientation, model.up_axis) == (200, "estimated", "plus-or-minus-y")
    # One spelling: the description's, the property's and the argument's.
    assert model.describe()["up_axis"] == model.up_axis


def test_the_nystrom_solver_gives_the_cli_model_bytes(ridi_bin, tmp_path):
    out = tmp_path / "cli.ridi"
    ridi_bin("train", "--list", GUILLAUME, "--out", out, "--grid", "none",
             "--placement-map", "tyrex4", "--solver", "nystrom", "--landmarks", "64")
    model = ridi.train(GUILLAUME, grid="none", placement_map="tyrex4", solver="nystrom",
                       landmarks=64)
    same = model.to_bytes() == out.read_bytes()
    assert same, "the Nyström model differs from the one `ridi train` writes"
    # The Nyström solver's own projection (90 %), not the exact solver's 99.99 %.
    assert 0.9 <= model.describe()["stored_variance"] < 0.9999
    # Another seed draws other landmarks: another model, the same from both.
    ridi_bin("train", "--list", GUILLAUME, "--out", out, "--grid", "none",
             "--placement-map", "tyrex4", "--solver", "nystrom", "--landmarks", "64",
             "--seed", "3")
    seeded = ridi.train(GUILLAUME, grid="none", placement_map="tyrex4", solver="nystrom",
                        landmarks=64, seed=3)
    same = seeded.to_bytes() == out.read_bytes()
    assert same, "the seeded Nyström model differs from the one `ridi train` writes"
    other = seeded.to_bytes() != model.to_bytes()
    assert other, "the seed did not change the landmarks"


def test_save_load_pickle_and_describe(model, model_file, ridi_bin):
    loaded = ridi.load(model_file)
    same = loaded.to_bytes() == model.to_bytes() == model_file.read_bytes()
    assert same, "a saved and loaded model differs"
    same = pickle.loads(pickle.dumps(model)).to_bytes() == model.to_bytes()
    assert same, "a pickled model differs"
    assert model.describe() == json.loads(ridi_bin("inspect", model_file, "--json"))
    assert model.describe()["solver"] == "exact"
    assert str(model).strip() in ridi_bin("inspect", model_file)
    assert "hand" in repr(model)


def test_train_on_sequences_equals_train_on_the_list(model):
    seqs = ridi.read_list(GUILLAUME, placement_map="tyrex4", purpose="training")
    same = ridi.train(seqs, grid="none").to_bytes() == model.to_bytes()
    assert same, "training on the sequences differs from training on the list"


def test_progress_reports_each_stage_and_can_cancel():
    seqs = ridi.read_list(GUILLAUME, placement_map="tyrex4")[:4]
    events = []
    ridi.train(seqs, grid="none", progress=lambda *e: events.append(e), jobs=1)
    stages = [s for s, done, total in events]
    assert stages[0] == "placement classifier"
    assert any(s.startswith("regressors ") for s in stages)
    assert all(0 <= done <= total for _, done, total in events)
    with pytest.raises(RuntimeError, match="cancelled"):
        ridi.train(seqs, grid="none", progress=lambda *e: False)

    def fail(*_):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        ridi.train(seqs, grid="none", progress=fail)


def test_ctrl_c_stops_a_training_on_worker_threads():
    # Python runs signal handlers on its main thread only, and the callback here runs on one
    # of the training's own: Ctrl-C must stop the training at its next report, not after it.
    seqs = ridi.read_list(GUILLAUME, placement_map="tyrex4")[:4]
    events = []

    def progress(*event):
        events.append(event)
        if len(events) == 1:
            _thread.interrupt_main()  # as Ctrl-C
            time.sleep(1)  # the main thread notices meanwhile

    with pytest.raises(KeyboardInterrupt):
        ridi.train(seqs, grid="none", progress=progress, jobs=2)
    # The first report is the classifier's start, before any parallel work; the test above
    # shows a whole training reports many more.
    assert events == [("placement classifier", 0, events[0][2])]


@pytest.mark.parametrize(
    "options, message",
    [
        (dict(grid="huge"), r"`grid` is 'huge'; expected one of 'paper', 'small', 'none'"),
        (dict(turned_copies=33), r"`turned_copies` is 33; expected a whole number from 0 to 32"),
        (dict(window=10), r"`window` is 10; expected a whole number from 20 to 600"),
        (dict(step=0), r"`step` is 0"),
        (dict(classifier_c=0.0), r"`classifier_c` is 0"),
        (dict(solver="nystrom", landmarks=1), r"`landmarks` is 1"),
        (dict(landmarks=64), r"`landmarks` is for solver=\"nystrom\""),
        (dict(landmarks=1), r"`landmarks` is 1"),
        (dict(storage="full"), r"`storage` is 'full'"),
        (dict(orientation="magnetic"), r"`orientation` is 'magnetic'"),
        (dict(up_axis="z"), r"`up_axis` is 'z'"),
        (dict(jobs=0), r"`jobs` is 0"),
        (dict(jobs=-1), r"`jobs` is -1; expected a whole number from 1"),
        (dict(turned_copies=-1), r"`turned_copies` is -1; expected a whole number from 0"),
        (dict(seed=-1), r"`seed` is -1; expected a whole number from 0 to 18446744073709551615"),
        (dict(seed=2**64), r"`seed` is 18446744073709551616"),
        (dict(placement_map="no-such-map.txt"), r"no-such-map.txt"),
        (dict(seed=True), r"expected a number, not a bool"),
        (dict(landmarks=True), r"expected a number, not a bool"),
    ],
)
def test_bad_training_options_are_refused(options, message):
    error = (OSError if "placement_map" in options
             else TypeError if any(v is True for v in options.values()) else ValueError)
    with pytest.raises(error, match=message):
        ridi.train(GUILLAUME, **options)


def test_training_lists_are_checked_at_their_line(tmp_path):
    run = SAMPLE / "Guillaume_Nexus5_NoDist_AR"
    listed = tmp_path / "train.txt"
    listed.write_text(f"{run},AR\n{SAMPLE / 'Guillaume_Nexus5_NoDist_Texting'}\n")
    # A processed file carries no label of its own: training needs it in the list.
    with pytest.raises(ValueError, match=r"train.txt:2: field `placement`"):
        ridi.train(listed, grid="none")
    with pytest.raises(ValueError, match=r"no placement label"):
        ridi.train([ridi.read(run)], grid="none")
    # A label the map lacks is refused in sequences as in lists, not made a class of its own.
    typo = [ridi.read(run).with_placement("Swingin")]
    message = r"sequence `Guillaume_Nexus5_NoDist_AR`: placement `Swingin` is not in the placement map"
    with pytest.raises(ValueError, match=message):
        ridi.train(typo, grid="none", placement_map="tyrex4")
    with pytest.raises(ValueError, match=message):
        ridi.evaluate(typo, ridi.bundled_model(), placement_map="tyrex4")
    with pytest.raises(TypeError, match="list file"):
        ridi.train(3.5)
    with pytest.raises(ValueError, match="no list file and no sequence"):
        ridi.train([])


def test_grid_search_with_too_few_sequences_says_how_to_train_without(tmp_path):
    seqs = ridi.read_list(GUILLAUME, placement_map="tyrex4")[:2]
    with pytest.raises(ValueError, match=r"grid=\"none\"` trains without it"):
        ridi.train(seqs, grid="small")


def test_a_searched_model_describes_its_cross_validation():
    lists = [SAMPLE / "list_Guillaume.txt", SAMPLE / "list_Jakob.txt"]
    model = ridi.train(lists, grid="small", solver="nystrom", landmarks=64, placement_map="tyrex4")
    table = model.describe()["cross_validation"]
    # Per placement and channel (S-x, S-z and the speed), the grid's rows.
    assert {(r["placement"], r["channel"]) for r in table} == {
        (p, c) for p in model.placement_names for c in (0, 1, 2)}
    assert all(r["mse"] > 0 and len(r["fold_mse"]) >= 2 for r in table), table
    text = str(model)
    assert "cross-validation" in text
    # Kernel ridge regressors: a C, and no epsilon to show.
    assert "epsilon" not in text and "eps=" not in text, text


def test_model_files(tmp_path, model):
    with pytest.raises(FileNotFoundError, match=r"cannot load model .*nowhere.ridi"):
        ridi.load(tmp_path / "nowhere.ridi")
    junk = tmp_path / "junk.ridi"
    junk.write_bytes(b"not a model at all, but long enough for a header")
    with pytest.raises(ValueError, match=r"cannot load model .*junk.ridi"):
        ridi.load(junk)
    with pytest.raises(ValueError, match="cannot load model"):
        ridi.Model.from_bytes(b"\0" * 10)
    with pytest.raises(OSError, match=r"cannot write .*missing"):
        model.save(tmp_path / "missing" / "m.ridi")


def test_the_bundled_model_is_the_one_ridi_track_uses_without_a_model(ridi_bin, tmp_path):
    model = ridi.bundled_model()
    assert model.placement_names == ["hand", "pocket", "running", "swing"]
    description = model.describe()
    assert description["solver"] == "nystrom" and description["landmarks"] is not None
    assert description["landmark_seed"] == 0 and description["cross_validation"] == []
    seq = ridi.read(SAMPLE / "Thibaud_Nexus5_NoDist_Texting")
    out = tmp_path / "t.csv"
    ridi_bin("track", SAMPLE / "Thibaud_Nexus5_NoDist_Texting", "--out", out)
    ridi.track(seq, model).write_csv(tmp_path / "py.csv")
    same = (tmp_path / "py.csv").read_bytes() == out.read_bytes()
    assert same, "the bundled model tracks otherwise than `ridi track` without --model"


def test_a_training_error_names_the_first_bad_sequence_whatever_the_threads():
    seqs = ridi.read_list(SAMPLE / "list_Guillaume.txt", placement_map="tyrex4")
    bare = [ridi.Sequence(s.time, s.gyro, s.acce, s.gravity, s.orientation, name=s.name,
                          placement=s.placement) for s in seqs]
    for jobs in (1, 2, 4, 4, 4):
        with pytest.raises(ValueError, match=rf"sequence `{bare[0].name}`: has no ground truth"):
            ridi.train(bare, grid="none", jobs=jobs)


def test_training_on_waypoint_ground_truth_warns(tmp_path):
    # A run whose ground truth is straight lines between a point every 5 s (the competition's
    # waypoints, interpolated): its targets are the lines' speeds, which the warning says.
    seqs = ridi.read_list(GUILLAUME, placement_map="tyrex4")[:4]
    s = seqs[0]
    t, p = s.time, s.ground_truth_position.copy()
    marks = list(range(0, len(t), 1000)) + [len(t) - 1]
    for a, b in zip(marks, marks[1:]):
        f = ((t[a:b + 1] - t[a]) / (t[b] - t[a]))[:, None]
        p[a:b + 1] = p[a] + (p[b] - p[a]) * f
    straight = ridi.Sequence(s.time, s.gyro, s.acce, s.gravity, s.orientation,
                             linacce=s.linacce, name="straight", placement=s.placement,
                             ground_truth_position=p,
                             ground_truth_orientation=s.ground_truth_orientation)
    events = []
    with pytest.warns(UserWarning, match=r"1 of 4 training sequences \(straight \(0\.\d a second\)\) "
                                         r"has a ground truth that moves in straight lines"):
        ridi.train([straight, *seqs[1:]], grid="none")
    # Before training, as `ridi train` prints it: a warning made an error stops it there.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="straight lines"):
            ridi.train([straight, *seqs[1:]], grid="none", progress=lambda *e: events.append(e))
    assert events == []


@pytest.mark.parametrize("value, warning", [
    ("100000", "RAYON_NUM_THREADS=100000 is over 4096 threads: using one worker thread per core"),
    ("2x", "RAYON_NUM_THREADS=2x is not a whole number: using one worker thread per core"),
    ("1", None),
    ("", None),
])
def test_rayon_num_threads_is_checked_at_import(value, warning):
    # rayon would start what RAYON_NUM_THREADS asks for at its first parallel call, without a
    # bound, and panic if the system refused: import starts the pool, and a count out of range
    # is a warning there; tracking runs on whatever was started.
    script = ("import warnings, sys; warnings.simplefilter('always'); import ridi;"
              "ridi.track(ridi.read(sys.argv[1]), ridi.bundled_model())")
    run = SAMPLE / "Jakob_Nexus5_NoDist_Texting"
    done = subprocess.run([sys.executable, "-c", script, str(run)], capture_output=True,
                          text=True, timeout=600, env={**os.environ, "RAYON_NUM_THREADS": value})
    assert done.returncode == 0, done.stderr
    if warning is None:
        assert "RAYON_NUM_THREADS" not in done.stderr, done.stderr
    else:
        assert f"UserWarning: {warning} (" in done.stderr, done.stderr
        assert done.stderr.count("RAYON_NUM_THREADS") == 1, done.stderr
