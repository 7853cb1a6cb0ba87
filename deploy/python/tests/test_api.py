"""The Python package against the command (api.rs runs pytest here with the built
module on PYTHONPATH, TACTILE_BIN and TACTILE_ROOT set): the same errors, the same
summary and trace, the GIL released while a run computes, Ctrl-C."""
import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq

import tactile

import pytest

ROOT = Path(os.environ["TACTILE_ROOT"])
paper = ROOT / "deploy" / "scenarios" / "paper.toml"
panda = ROOT / "deploy" / "scenarios" / "panda.toml"


def cli(*args):
    return subprocess.run([os.environ["TACTILE_BIN"], *args], capture_output=True, text=True)


@pytest.fixture
def work(tmp_path):
    return tmp_path


def test_bad_input_is_the_commands_error(work):
    sc = tactile.Scenario.load(paper)
    for key, value, text, names in [
            ("samples", -3, "-3", "samples=-3"),
            ("control.kind", "nope", '"nope"', "unknown variant `nope`"),
            ("network.forward.delay_ms", [1, 2], "[1,2]", "field `network.forward.delay_ms`"),
            ("no.such", 1, "1", "unknown field `no`")]:
        try:
            sc.with_set({key: value}).check()
        except tactile.ScenarioError as e:
            said = str(e)
        else:
            raise AssertionError(f"{key}={value} passed")
        c = cli("check", str(paper), "--set", f"{key}={text}")
        assert c.returncode == 2, (key, c.returncode, c.stderr)
        assert said in c.stderr and names in said, (said, c.stderr)
    try:
        sc.with_set({"samples": float("nan")})
    except tactile.ScenarioError as e:
        assert "samples" in str(e), e
    else:
        raise AssertionError("a NaN passed")
    missing = work / "missing.toml"
    try:
        tactile.Scenario.load(missing)
    except tactile.ScenarioError as e:
        c = cli("check", str(missing))
        assert c.returncode == 2 and str(e) in c.stderr, (str(e), c.stderr)
    else:
        raise AssertionError("a missing file passed")
    # A string outside the BMP is one TOML character (JSON's escapes would split it).
    named = sc.with_set({"name": "wall \U0001F600"}).to_toml()
    assert 'name = "wall \U0001F600"' in named, named


def test_sets_are_the_commands():
    sc = tactile.Scenario.load(paper).with_set(
        {"samples": 300, "control.kind": "tdpa", "network.forward.delay_ms": 50,
         "network.forward.noise_std": [0.0, 0.0, 0.0]})
    c = cli("check", str(paper), "--set", "samples=300", "--set", "control.kind=tdpa",
            "--set", "network.forward.delay_ms=50",
            "--set", "network.forward.noise_std=[0.0,0.0,0.0]")
    assert c.returncode == 0, c.stderr
    assert sc.to_toml() == c.stdout, (sc.to_toml(), c.stdout)
    notes = sc.check()
    assert any("50 ms" in n for n in notes), notes


def test_a_run_is_the_commands_run(work):
    sc = tactile.Scenario.load(paper).with_set({"samples": 400, "control.kind": "tdpa"})
    r = tactile.run(sc, out=work / "py")
    c = cli("run", str(paper), "--in-process", "-q", "--set", "samples=400",
            "--set", "control.kind=tdpa", "--trace-format", "both", "--out", str(work / "cli"))
    assert c.returncode == 0, c.stderr
    assert r.completed and r.out == work / "py"
    assert r.summary == json.loads((work / "py" / "summary.json").read_text())
    theirs = pq.read_table(work / "cli" / "trace.parquet")
    assert r.trace.num_rows == 400 and r.trace.column_names == theirs.column_names
    timing = r.trace.column_names.index("round_trip_ns")
    signals = r.trace.column_names[:timing]
    assert r.trace.select(signals).equals(theirs.select(signals)), "signal columns differ"
    cli_summary = json.loads((work / "cli" / "summary.json").read_text())
    for k in ["samples_sent", "samples_received", "tracking_rms_m", "tracking", "contact"]:
        assert r.summary[k] == cli_summary[k], (k, r.summary[k], cli_summary[k])
    assert r.joints is None
    again = tactile.report(work / "py", out=work / "again")
    assert again.trace.select(signals).equals(r.trace.select(signals))
    assert again.summary["tracking"] == r.summary["tracking"]
    # Without out, beside the master's record, as the command.
    assert tactile.report(work / "py").out == work / "py"


