"""tactile.sweep against the command's sweep: the wall-delay study of docs/05 equals
deploy/results/wall-delay/sweep.csv, the table's columns and types, the sets a
Scenario carries, bad input before any run, progress, and a progress callback's
exception stopping the sweep with the runs that ended kept."""
import os
import subprocess
from pathlib import Path

import pandas
import pytest

import tactile

ROOT = Path(os.environ["TACTILE_ROOT"])
WALL = ROOT / "deploy" / "scenarios" / "wall-delay.toml"
PAPER = ROOT / "deploy" / "scenarios" / "paper.toml"
DELAYS_MS = [0, 10, 50, 100, 200]
KINDS = ["none", "tdpa", "wave", "mmt"]


def test_the_wall_delay_sweep_equals_the_commands_table(tmp_path):
    sc = tactile.Scenario.load(WALL)
    df = tactile.sweep(sc, {"network.forward.delay_ms": DELAYS_MS, "control.kind": KINDS,
                            "network.backward.delay_ms": [0]}, out=tmp_path / "s",
                       progress=False)
    ref = pandas.read_csv(ROOT / "deploy" / "results" / "wall-delay" / "sweep.csv")
    assert len(df) == len(ref) == 20
    metrics = list(ref.columns[ref.columns.get_loc("seed"):])
    pandas.testing.assert_frame_equal(df[metrics], ref[metrics], check_exact=True)
    assert list(df["network.forward.delay_ms"]) == [d for d in DELAYS_MS for _ in KINDS]
    assert list(df["control.kind"]) == KINDS * len(DELAYS_MS)
    assert list(df["run"]) == list(ref["run"])
    assert df["folder"].map(lambda f: (Path(f) / "summary.json").is_file()).all()


def test_columns_are_the_same_whatever_the_seeds_and_keep_python_types(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 200})
    grid = {"network.forward.delay": [[0, 0, 0], [5, 5, 5]], "control.kind": ["none", "tdpa"]}
    one = tactile.sweep(sc, grid, out=tmp_path / "one", progress=False)
    two = tactile.sweep(sc, grid, seeds=2, jobs=1, out=tmp_path / "two", progress=False)
    assert list(one.columns) == list(two.columns)
    assert list(one.columns[:5]) == ["run", "combination", "network.forward.delay",
                                     "control.kind", "seed"]
    assert one.columns[-1] == "folder"
    assert len(one) == 4 and len(two) == 8
    assert two["network.forward.delay"].iloc[-1] == [5, 5, 5]
    assert isinstance(two["control.kind"].iloc[0], str)
    first = int(one["seed"].iloc[0])
    assert sorted(set(two["seed"])) == [first, first + 1]
    # The Scenario's own sets are every run's: 200 samples each.
    assert (one["samples_sent"] == 200).all() and (two["samples_sent"] == 200).all()
    # The long table is sweep.csv, and sweep-summary.csv holds the means.
    assert (tmp_path / "two" / "sweep-summary.csv").is_file()


def test_a_swept_key_replaces_the_scenarios_set_of_it(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 999})
    df = tactile.sweep(sc, {"samples": [100, 150]}, progress=False)
    assert list(df["samples_sent"]) == [100, 150]
    assert df["folder"].isna().all()
    # Its twin in the other unit too; NumPy arrays are lists of values.
    import numpy as np
    sc = sc.with_set({"samples": 100, "network.forward.delay_ms": 70})
    df = tactile.sweep(sc, {" network.forward.delay ": np.array([[2, 2, 2], [4, 4, 4]])},
                       progress=False, trace_format=None)
    assert list(df["network.forward.delay"]) == [[2, 2, 2], [4, 4, 4]]
    # In process a round trip is the delay to the nanosecond, and its p50 says so (the
    # histogram's bucket read 20,004,863 ns).
    assert list(df["round_trip_p50_ns"]) == [20_000_000, 40_000_000]


