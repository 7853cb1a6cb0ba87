"""Python in the loop of an in-process run: a predictor written in Python equal to the
built-in one gives a byte-identical trace (both channels, with a lossy network and
deadband codecs, so the predictors fill thousands of samples); so does an operator
equal to the built-in circle; the operator is called once a sample in order with the
force felt at the sample before; a bad result or an exception stops the run and is
raised naming the callable and the sample, the report kept."""
import csv
import filecmp
import json
import math
import os
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import tactile

ROOT = Path(os.environ["TACTILE_ROOT"])
PAPER = ROOT / "deploy" / "scenarios" / "paper.toml"
WALL = ROOT / "deploy" / "scenarios" / "wall-delay.toml"
LOSSY = {"codec.forward.kind": "deadband", "codec.backward.kind": "deadband",
         "network.forward.loss": 0.05, "network.backward.loss": 0.05}


def hold(n, to, history):
    return history[-1, 1:]


def linear(n, to, history):
    """The built-in `linear`: on from the last two values accepted."""
    t1, x1 = history[-1, 0], history[-1, 1:]
    if len(history) < 2:
        return x1
    t0, x0 = history[-2, 0], history[-2, 1:]
    if not (to > t1 > t0):
        return x1
    return x1 + (to - t1) / (t1 - t0) * (x1 - x0)


@pytest.mark.parametrize("kind,guess", [("linear", linear), ("hold", hold)])
def test_a_predictor_in_python_equal_to_the_built_in_gives_the_same_trace(tmp_path, kind,
                                                                          guess):
    sc = tactile.Scenario.load(PAPER).with_set(
        {**LOSSY, "slave.predictor.kind": kind, "master.predictor.kind": kind})
    calls = {"backward": 0, "forward": 0}
    shapes = set()

    def counted(side):
        def f(n, to, history):
            calls[side] += 1
            shapes.add(history.shape[1])
            assert not history.flags.writeable and len(history) <= 64
            assert history[-1, 0] <= to
            return guess(n, to, history)
        return f

    tactile.run(sc, out=tmp_path / "built-in", trace_format="csv")
    tactile.run(sc, out=tmp_path / "python", trace_format="csv",
                backward_predictor=counted("backward"), forward_predictor=counted("forward"))
    assert filecmp.cmp(tmp_path / "built-in" / "trace.csv", tmp_path / "python" / "trace.csv",
                       shallow=False)
    assert calls["backward"] > 500 and calls["forward"] > 500, calls
    assert shapes == {4}
    # A predictor that guesses otherwise changes the run, on either side: the hooks
    # are in the loop.
    for side in ["forward_predictor", "backward_predictor"]:
        r = tactile.run(sc, out=tmp_path / side, trace_format="csv",
                        **{side: lambda n, to, h: np.zeros(3)})
        assert not filecmp.cmp(tmp_path / "built-in" / "trace.csv",
                               tmp_path / side / "trace.csv", shallow=False), side
        # The report says a hook stood in for the scenario's predictor.
        assert any("predictor was a hook" in e for e in r.summary["events"]), r.summary
    builtin = json.loads((tmp_path / "built-in" / "summary.json").read_text())
    assert not any("hook" in e for e in builtin["events"])


def circle_scenario(base):
    toml = base.to_toml()
    assert '[operator]\nkind = "paper"' in toml
    return tactile.Scenario.from_toml(toml.replace(
        '[operator]\nkind = "paper"',
        '[operator]\nkind = "circle"\ncenter = [0.0, 0.15, 0.05]\nradius = 0.03\nperiod_s = 2.0'))


def test_an_operator_in_python_equal_to_the_circle_gives_the_same_trace(tmp_path):
    base = tactile.Scenario.load(PAPER).with_set({"samples": 1500})

    def circle(n, t, felt):
        w = 2.0 * math.pi * t / 2.0
        return (0.0 + 0.03 * math.cos(w), 0.15 + 0.03 * math.sin(w), 0.05)

    tactile.run(circle_scenario(base), out=tmp_path / "built-in", trace_format="csv")
    tactile.run(base, out=tmp_path / "python", trace_format="csv", operator=circle)
    assert filecmp.cmp(tmp_path / "built-in" / "trace.csv", tmp_path / "python" / "trace.csv",
                       shallow=False)


