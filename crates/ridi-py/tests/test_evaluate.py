"""ridi.evaluate: the dict of `ridi eval`'s report.json, from list files or sequences, and its
options and refusals."""

import _thread
import json
import math
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import ridi
from conftest import ROOT, SAMPLE

RUNS = ["Thibaud_Nexus5_NoDist_Texting", "Thibaud_Nexus5_NoDist_FrontPocket"]

# Two runs keep these tests quick, and are too few for intervals: the report says so (tested
# once, below), every other test here leaves that warning aside.
pytestmark = pytest.mark.filterwarnings("ignore:.*too few for 95 % intervals:UserWarning")


@pytest.fixture()
def test_list(tmp_path):
    listed = tmp_path / "test.txt"
    listed.write_text("".join(f"{SAMPLE / r},{r.rsplit('_', 1)[1]}\n" for r in RUNS))
    return listed


def same(a, b):
    """Equal, NaN (None in JSON) included, floats to the last bit."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_evaluate_equals_report_json(model, model_file, ridi_bin, test_list, tmp_path):
    ridi_bin("eval", "--list", test_list, "--model", model_file, "--out", tmp_path / "out",
             "--placement-map", "tyrex4", "--plots", "none")
    expected = json.loads((tmp_path / "out" / "report.json").read_text())
    # The command line names the model's file; Python's model has none.
    assert expected["provenance"].pop("model_source") == str(model_file)
    expected["provenance"]["model_source"] = None
    report = ridi.evaluate(test_list, model, placement_map="tyrex4")
    assert same(report, expected), (report, expected)
    assert len(report["provenance"]["model_fingerprint"]) == 16
    assert report["provenance"]["placement_map"] == "tyrex4"
    assert report["methods"] == list(ridi.METHODS)
    assert [s["name"] for s in report["sequences"]] == RUNS


def test_evaluate_options_reach_the_cli_flags(model, model_file, ridi_bin, test_list, tmp_path):
    ridi_bin("eval", "--list", test_list, "--model", model_file, "--out", tmp_path / "out",
             "--placement-map", "tyrex4", "--plots", "none", "--methods", "ridi,pdr",
             "--align", "all", "--placement-window", "0", "--jobs", "1", "--regress-every", "25",
             "--lambda", "0.3", "--estimate-initial-velocity")
    expected = json.loads((tmp_path / "out" / "report.json").read_text())
    expected["provenance"]["model_source"] = None
    assert expected["provenance"]["placement_window_s"] is None
    assert expected["provenance"]["regress_every"] == 25
    correction = expected["provenance"]["correction"]
    assert (correction["lambda"], correction["initial_velocity"]) == (0.3, "estimate")
    report = ridi.evaluate([test_list], model, placement_map="tyrex4", methods=["ridi", "pdr"],
                           align="all", placement_window=0, jobs=1, regress_every=25,
                           lambda_=0.3, estimate_initial_velocity=True)
    assert same(report, expected)
    assert report["methods"] == ["ridi", "pdr"]
    # The tracking options change RIDI's trajectories, as they change `ridi.track`'s.
    default = ridi.evaluate([test_list], model, placement_map="tyrex4", methods=["ridi", "pdr"],
                            align="all", placement_window=0, jobs=1)
    assert default["provenance"]["correction"]["lambda"] == 0.1
    assert default["summary"]["ridi"]["ate_m"] != report["summary"]["ridi"]["ate_m"]
    assert default["summary"]["pdr"] == report["summary"]["pdr"]
    for bad, message in [(dict(regress_every=0), "regress_every"), (dict(lambda_=-1.0), "lambda_")]:
        with pytest.raises(ValueError, match=message):
            ridi.evaluate([test_list], model, placement_map="tyrex4", **bad)


def test_evaluate_sequences_equals_the_list(model, test_list):
    seqs = ridi.read_list(test_list, placement_map="tyrex4", purpose="evaluation")
    given = ridi.evaluate(seqs, model, methods=["ridi"])
    listed = ridi.evaluate(test_list, model, placement_map="tyrex4", methods=["ridi"])
    # The same but for the map, applied when the sequences were read, not by evaluate.
    assert (given["provenance"]["placement_map"], listed["provenance"]["placement_map"]) == (
        None, "tyrex4")
    given["provenance"]["placement_map"] = "tyrex4"
    assert same(given, listed)
    # The model's description names it as the report does.
    assert model.describe()["fingerprint"] == given["provenance"]["model_fingerprint"]


def test_bad_evaluations_are_refused(model, test_list, tmp_path):
    with pytest.raises(ValueError, match="unknown method"):
        ridi.evaluate(test_list, model, methods=["ridi", "magic"])
    with pytest.raises(ValueError, match="`methods` is empty"):
        ridi.evaluate(test_list, model, methods=[])
    with pytest.raises(ValueError, match=r"`methods` is 5; expected a list"):
        ridi.evaluate(test_list, model, methods=5)
    with pytest.raises(ValueError, match=r"`jobs` is -1; expected a whole number from 1"):
        ridi.evaluate(test_list, model, jobs=-1)
    with pytest.raises(ValueError, match=r"`align` is 'half'"):
        ridi.evaluate(test_list, model, align="half")
    with pytest.raises(ValueError, match=r"`align` is -1"):
        ridi.evaluate(test_list, model, align=-1.0)
    # A bool is no number of seconds (True would align on 1 s).
    for true in (True, np.True_, np.array(True)):
        with pytest.raises(TypeError, match=r"`align` must be a number of seconds or 'all'"):
            ridi.evaluate(test_list, model, align=true)
    twice = tmp_path / "twice.txt"
    twice.write_text(test_list.read_text() + f"{SAMPLE / RUNS[0]},Texting\n")
    with pytest.raises(ValueError, match=r"twice.txt:3"):
        ridi.evaluate(twice, model)
    no_truth = ridi.read(SAMPLE / RUNS[0])
    args = {k: getattr(no_truth, k) for k in ("time", "gyro", "acce", "gravity", "orientation")}
    with pytest.raises(ValueError, match="ground truth"):
        ridi.evaluate([ridi.Sequence(**args, name="bare")], model)
    # Sequences built without a name share the default one: errors and reports could not
    # tell them apart, in evaluation as in training.
    seqs = ridi.read_list(test_list, placement_map="tyrex4", purpose="evaluation")
    unnamed = [ridi.Sequence(s.time, s.gyro, s.acce, s.gravity, s.orientation,
                             placement=s.placement, ground_truth_position=s.ground_truth_position,
                             ground_truth_orientation=s.ground_truth_orientation)
               for s in seqs[:3]]
    with pytest.raises(ValueError, match=r"sequences 0 and 1 are both named `sequence`: give each "
                                         r"its own name \(`ridi.Sequence\(..., name=...\)`\)"):
        ridi.evaluate(unnamed, model)
    with pytest.raises(ValueError, match=r"sequences 0 and 1 are both named `sequence`"):
        ridi.train(unnamed, grid="none")
    # A renamed copy of a recording is the recording: the CLI's lists refuse it by content.
    copy = ridi.Sequence(seqs[0].time, seqs[0].gyro, seqs[0].acce, seqs[0].gravity,
                         seqs[0].orientation, name="renamed", placement=seqs[0].placement,
                         ground_truth_position=seqs[0].ground_truth_position,
                         ground_truth_orientation=seqs[0].ground_truth_orientation)
    given = [*seqs[:3], copy]
    for call in (lambda d: ridi.evaluate(d, model), lambda d: ridi.train(d, grid="none")):
        with pytest.raises(ValueError, match=rf"sequence `renamed`: is the same recording as "
                                             rf"sequence 0, `{seqs[0].name}`"):
            call(given)


def test_one_method_by_name_and_warnings_as_python_warnings(model, test_list):
    # Labels the model does not know (no placement map): the report says so, and so does Python.
    with pytest.warns(UserWarning, match=r"placement labels are not among the model's classes"):
        one = ridi.evaluate(test_list, model, methods="ridi")
    assert one["methods"] == ["ridi"] and one["warnings"]
    with pytest.warns(UserWarning):
        assert same(one, ridi.evaluate(test_list, model, methods=["ridi"]))


def test_a_weakly_determined_alignment_is_a_warning_in_the_report_and_in_python(seq, model):
    # Ground truth that never moves: the alignment's heading rests on no motion at all.
    still = ridi.Sequence(seq.time, seq.gyro, seq.acce, seq.gravity, seq.orientation,
                          name="still", placement="hand",
                          ground_truth_position=np.zeros((len(seq), 3)),
                          ground_truth_orientation=seq.orientation)
    with pytest.warns(UserWarning, match=r"weakly determined alignment in 1 of 1 sequence: .*still \(0.00 m\)"):
        report = ridi.evaluate([still], model, methods="ridi", placement_map="tyrex4")
    assert any(w.startswith("weakly determined alignment") for w in report["warnings"])


def test_the_python_demo_runs_as_its_docstring_says(tmp_path, ridi_bin):
    # examples/python_demo.py, as a user runs it: `ridi demo`'s table, line for line (intervals,
    # RIDI - PDR and each device's figures), each warning once (as a Python warning), exit 0.
    done = subprocess.run(
        [sys.executable, "-W", "always", str(ROOT / "examples" / "python_demo.py"), "--plot",
         str(tmp_path / "t.png")], capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr

    def table(text):
        """From the summary line to the last device's line; the CLI's pointer to report.md,
        which Python does not write, left out."""
        lines = text.splitlines()
        start = next(i for i, line in enumerate(lines) if "sequences; velocity MSE" in line)
        end = max(i for i, line in enumerate(lines) if line.startswith("  ") and "ridi " in line)
        return [line.replace("; every difference in report.md", "") for line in lines[start:end + 1]]

    demo = table(ridi_bin("demo", "--out", tmp_path / "demo"))
    assert "RTE 5 s per device (m):" in demo and any(" [95 %]" in line for line in demo)
    assert table(done.stdout) == demo
    for line in set(done.stderr.splitlines()):
        if "Warning" in line:
            assert done.stderr.count(line) == 1, done.stderr


@pytest.mark.filterwarnings("default")
def test_fewer_runs_than_an_interval_needs_give_means_alone(model, test_list):
    with pytest.warns(UserWarning, match=r"2 sequences \(2 runs, .*\): too few for 95 % "
                                         r"intervals, which need 5 runs"):
        report = ridi.evaluate(test_list, model, methods=["ridi", "pdr"], placement_map="tyrex4")
    # The means stay, without bounds.
    for table in (report["intervals"], report["ridi_minus"]):
        assert all(i["low"] is None and i["high"] is None
                   for m in table.values() for i in m.values()), table
    d = report["ridi_minus"]["pdr"]["rte_5s_m"]["mean"]
    rte = [s["methods"]["ridi"]["rte_5s_m"] - s["methods"]["pdr"]["rte_5s_m"]
           for s in report["sequences"]]
    assert d == pytest.approx(sum(rte) / len(rte), abs=1e-12)
    assert [s["run"] for s in report["sequences"]] == RUNS


def test_compare_pairs_two_evaluations_as_the_command_does(model, model_file, ridi_bin, tmp_path):
    # Five runs of the sample, evaluated twice: as is, and with each regression's own placement.
    runs = ["Thibaud_Nexus5_NoDist_Texting", "Thibaud_Nexus5_NoDist_FrontPocket",
            "Thibaud_Nexus5_NoDist_BackPocket", "Thibaud_Nexus5_NoDist_Swinging",
            "Thibaud_Nexus5_NoDist_Phoning"]
    listed = tmp_path / "five.txt"
    listed.write_text("".join(f"{SAMPLE / r},{r.rsplit('_', 1)[1]}\n" for r in runs))
    first = ridi.evaluate(listed, model, methods=["ridi", "pdr"], placement_map="tyrex4")
    second = ridi.evaluate(listed, model, methods=["ridi", "pdr"], placement_map="tyrex4",
                           placement_window=0)
    c = ridi.compare(first, second)
    assert c["settings"] == ["placement: 10 s against per regression"]
    third = ridi.evaluate(listed, model, methods=["ridi", "pdr"], placement_map="tyrex4",
                          lambda_=0.3)
    assert ridi.compare(first, third)["settings"] == ["correction lambda: 0.1 against 0.3"]
    # A report of an older ridi, without its correction: a warning says so.
    older = json.loads(json.dumps(first))
    del older["provenance"]["correction"]
    with pytest.warns(UserWarning, match=r"the first report does not record its correction"):
        assert ridi.compare(older, third)["settings"] == []
    assert (c["sequences"], c["runs"], c["warnings"]) == (5, 5, [])
    rte = {(f["method"], f["metric"]): f for f in c["figures"]}
    assert rte[("pdr", "rte_5s_m")]["difference"] == 0.0
    ridi_rte = rte[("ridi", "rte_5s_m")]
    assert ridi_rte["first"] == first["summary"]["ridi"]["rte_5s_m"]
    assert ridi_rte["second"] == second["summary"]["ridi"]["rte_5s_m"]
    assert ridi_rte["interval"]["low"] <= ridi_rte["difference"] <= ridi_rte["interval"]["high"]
    # The same from the command's files, the folder or its report.json.
    out = tmp_path / "eval"
    ridi_bin("eval", "--list", listed, "--model", model_file, "--out", out, "--methods",
             "ridi,pdr", "--placement-map", "tyrex4", "--plots", "none")
    with pytest.warns(UserWarning, match=r"the two reports are identical \(the same folder"):
        same_model = ridi.compare(out, out / "report.json")
    assert same_model["settings"] == [] and all(
        f["difference"] == 0.0 for f in same_model["figures"])
    # Read back to the last bit: each figure's mean is the report's own.
    saved = json.loads((out / "report.json").read_text())
    model_figures = {"velocity_mse_x": 0, "velocity_mse_z": 1, "placement_accuracy": None}
    for f in same_model["figures"]:
        if f["metric"] in model_figures:
            # The model's own figures, `ridi`'s: means of the sequences' values.
            assert f["method"] == "ridi"
            channel = model_figures[f["metric"]]
            values = [s["velocity_mse"][channel] if channel is not None
                      else s["placement_accuracy"] for s in saved["sequences"]]
            assert f["first"] == pytest.approx(sum(values) / len(values), rel=1e-12)
        else:
            assert f["first"] == saved["summary"][f["method"]][f["metric"]], f
    assert {f["metric"] for f in same_model["figures"]} >= set(model_figures)
    printed = ridi_bin("compare", out, out)
    assert "Nothing recorded differs between the two" in printed
    # The command's JSON is ridi.compare's on the same files.
    other = tmp_path / "eval-other"
    ridi_bin("eval", "--list", listed, "--model", model_file, "--out", other, "--methods",
             "ridi,pdr", "--placement-map", "tyrex4", "--plots", "none", "--placement-window", "0")
    assert same(json.loads(ridi_bin("compare", out, other, "--json")), ridi.compare(out, other))
    with pytest.raises(TypeError, match=r"`second` must be a report of `ridi.evaluate`"):
        ridi.compare(first, 5)
    with pytest.raises(ValueError, match=r"`first` is not a report of `ridi.evaluate`"):
        ridi.compare({"sequences": 3}, first)
    # A dict is checked as a report.json file is: a window that is not positive is refused.
    edited = json.loads((out / "report.json").read_text())
    edited["config"]["rte_window_s"] = -5.0
    with pytest.raises(ValueError, match=r"config.rte_window_s"):
        ridi.compare(edited, first)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_ctrl_c_stops_an_evaluation(model):
    # The evaluation runs on threads of its own while the main thread, where Python runs signal
    # handlers, waits for it: Ctrl-C stops it after the sequences under way, not at its end.
    seqs = ridi.read_list(SAMPLE / "list_all.txt", placement_map="tyrex4")
    start = time.perf_counter()
    ridi.evaluate(seqs, model, jobs=1)
    whole = time.perf_counter() - start
    handled = []

    def on_sigint(*_):
        handled.append(time.perf_counter())
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        with pytest.raises(KeyboardInterrupt):
            threading.Timer(0.02, _thread.interrupt_main).start()  # as Ctrl-C
            ridi.evaluate(seqs, model, jobs=1)
            time.sleep(10)  # where an evaluation that ignored the signal takes it
    finally:
        signal.signal(signal.SIGINT, previous)
    stopped = time.perf_counter() - handled[0]
    # One sequence at a time: after the handler ran, at most the one under way of 26.
    assert stopped < whole / 2, f"{stopped:.2f} s after Ctrl-C; a whole evaluation takes {whole:.2f} s"