def test_bad_input_runs_nothing(tmp_path):
    sc = tactile.Scenario.load(PAPER)
    out = tmp_path / "bad"
    cases = [({"control.kind": ["none", "nope"]}, "unknown variant `nope`"),
             ({"control.kind": "tdpa"}, "control.kind: give its values as a non-empty list"),
             ({"control.kind": []}, "non-empty list"),
             ({}, "give the swept keys"),
             ({"no.such": [1]}, "unknown field `no`")]
    for grid, said in cases:
        with pytest.raises(tactile.ScenarioError, match=said.replace("`", ".")):
            tactile.sweep(sc, grid, out=out, progress=False)
        assert not (out / "run-0000").exists()
    with pytest.raises(tactile.ScenarioError, match="--seeds 0"):
        tactile.sweep(sc, {"samples": [10]}, seeds=0, out=out, progress=False)
    with pytest.raises(tactile.ScenarioError, match="seeds=-1"):
        tactile.sweep(sc, {"samples": [10]}, seeds=-1, out=out, progress=False)
    # The command says the same of the same value.
    c = subprocess.run([os.environ["TACTILE_BIN"], "sweep", str(PAPER), "--set",
                        "control.kind=none,nope", "--out", str(out)],
                       capture_output=True, text=True)
    assert c.returncode == 2 and "unknown variant `nope`" in c.stderr, c.stderr


def test_progress_is_told_and_an_exception_there_stops_the_sweep(tmp_path, capsys):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    seen = []
    tactile.sweep(sc, {"samples": [100, 110, 120]}, jobs=1, out=tmp_path / "a",
                  progress=lambda ended, total, run, what: seen.append((ended, total, run, what)))
    assert [s[:3] for s in seen] == [(1, 3, "run-0000"), (2, 3, "run-0001"), (3, 3, "run-0002")]
    assert seen[0][3] == "samples=100"

    class Enough(Exception):
        pass

    def stop(ended, total, run, what):
        raise Enough(run)

    # The runs after the first are long: the stop reaches the second while it runs.
    with pytest.raises(Enough, match="run-0000"):
        tactile.sweep(sc, {"samples": [100, 200_000, 200_001]}, jobs=1, out=tmp_path / "b",
                      progress=stop)
    rows = pandas.read_csv(tmp_path / "b" / "sweep.csv")
    assert list(rows["run"]) == ["run-0000"]
    # Without tqdm, the command's line on standard error; with it, a bar there.
    tactile.sweep(sc, {"samples": [100]}, out=tmp_path / "c")
    err = capsys.readouterr().err
    assert "1/1" in err, err


# Python's own SIGINT handler first, whatever the parent ignored (see test_api.py).
INTERRUPTED = """
import signal, sys, tactile
signal.signal(signal.SIGINT, signal.default_int_handler)
sc = tactile.Scenario.paper().with_set({"samples": 5000})
def told(ended, total, run, what):
    print("ended", run, flush=True)
try:
    tactile.sweep(sc, {"seed": list(range(1, 60))}, jobs=1, out=sys.argv[1], progress=told)
except KeyboardInterrupt:
    print("KeyboardInterrupt", flush=True)
"""


def test_ctrl_c_stops_a_sweep_keeping_the_runs_that_ended(tmp_path, child):
    """SIGINT to the interpreter stops a sweep as it stops the command: the run in
    hand ends early, the tables of the runs that ended are written, then
    KeyboardInterrupt; resume=True runs the rest."""
    import signal
    out = tmp_path / "stopped"
    # 59 runs that did not stop would take minutes: killed sooner.
    p = child(INTERRUPTED, out)
    assert p.stdout.readline().strip() == "ended run-0000", p.stderr.read()
    p.send_signal(signal.SIGINT)
    lines = [line.strip() for line in p.stdout]
    p.wait(timeout=60)
    assert lines and lines[-1] == "KeyboardInterrupt", (lines, p.stderr.read())
    rows = list(pandas.read_csv(out / "sweep.csv")["run"])
    ended = ["run-0000"] + [line.split()[1] for line in lines[:-1]]
    # Every run told ended is in the table, in order; a run that ended while the
    # interrupt was on its way is too, untold (its progress is not called after it).
    assert rows[:len(ended)] == ended and len(ended) <= len(rows) <= len(ended) + 1, rows
    assert len(rows) < 59
    assert "stopped by a signal" in p.stderr.read()
    # The rest, resumed: every run, the ones kept from before unchanged.
    sc = tactile.Scenario.paper().with_set({"samples": 5000})
    df = tactile.sweep(sc, {"seed": list(range(1, 60))}, out=out, resume=True, progress=False)
    assert len(df) == 59 and list(df["seed"]) == list(range(1, 60))
    assert (df["samples_sent"] == 5000).all()


def cli_sweep(scenario, out, *sets, extra=()):
    args = [os.environ["TACTILE_BIN"], "sweep", str(scenario), "-q", "--out", str(out)]
    for s in sets:
        args += ["--set", s]
    return subprocess.run(args + list(extra), capture_output=True, text=True)