def test_in_memory_and_an_arm():
    sc = tactile.Scenario.load(panda).with_set({"samples": 300})
    r = tactile.run(sc)
    assert r.out is None and r.completed
    assert r.trace.num_rows == 300
    assert r.joints is not None and r.joints.num_rows == 300
    assert "q_1" in r.joints.column_names and r.summary["task_space"] is not None


def test_a_physics_runs_bodies():
    """push-box: the box's pose every sample beside the tool's, in memory; an
    analytic run has none."""
    sc = tactile.Scenario.load(ROOT / "deploy" / "scenarios" / "push-box.toml")
    r = tactile.run(sc)
    b = r.bodies
    assert b is not None and b.column_names == ["sample", "body", "x", "y", "z",
                                                "qx", "qy", "qz", "qw"]
    df = b.to_pandas()
    assert sorted(df["body"].unique()) == ["box", "tool"]
    box = df[df["body"] == "box"]
    assert len(box) == 7000 and list(box["sample"]) == list(range(7000))
    # Pushed 8 cm along x, to within 1 cm of its target at x = 5 cm.
    assert abs(box["x"].iloc[0]) < 1e-3 and abs(box["x"].iloc[-1] - 0.05) < 0.01
    assert r.summary["task"]["success"]
    assert tactile.run(tactile.Scenario.paper().with_set({"samples": 100})).bodies is None


def test_no_trace_is_the_commands_no_trace(work):
    sc = tactile.Scenario.paper().with_set({"samples": 200})
    r = tactile.run(sc, out=work / "bare", trace_format=None)
    with pytest.warns(tactile.NoTraceWarning):
        assert r.trace is None and r.summary["samples_sent"] == 200
    assert not any((work / "bare" / f).exists() for f in ["trace.parquet", "trace.csv", "run.mcap"])
    with pytest.raises(tactile.ScenarioError, match="trace_format"):
        tactile.run(sc, trace_format="xlsx")


def test_the_gil_is_released_while_it_runs():
    sc = tactile.Scenario.paper().with_set({"samples": 40_000})
    done, failed = threading.Event(), []

    def work():
        try:
            tactile.run(sc)
        except BaseException as e:  # noqa: BLE001 - reported below
            failed.append(e)
        finally:
            done.set()

    t = threading.Thread(target=work)
    start = last = time.monotonic()
    t.start()
    gap = 0.0
    while not done.is_set():
        time.sleep(0.001)
        now = time.monotonic()
        gap, last = max(gap, now - last), now
    t.join()
    took = time.monotonic() - start
    assert not failed, failed
    # Held, the GIL would stop this loop for the whole run: its longest pause would be
    # the run's length.
    assert took > 0.3 and gap < took / 4, (took, gap)


# The child installs Python's own SIGINT handler first: an interpreter started with
# SIGINT ignored (a background job of a non-interactive shell, as CI may start the
# suite) keeps it ignored, and the run would never hear the Ctrl-C.
INTERRUPTED = """
import signal, sys, time, tactile
signal.signal(signal.SIGINT, signal.default_int_handler)
sc = tactile.Scenario.paper().with_set({"samples": 100_000_000})
for k in range(2):
    print("running", k, flush=True)
    try:
        tactile.run(sc, out=f"{sys.argv[1]}-{k}")
    except KeyboardInterrupt as e:
        print("KeyboardInterrupt", k, flush=True)
    # What a notebook's kernel does around every cell: Python's handler again.
    signal.signal(signal.SIGINT, signal.default_int_handler)
r = tactile.run(tactile.Scenario.paper().with_set({"samples": 50}))
print("then", r.completed, r.summary["samples_sent"], flush=True)
time.sleep(60)
"""