def test_the_operator_is_called_each_sample_with_the_force_felt_before():
    sc = tactile.Scenario.load(WALL).with_set({"samples": 1500})
    seen = []

    def press(n, t, felt):
        seen.append((n, t, felt.copy()))
        return np.array([0.0, -0.11, -0.035 - 0.04 * min(t / 0.5, 1.0)])

    r = tactile.run(sc, operator=press)
    assert [s[0] for s in seen] == list(range(1500))
    assert all(t == n * 0.001 for n, t, _ in seen)
    felt = np.column_stack([r.trace.column(f"felt_{i}").to_numpy() for i in (1, 2, 3)])
    got = np.array([s[2] for s in seen])
    assert (got[0] == 0).all()
    np.testing.assert_array_equal(got[1:], felt[:-1])
    assert np.abs(felt).max() > 1.0, "the wall was never felt"


def test_a_bad_result_or_an_exception_stops_the_run_naming_the_sample(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 1000})
    here = (0.0, 0.15, 0.05)
    cases = [
        ("nan", lambda n, t, f: (math.nan, 0.0, 0.0) if n == 300 else here,
         r"operator at sample 300: gave \[nan, 0.0, 0.0\], not finite"),
        ("shape", lambda n, t, f: (1.0, 2.0) if n == 40 else here,
         r"operator at sample 40: gave an array of shape \(2,\)"),
        ("text", lambda n, t, f: "up" if n == 7 else here, "operator at sample 7: gave 'up'"),
        # Only real numbers: what float() or NumPy would turn into one is refused.
        ("texts", lambda n, t, f: ("0", "0.15", "0.05") if n == 9 else here,
         r"operator at sample 9: gave \('0', '0.15', '0.05'\), not three real numbers \(text\)"),
        ("complex", lambda n, t, f: np.array(here) + 0j if n == 10 else here,
         r"operator at sample 10: .*not three real numbers \(complex numbers\)"),
        ("masked", lambda n, t, f: np.ma.array(here, mask=[0, 1, 0]) if n == 11 else here,
         r"operator at sample 11: .*a masked array: its mask would be dropped"),
        ("bools", lambda n, t, f: (True, False, True) if n == 13 else here,
         r"operator at sample 13: .*\(booleans\)"),
        ("array of text", lambda n, t, f: np.array(["0", "1", "2"]) if n == 14 else here,
         r"operator at sample 14: .*\(text\)"),
        # Last: the cause checked below is its.
        ("raises", lambda n, t, f: 1 / (n - 12) and here,
         "operator at sample 12: ZeroDivisionError"),
    ]
    for name, op, said in cases:
        out = tmp_path / name
        with pytest.raises(tactile.CallbackError, match=said) as e:
            tactile.run(sc, out=out, operator=op)
        summary = json.loads((out / "summary.json").read_text())
        assert summary["interrupted"] is True
        stopped_at = int(said.split("sample ")[1].split(":")[0])
        assert stopped_at < summary["samples_sent"] <= stopped_at + 3, summary["samples_sent"]
    assert isinstance(e.value.__cause__, ZeroDivisionError)
    lossy = tactile.Scenario.load(PAPER).with_set(LOSSY)
    with pytest.raises(tactile.CallbackError, match=r"forward predictor at sample \d+: gave"):
        tactile.run(lossy, forward_predictor=lambda n, to, h: [math.inf] * 3)
    # The next run runs whole: the stop the callable asked for is not left behind.
    assert tactile.run(sc, operator=lambda n, t, f: here).completed


def test_every_kind_of_real_number_is_taken():
    """The quick path's tuples and float arrays, and what NumPy reads as real
    numbers (a float32 array, NumPy scalars, fractions), all run."""
    from fractions import Fraction
    here = (0.0, 0.15, 0.05)
    forms = [here, list(here), np.array(here), np.array(here, dtype=np.float32),
             (np.float64(0.0), np.float32(0.15), 0.05), (0, 0.15, 0.05),
             (Fraction(0), 0.15, 0.05), np.array([0, 0, 0], dtype=np.int64) + 0.05]
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 80})
    assert tactile.run(sc, operator=lambda n, t, f: forms[n % len(forms)]).completed