def test_swept_numbers_are_numeric_columns(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    df = tactile.sweep(sc, {"network.forward.delay_ms": [0, 10],
                            "network.forward.loss": [0, 0.5],
                            "control.kind": ["none"],
                            "network.backward.delay": [[0, 0, 0]]},
                       out=tmp_path / "s", progress=False)
    types = df.dtypes.map(str).to_dict()
    assert types["network.forward.delay_ms"] == "int64", types
    # A whole number beside a float is a float, as in any numeric column.
    assert types["network.forward.loss"] == "float64", types
    assert types["combination"] == types["seed"] == "int64", types
    assert types["samples_sent"] == "int64" and types["tracking_rms_m"] == "float64", types
    assert df["network.forward.loss"].tolist() == [0.0, 0.5, 0.0, 0.5]
    assert isinstance(df["control.kind"].iloc[0], str)
    assert df["network.backward.delay"].iloc[0] == [0, 0, 0]
    # Numbers group and plot as numbers.
    assert df.groupby("network.forward.delay_ms")["round_trip_p50_ns"].max().index.tolist() == [0, 10]


def test_read_sweep_reads_back_either_front_ends_sweep(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    grid = {"network.forward.delay_ms": [0, 10], "control.kind": ["none", "tdpa"]}
    df = tactile.sweep(sc, grid, out=tmp_path / "py", progress=False)
    pandas.testing.assert_frame_equal(tactile.read_sweep(tmp_path / "py"), df)
    c = cli_sweep(PAPER, tmp_path / "cli", "network.forward.delay_ms=0,10",
                  "control.kind=none,tdpa", extra=["--set", "samples=100"])
    # (The command's grid has samples as a third key: one value.)
    assert c.returncode == 0, c.stderr
    theirs = tactile.read_sweep(tmp_path / "cli")
    assert list(theirs["control.kind"]) == list(df["control.kind"])
    assert theirs["network.forward.delay_ms"].dtype == "int64"
    metrics = list(df.columns[df.columns.get_loc("seed"):-1])
    pandas.testing.assert_frame_equal(theirs[metrics], df[metrics])
    with pytest.raises(tactile.RunError, match="no sweep to read"):
        tactile.read_sweep(tmp_path)


def test_a_sweep_resumes_across_front_ends(tmp_path):
    """The command's sweep and the same sweep from Python are one sweep, however each
    writes its values (tdpa or "tdpa", 1 or 1.0): either resumes the other's."""
    grid = {"network.forward.delay_ms": [0, 1.0], "control.kind": ["none", "tdpa"]}
    sets = ["network.forward.delay_ms=0,1", "control.kind=none,tdpa"]
    small = tmp_path / "small.toml"
    small.write_text(WALL.read_text().replace("samples = 8000", "samples = 300"))
    assert "samples = 300" in small.read_text()
    sc = tactile.Scenario.load(small)
    # The command runs half the grid; Python runs the rest, keeping that half.
    c = cli_sweep(small, tmp_path / "a", *sets, extra=["--shard", "1/2"])
    assert c.returncode == 0, c.stderr
    seen = []
    df = tactile.sweep(sc, grid, out=tmp_path / "a", resume=True,
                       progress=lambda *a: seen.append(a[2]))
    assert sorted(seen) == ["run-0001", "run-0003"], seen
    assert len(df) == 4
    # Python runs the whole grid; the command resumes it, keeping every run.
    tactile.sweep(sc, grid, out=tmp_path / "b", progress=False)
    (tmp_path / "b" / "run-0002" / "summary.json").unlink()
    c = cli_sweep(small, tmp_path / "b", *sets, extra=["--resume"])
    assert c.returncode == 0 and "3 runs kept from before" in c.stderr, c.stderr
    # The same rows; the keys' values as the command wrote them last (1, not 1.0).
    pandas.testing.assert_frame_equal(tactile.read_sweep(tmp_path / "b").drop(columns="folder"),
                                      df.drop(columns="folder"), check_dtype=False)


def test_paired_keys_move_together(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    pair = ("network.forward.delay_ms", "network.backward.delay_ms")
    df = tactile.sweep(sc, {pair: [(0, 0), (10, 10)], "control.kind": ["none", "tdpa"]},
                       out=tmp_path / "py", progress=False)
    assert len(df) == 4
    assert list(df["network.forward.delay_ms"]) == [0, 0, 10, 10]
    assert list(df["network.backward.delay_ms"]) == [0, 0, 10, 10]
    assert [round(x / 1e6) for x in df["round_trip_p50_ns"]] == [0, 0, 20, 20]
    # The command's paired key: the same sweep.
    c = cli_sweep(PAPER, tmp_path / "cli", "network.forward.delay_ms=0,10",
                  "+network.backward.delay_ms=0,10", "control.kind=none,tdpa",
                  extra=["--set", "samples=100"])
    assert c.returncode == 0, c.stderr
    cli = tactile.read_sweep(tmp_path / "cli")
    pandas.testing.assert_frame_equal(cli.drop(columns=["folder", "samples"]),
                                      df.drop(columns="folder"))
    for grid, said in [({pair: [(0, 0), 5]}, "each value is a tuple of 2"),
                       ({("samples",): [(10,)]}, "paired keys are two or more")]:
        with pytest.raises(tactile.ScenarioError, match=said):
            tactile.sweep(sc, grid, out=tmp_path / "bad", progress=False)
    c = cli_sweep(PAPER, tmp_path / "bad", "+network.backward.delay_ms=0,5")
    assert c.returncode == 2 and "there is none" in c.stderr, c.stderr
    c = cli_sweep(PAPER, tmp_path / "bad", "network.forward.delay_ms=0,5",
                  "+network.backward.delay_ms=0")
    assert c.returncode == 2 and "a paired key takes one value for each" in c.stderr, c.stderr


def test_a_value_given_twice_is_refused(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    out = tmp_path / "d"
    for grid, said in [({"control.kind": ["tdpa", "tdpa"]}, "value 1 and value 2 are one value"),
                       ({"network.forward.delay_ms": [10, 10.0]}, "are one value"),
                       # Both one sample at the paper's 100 Hz: one scenario.
                       ({"network.forward.delay_ms": [10, 10.0000001]},
                        "run-0000 .* and run-0001 .* would run the same scenario")]:
        with pytest.raises(tactile.ScenarioError, match=said):
            tactile.sweep(sc, grid, out=out, progress=False)
        assert not (out / "run-0000").exists()
    for s in ["control.kind=tdpa,tdpa", "network.forward.delay_ms=10,10.0000001"]:
        c = cli_sweep(PAPER, out, s)
        assert c.returncode == 2 and ("one value" in c.stderr or "same scenario" in c.stderr), c.stderr


def test_seeds_that_change_nothing_have_no_interval(tmp_path):
    """The wall scenario has nothing random: every seed gives the same values, whose
    interval is 0, not a rounding error."""
    sc = tactile.Scenario.load(WALL).with_set({"samples": 300})
    tactile.sweep(sc, {"control.kind": ["none", "tdpa"]}, seeds=3, out=tmp_path / "s",
                  progress=False)
    summary = pandas.read_csv(tmp_path / "s" / "sweep-summary.csv")
    ci = summary[[c for c in summary.columns if c.endswith("_ci95")]]
    assert ((ci == 0) | ci.isna()).all().all(), ci.T[(ci != 0).any()]
    assert (ci == 0).sum().sum() > 20


def test_a_run_without_its_trace_says_how_to_get_it(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 100})
    df = tactile.sweep(sc, {"control.kind": ["none"]}, out=tmp_path / "s", progress=False)
    r = tactile.Run.read(df["folder"][0])
    with pytest.warns(tactile.NoTraceWarning, match=r"tactile\.report\(") as said:
        assert r.trace is None
    # What it says works.
    again = tactile.report(df["folder"][0], out=tmp_path / "again")
    assert again.trace.num_rows == 100
    assert "trace=True" in str(said[0].message)
    mem = tactile.run(sc, trace_format=None)
    with pytest.warns(tactile.NoTraceWarning, match="trace_format='parquet'"):
        assert mem.trace is None


def test_a_task_scene_runs_and_sweeps_with_its_task(tmp_path):
    """A physics scene's task (docs/16) from Python: the run's summary says it
    succeeded and when; a sweep's table has the task's columns, the command's."""
    sc = tactile.Scenario.shipped("push-box")
    r = tactile.run(sc, trace_format=None)
    assert r.summary["task"]["success"] is True
    assert 4.0 < r.summary["task"]["completion_s"] < 6.0
    df = tactile.sweep(sc, {"control.kind": ["none", "wave"]}, out=tmp_path / "s",
                       progress=False)
    assert list(df["task_success"]) == [1, 1]
    assert (df["task_completion_s"] > 4.0).all()
    assert (df["task_peak_force_n"] > 0.5).all()
    # A sweep without a task has no task columns, as the command's.
    wall = tactile.sweep(tactile.Scenario.load(WALL), {"control.kind": ["none"]},
                         out=tmp_path / "w", progress=False)
    assert not [c for c in wall.columns if c.startswith("task_")]