def test_ctrl_c_stops_a_run_keeps_its_report_and_the_next_runs(work, child):
    """SIGINT (a terminal's Ctrl-C, a notebook's interrupt) ends a run as it ends the
    command: KeyboardInterrupt, the report of what ran written and marked; again after
    Python's handler is installed anew (as a notebook's kernel does); the next run
    runs whole, and a SIGTERM still ends the interpreter."""
    out = work / "stopped"
    p = child(INTERRUPTED, out)
    for k in range(2):
        assert p.stdout.readline().strip() == f"running {k}"
        rec = Path(f"{out}-{k}") / "master.rec"
        # The master's record growing is the run going.
        while not rec.exists() or rec.stat().st_size == 0:
            assert p.poll() is None, p.stderr.read()
            time.sleep(0.01)
        p.send_signal(signal.SIGINT)
        assert p.stdout.readline().strip() == f"KeyboardInterrupt {k}"
        s = json.loads((Path(f"{out}-{k}") / "summary.json").read_text())
        assert s["interrupted"] is True, s
        assert 0 < s["samples_sent"] < 100_000_000, s["samples_sent"]
    assert p.stdout.readline().strip() == "then True 50"
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=60)
    assert p.returncode == -signal.SIGTERM, (p.returncode, p.stderr.read())


def test_with_set_says_a_wrong_key_where_it_is_typed(work):
    sc = tactile.Scenario.load(paper)
    for key, value, text in [("no.such", 1, "1"), ("control.kidn", "tdpa", '"tdpa"'),
                             ("samples", "many", '"many"')]:
        with pytest.raises(tactile.ScenarioError) as e:
            sc.with_set({key: value})
        c = cli("check", str(paper), "--set", f"{key}={text}")
        assert c.returncode == 2 and str(e.value) in c.stderr, (str(e.value), c.stderr)
    # A value out of range may hang on keys still to come: said by check().
    later = sc.with_set({"network.forward.delay_ms": [1, 2]})
    with pytest.raises(tactile.ScenarioError, match="network.forward.delay_ms"):
        later.check()
    with pytest.raises(TypeError, match="give a dict"):
        sc.with_set([("samples", 10)])
    with pytest.raises(TypeError, match="a key is a scenario key"):
        sc.with_set({3: 10})


def test_wrong_arguments_say_what_to_give(work, monkeypatch):
    sc = tactile.Scenario.paper().with_set({"samples": 50})
    with pytest.raises(TypeError, match=r"give a tactile\.Scenario .*Scenario\.load"):
        tactile.run(str(paper))
    with pytest.raises(TypeError, match="give a tactile.Scenario"):
        tactile.sweep(str(paper), {"samples": [10]})
    with pytest.raises(TypeError, match="give the grid as a dict"):
        tactile.sweep(sc, [("samples", [10])])
    with pytest.raises(tactile.ScenarioError, match=r"jobs=18446744073709551616"):
        tactile.sweep(sc, {"samples": [10]}, jobs=2**64)
    with pytest.raises(tactile.ScenarioError, match=r"seeds=18446744073709551616: give 1 to 1000"):
        tactile.sweep(sc, {"samples": [10]}, seeds=2**64)
    with pytest.raises(TypeError, match=r"jobs=1\.5: give a whole number"):
        tactile.sweep(sc, {"samples": [10]}, jobs=1.5)
    with pytest.raises(TypeError, match="progress='yes'"):
        tactile.sweep(sc, {"samples": [10]}, progress="yes")
    # An empty output folder is no folder: nothing lands in the working folder.
    monkeypatch.chdir(work)
    for call in [lambda: tactile.run(sc, out=""),
                 lambda: tactile.sweep(sc, {"samples": [10]}, out=""),
                 lambda: tactile.report(work, out="")]:
        with pytest.raises(tactile.ScenarioError, match="out='' is no folder"):
            call()
    assert list(work.iterdir()) == []