def test_what_cannot_take_a_callable_is_refused(tmp_path):
    sc = tactile.Scenario.load(PAPER)
    with pytest.raises(tactile.ScenarioError, match="operator: give a function"):
        tactile.run(sc, operator=[0.0, 0.1, 0.0])
    pose = tactile.Scenario.load(ROOT / "deploy" / "scenarios" / "panda-pose.toml")
    with pytest.raises(tactile.ScenarioError, match="a scripted operator gives positions"):
        tactile.run(pose, out=tmp_path / "pose", operator=lambda n, t, f: (0.0, 0.0, 0.0))
    # Refused before anything is made.
    assert not (tmp_path / "pose").exists()


def test_a_failing_callable_stops_its_own_run_only(tmp_path):
    """The stop a callable's error asks for is its run's: a run in another thread
    goes on to its end, and an error at the last sample still marks the run
    interrupted with its whole report."""
    import threading
    long = tactile.Scenario.paper().with_set({"samples": 30_000})
    other = {}

    def beside():
        other["run"] = tactile.run(long, trace_format=None)

    t = threading.Thread(target=beside)
    t.start()
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 400})
    here = (0.0, 0.15, 0.05)
    with pytest.raises(tactile.CallbackError, match="operator at sample 399"):
        tactile.run(sc, out=tmp_path / "last", operator=lambda n, t, f: None if n == 399 else here)
    t.join()
    assert other["run"].completed and other["run"].summary["samples_sent"] == 30_000
    summary = json.loads((tmp_path / "last" / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["samples_sent"] == 400



@pytest.mark.parametrize("how", ["sleep", "recv", "spin"])
def test_ctrl_c_reaches_a_callable_that_blocks(tmp_path, child, how):
    """A Ctrl-C while the operator sleeps, waits on a socket or loops in Python is
    raised inside it at once (the loop runs on the caller's thread, where Python runs
    its signal handlers), and the run stops after that sample with its report. The
    child is the one deploy/python/bench/ctrl_c.py times."""
    import signal
    import time
    out = tmp_path / how
    # Not heard, the callable would block for a minute: killed sooner, so the test
    # fails rather than waits.
    p = child(str(ROOT / "deploy" / "python" / "bench" / "ctrl_c.py"), "child", out, how,
              seconds=30)
    assert p.stdout.readline().strip() == "blocking", p.stderr.read()
    time.sleep(0.2)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    said = p.stdout.readline().strip()
    took = time.monotonic() - sent
    assert said == "KeyboardInterrupt in operator", (said, p.stderr.read())
    # About 50 ms here (the interrupted report is written within 0.7 s); a loaded
    # machine gets some slack.
    assert took < 5, took
    assert p.wait(timeout=30) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True and 200 < summary["samples_sent"] <= 203, summary
    assert not any("hook" in e and "failed" in e for e in summary["events"]), summary["events"]


def test_a_guess_a_received_force_would_be_refused_for_is_refused(tmp_path):
    """A backward predictor guessing 1e300 N (finite, so the callable's check takes it)
    had it rendered at the device's full force at every guessed sample, where the same
    value received was refused: now each such guess is refused and the last value
    held, so the felt force is the built-in `hold` predictor's to the bit; the sample
    is flagged GUESS_REFUSED (65536) and the summary warns with the count."""
    sc = tactile.Scenario.load(PAPER).with_set(
        {"network.backward.loss": 0.2, "master.predictor.kind": "hold"})
    held = tactile.run(sc, out=tmp_path / "held", trace_format="csv")
    run = tactile.run(sc, out=tmp_path / "huge", trace_format="csv",
                      backward_predictor=lambda n, to, history: (0.0, 0.0, 1e300))
    rows = {d: list(csv.DictReader(open(tmp_path / d / "trace.csv"))) for d in ["held", "huge"]}
    refused = sum(1 for r in rows["huge"] if int(r["flags_m"]) & 65536)
    assert refused > 100, refused
    for axis in ["felt_1", "felt_2", "felt_3"]:
        assert [r[axis] for r in rows["huge"]] == [r[axis] for r in rows["held"]], axis
    warnings = " ".join(run.summary["warnings"])
    assert f"master: {refused} guesses of its predictor" in warnings, warnings
    assert not held.summary["warnings"], held.summary["warnings"]
