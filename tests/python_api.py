"""The Python package against the command (tests/python.rs runs this with the built
module on PYTHONPATH): the same errors, the same summary and trace, the GIL released
while a run computes. Usage: python_api.py TACTILE_BINARY WORK_DIR REPO_ROOT."""
import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq

import tactile

tactile_bin, work, root = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
paper = root / "deploy" / "scenarios" / "paper.toml"
panda = root / "deploy" / "scenarios" / "panda.toml"


def cli(*args):
    return subprocess.run([tactile_bin, *args], capture_output=True, text=True)


def bad_input_is_the_commands_error():
    sc = tactile.Scenario.load(paper)
    for key, value, text in [("samples", -3, "-3"), ("control.kind", "nope", '"nope"'),
                             ("network.forward.delay_ms", [1, 2], "[1,2]"),
                             ("no.such", 1, "1")]:
        try:
            sc.with_set({key: value}).check()
        except tactile.ScenarioError as e:
            said = str(e)
        else:
            raise AssertionError(f"{key}={value} passed")
        c = cli("check", str(paper), "--set", f"{key}={text}")
        assert c.returncode == 2, (key, c.returncode, c.stderr)
        assert said in c.stderr, (said, c.stderr)
        assert key.split(".")[-1] in said or "no" in said, said
    try:
        sc.with_set({"samples": float("nan")})
    except tactile.ScenarioError as e:
        assert "samples" in str(e), e
    else:
        raise AssertionError("a NaN passed")
    try:
        tactile.Scenario.load(work / "missing.toml")
    except tactile.ScenarioError as e:
        assert "missing.toml" in str(e), e
    else:
        raise AssertionError("a missing file passed")


def sets_are_the_commands():
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


def a_run_is_the_commands_run():
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


def in_memory_and_an_arm():
    sc = tactile.Scenario.load(panda).with_set({"samples": 300})
    r = tactile.run(sc)
    assert r.out is None and r.completed
    assert r.trace.num_rows == 300
    assert r.joints is not None and r.joints.num_rows == 300
    assert "q_1" in r.joints.column_names and r.summary["task_space"] is not None


def the_gil_is_released_while_it_runs():
    sc = tactile.Scenario.paper().with_set({"samples": 3000})
    done = threading.Event()
    t = threading.Thread(target=lambda: (tactile.run(sc), done.set()))
    start = time.monotonic()
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    took = time.monotonic() - start
    # Held, the GIL would keep this loop from running at all until the run ends.
    assert took > 0.05 and ticks > 10, (took, ticks)


INTERRUPTED = """
import sys, tactile
sc = tactile.Scenario.paper().with_set({"samples": 100_000_000})
print("running", flush=True)
try:
    tactile.run(sc, out=sys.argv[1])
except KeyboardInterrupt as e:
    print("KeyboardInterrupt:", e, flush=True)
r = tactile.run(tactile.Scenario.paper().with_set({"samples": 50}))
print("then", r.completed, r.summary["samples_sent"], flush=True)
"""


def ctrl_c_stops_a_run_keeps_its_report_and_the_next_runs():
    """SIGINT (a terminal's Ctrl-C, a notebook's interrupt) ends a run as it ends the
    command: KeyboardInterrupt, the report of what ran written and marked; the next
    run in the same process runs whole."""
    out = work / "stopped"
    p = subprocess.Popen([sys.executable, "-c", INTERRUPTED, str(out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "running"
    # The run writes its records as it goes: the master's record growing is the run
    # going (a signal before the run installs its handlers would end Python itself).
    while not (out / "master.rec").exists() or (out / "master.rec").stat().st_size == 0:
        assert p.poll() is None, p.stderr.read()
        time.sleep(0.01)
    p.send_signal(2)
    said, err = p.communicate(timeout=120)
    assert p.returncode == 0, (p.returncode, said, err)
    assert "KeyboardInterrupt: stopped by a signal" in said, (said, err)
    assert "then True 50" in said, (said, err)
    s = json.loads((out / "summary.json").read_text())
    assert s["interrupted"] is True and 0 < s["samples_sent"] < 100_000_000, s["samples_sent"]


for test in [bad_input_is_the_commands_error, sets_are_the_commands,
             a_run_is_the_commands_run, in_memory_and_an_arm,
             the_gil_is_released_while_it_runs,
             ctrl_c_stops_a_run_keeps_its_report_and_the_next_runs]:
    test()
    print(f"ok {test.__name__}", flush=True)