def test_scenario_text_has_the_commands_size_limit(work):
    limit = 1 << 20
    big = work / "big.toml"
    big.write_text("#" * (limit + 1))
    c = cli("check", str(big))
    said = f"is {limit + 1} bytes, more than the {limit} a scenario may have"
    assert c.returncode == 2 and said in c.stderr, c.stderr
    with pytest.raises(tactile.ScenarioError, match=said):
        tactile.Scenario.from_toml("#" * (limit + 1))
    # Counted in bytes, as a file's: 2 bytes a character here.
    with pytest.raises(tactile.ScenarioError, match=f"is {limit + 2} bytes"):
        tactile.Scenario.from_toml("\u00e9" * (limit // 2 + 1))
    assert tactile.Scenario.from_toml("#" * limit).sets == ()
    with pytest.raises(TypeError, match="a scenario's TOML is a str"):
        tactile.Scenario.from_toml(b"samples = 10")
    # A value has the same bound (a command line's is the system's argument list).
    huge = [0.0] * 300_000
    with pytest.raises(tactile.ScenarioError, match="with_set: the values are .* bytes of TOML"):
        tactile.Scenario.paper().with_set({"environment.objects": [huge]})
    with pytest.raises(tactile.ScenarioError, match="sweep: the values are .* bytes of TOML"):
        tactile.sweep(tactile.Scenario.paper(), {"name": ["x" * limit, "y"]})


def test_the_shipped_scenarios_are_the_repositorys_and_run_from_anywhere(work, monkeypatch):
    names = tactile.Scenario.shipped_names()
    assert names == sorted(p.stem for p in (ROOT / "deploy" / "scenarios").glob("*.toml"))
    assert "wall-delay" in names and "panda-reach" in names
    monkeypatch.chdir(work)
    for name in names:
        sc = tactile.Scenario.shipped(name)
        assert sc._text == (ROOT / "deploy" / "scenarios" / f"{name}.toml").read_text()
        if "ros2" in name:
            # ROS 2 needs the node programs: said for what it is, not "rebuild".
            with pytest.raises(tactile.ScenarioError, match="needs the node programs") as e:
                sc.check()
            assert "in-process" in str(e.value)
        else:
            sc.check()
    # Its inputs (a trajectory, an arm's URDF) are shipped beside it.
    r = tactile.run(tactile.Scenario.shipped("panda-reach").with_set({"samples": 200}))
    assert r.completed and r.joints.num_rows == 200
    with pytest.raises(tactile.ScenarioError, match="the package ships .*wall-delay"):
        tactile.Scenario.shipped("wall-dealy")


def test_what_this_package_cannot_run_says_what_would():
    """The command's refusals name a cargo flag; from Python they name what helps:
    the node programs for ROS 2 (no build of the package could), a pip option for
    the RTL."""
    ros = tactile.Scenario.shipped("panda-ros2")
    with pytest.raises(tactile.ScenarioError, match="needs the node programs") as e:
        tactile.run(ros)
    assert "in-process" in str(e.value)
    rtl = tactile.Scenario.paper().with_set({"arithmetic": "rtl"})
    try:
        rtl.check()
    except tactile.ScenarioError as e:
        # A package built without the RTL (the default; --all-features builds it).
        said = str(e)
        assert "this package was built without" in said, said
        assert "pip install ./deploy/python --config-settings" in said, said


def test_the_shipped_networks_are_in_the_package_by_path_and_by_name(work, monkeypatch):
    """deploy/networks comes with the package, file for file (its PROVENANCE and
    licences too); a scenario beside the shipped ones reads a histogram by its
    relative path, and any scenario names a shipped one."""
    here = Path(tactile.__file__).resolve().parent
    shipped = ROOT / "deploy" / "networks"
    files = [f for f in shipped.rglob("*") if f.is_file()]
    assert any(f.name == "PROVENANCE" for f in files)
    for f in files:
        assert (here / "networks" / f.relative_to(shipped)).read_bytes() == f.read_bytes()
    monkeypatch.chdir(work)
    text = (ROOT / "deploy" / "scenarios" / "wall-delay.toml").read_text()
    text = text.replace("samples = 8000", "samples = 300")
    raw = "../networks/deterministic6g/PD-Wireless-5G-2a/5G-midband-Downlink_PD-Wireless-5G-2a.csv"
    by_path = text.replace(
        "delay = [25, 25, 25]",
        f'delay_histogram = {{ path = "{raw}", format = "d6g_data" }}', 1)
    by_name = text.replace(
        "delay = [25, 25, 25]", 'delay_histogram = { name = "5g-3.7ghz-downlink" }', 1)
    a = tactile.run(tactile.Scenario.from_toml(by_path, here / "scenarios"))
    b = tactile.run(tactile.Scenario.from_toml(by_name, work))
    assert a.completed and b.completed
    assert a.trace.equals(b.trace)
