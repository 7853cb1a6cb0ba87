"""Tactile from Python: load a scenario, change it as `--set` does, check it, run it
in-process and read its report back, through the same libraries as the `tactile`
command (no subprocess, no second copy of the loop).

    import tactile
    sc = tactile.Scenario.load("deploy/scenarios/paper.toml")
    sc = sc.with_set({"samples": 3000, "control.kind": "tdpa"})
    sc.check()                       # the command's errors, as ScenarioError
    run = tactile.run(sc, out="runs/a")
    run.summary["round_trip_ns"]["p50"]
    run.trace                        # pyarrow.Table, trace.parquet's columns
    df = tactile.sweep(sc, {"network.forward.delay_ms": [0, 10, 50],
                            "control.kind": ["none", "tdpa"]}, seeds=3)

A run's folder is the command's: `tactile report` and every tool read it the same.
"""
from __future__ import annotations

import csv
import itertools
import json
import math
import numbers
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from . import _native
from ._native import RunError, ScenarioError

__all__ = ["Scenario", "Run", "run", "sweep", "report", "ScenarioError", "RunError",
           "CallbackError"]

PathLike = Union[str, "os.PathLike[str]"]


class CallbackError(RunError):
    """A Python callable in a run's loop raised or gave a value the run cannot take
    (not three finite numbers); the message names the callable and the sample, the
    callable's own exception is the cause. The run stopped after that sample and its
    report (marked interrupted) was written."""


def _toml_string(s: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped,
    everything else as it is (JSON's escapes would split a character outside the BMP
    into surrogates, which TOML refuses)."""
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(key: str, v: Any) -> str:
    """A Python value (NumPy's scalars too) as the TOML literal `--set KEY=VALUE`
    takes."""
    if isinstance(v, bool) or getattr(getattr(v, "dtype", None), "kind", None) == "b":
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        if not math.isfinite(x):
            raise ScenarioError(f"--set {key}: {x} is not a finite number")
        return repr(x)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_toml_value(key, x) for x in v) + "]"
    raise ScenarioError(f"--set {key}: a {type(v).__name__} is no TOML value "
                        "(give a number, a string, a bool or a list of them)")


class Scenario:
    """A scenario: its TOML, the folder its relative paths are read from, and the
    `--set`s to apply. Immutable: `with_set` returns a new one."""

    __slots__ = ("_text", "_base_dir", "_name", "_path", "_sets")

    def __init__(self, text: str, base_dir: PathLike = ".", name: str = "<scenario text>",
                 path: Optional[PathLike] = None, sets: Sequence[str] = ()):
        self._text = text
        self._base_dir = os.fspath(Path(base_dir).resolve())
        self._name = name
        self._path = None if path is None else os.fspath(Path(path).resolve())
        self._sets = tuple(sets)

    @classmethod
    def load(cls, path: PathLike) -> "Scenario":
        """The scenario in file `path`, read as the command reads it (UTF-8, at most
        1 MiB; the same errors); relative paths in it are read beside it."""
        text, base_dir, name = _native.read_scenario(os.fspath(path))
        return cls(text, base_dir, name, path)

    @classmethod
    def from_toml(cls, text: str, base_dir: PathLike = ".") -> "Scenario":
        """A scenario from its TOML text; relative paths are read from `base_dir`."""
        return cls(text, base_dir)

    @classmethod
    def paper(cls) -> "Scenario":
        """The built-in paper scenario (what `tactile run` runs with no scenario)."""
        return cls(_native.PAPER_SCENARIO, ".", "deploy/scenarios/paper.toml (built in)")

    def with_set(self, values: Mapping[str, Any]) -> "Scenario":
        """A copy with `--set KEY=VALUE` for each entry: the same keys and checks as the
        command's (`network.forward.delay_ms`, `control.kind`, ...)."""
        sets = [f"{k}={_toml_value(k, v)}" for k, v in values.items()]
        return Scenario(self._text, self._base_dir, self._name, self._path,
                        self._sets + tuple(sets))

    @property
    def sets(self) -> tuple:
        """The `--set`s applied, as the command takes them."""
        return self._sets

    def _source(self) -> tuple:
        return (self._text, self._base_dir, self._name, self._path, list(self._sets))

    def check(self) -> list:
        """Validates the scenario as `tactile check` does (inputs read, arm loaded);
        raises ScenarioError naming the field. Returns what check says (length,
        files, the delays in both units, warnings)."""
        return _native.check(*self._source())[1]

    def to_toml(self) -> str:
        """The scenario as it would run: every default filled in, the sets applied,
        paths resolved (`tactile check`'s output)."""
        return _native.check(*self._source())[0]

    def __repr__(self) -> str:
        sets = "".join(f" --set {s}" for s in self._sets)
        return f"<tactile.Scenario {self._name}{sets}>"


class Run:
    """A run's report, read back from its folder: `summary` (summary.json as a dict),
    `trace` (pyarrow.Table: trace.parquet, or trace.csv), `joints` (a URDF arm's
    joints.csv as a pyarrow.Table, else None), `completed`, and `out` (the folder, or
    None for a run kept in memory)."""

    def __init__(self, out: Optional[Path], summary: dict, trace: Any, joints: Any,
                 completed: bool):
        self.out = out
        self.summary = summary
        self.trace = trace
        self.joints = joints
        self.completed = completed

    @classmethod
    def read(cls, folder: PathLike) -> "Run":
        """The report in `folder` (summary.json, the trace, joints.csv); `completed`
        is the summary's (not `failed`)."""
        d = Path(folder)
        try:
            summary = json.loads((d / "summary.json").read_text())
        except (OSError, ValueError) as e:
            raise RunError(f"{d}: no report to read ({e})") from None
        trace = None
        if (d / "trace.parquet").exists():
            import pyarrow.parquet as pq
            trace = pq.read_table(d / "trace.parquet")
        elif (d / "trace.csv").exists():
            import pyarrow.csv as pc
            trace = pc.read_csv(d / "trace.csv")
        joints = None
        if (d / "joints.csv").exists():
            import pyarrow.csv as pc
            joints = pc.read_csv(d / "joints.csv")
        return cls(d, summary, trace, joints, not summary.get("failed", False))

    def __repr__(self) -> str:
        rt = (self.summary.get("round_trip_ns") or {}).get("p50")
        return f"<tactile.Run {self.out or '(in memory)'} completed={self.completed} round_trip_p50_ns={rt}>"


Operator = Callable[[int, float, "numpy.ndarray"], Any]
Predictor = Callable[[int, int, "numpy.ndarray"], Any]


def _three(r: Any, what: str, n: int) -> tuple:
    """A callable's result as three finite floats, or CallbackError naming the sample.
    A tuple, list or 1-D array of three numbers takes the quick way (a few hundred
    nanoseconds a call); anything else is read by NumPy, which says what is wrong."""
    import numpy as np
    if isinstance(r, (tuple, list)) or (isinstance(r, np.ndarray) and r.ndim == 1):
        try:
            if len(r) == 3:
                x, y, z = float(r[0]), float(r[1]), float(r[2])
                if math.isfinite(x) and math.isfinite(y) and math.isfinite(z):
                    return x, y, z
        except (TypeError, ValueError):
            pass
    try:
        a = np.asarray(r, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise CallbackError(f"{what} at sample {n}: gave {r!r}, not three numbers ({e})") from None
    if a.shape != (3,):
        raise CallbackError(f"{what} at sample {n}: gave an array of shape {a.shape}, "
                            "not three numbers (shape (3,))")
    if not np.isfinite(a).all():
        raise CallbackError(f"{what} at sample {n}: gave {a.tolist()}, not finite")
    return float(a[0]), float(a[1]), float(a[2])


def _raised(what: str, n: int, e: Exception) -> CallbackError:
    return CallbackError(f"{what} at sample {n}: {type(e).__name__}: {e}")


def _operator(f: Operator) -> Callable:
    """The operator as the loop calls it: (n, t, fx, fy, fz) -> three floats."""
    import numpy as np

    def call(n: int, t: float, fx: float, fy: float, fz: float) -> tuple:
        try:
            r = f(n, t, np.array((fx, fy, fz)))
        except Exception as e:
            raise _raised("operator", n, e) from e
        return _three(r, "operator", n)
    return call


def _predictor(f: Predictor, what: str) -> Callable:
    """A predictor as the loop calls it: (n, to, history's bytes) -> three floats;
    the history a read-only (k, 4) array, rows [sample, x, y, z], oldest first."""
    import numpy as np

    def call(n: int, to: int, raw: bytes) -> tuple:
        history = np.frombuffer(raw, dtype=np.float64).reshape(-1, 4)
        try:
            r = f(n, to, history)
        except Exception as e:
            raise _raised(what, n, e) from e
        return _three(r, what, n)
    return call


def _hook(f: Any, wrap: Callable, name: str, *args: str) -> Optional[Callable]:
    if f is None:
        return None
    if not callable(f):
        raise ScenarioError(f"{name}: give a function, not a {type(f).__name__}")
    return wrap(f, *args)


def run(scenario: Scenario, out: Optional[PathLike] = None,
        trace_format: Optional[str] = "parquet",
        operator: Optional[Operator] = None,
        backward_predictor: Optional[Predictor] = None,
        forward_predictor: Optional[Predictor] = None) -> Run:
    """Runs `scenario` in this process, as `tactile run --in-process` does, into
    folder `out` (None: a temporary folder, read into memory and removed, with it the
    report of a run that failed or was interrupted). The GIL is released while it
    runs, except while a callable below runs. Bad input raises ScenarioError; a failed
    run RunError after its report is read; Ctrl-C stops the run after the sample in
    hand and raises KeyboardInterrupt once its report is written. `trace_format` is
    the command's `--trace-format` (parquet, csv, both); None writes no trace and no
    recording, as `--no-trace` (then `Run.trace` is None).

    Python in the loop, each called on the run's thread when the loop needs it:

    - `operator(n, t, felt)`: the simulated hand's target at sample n (time t, s),
      given `felt`, the force (N, a (3,) array) the hand was made to feel at the sample
      before; returns the handle's position (m, three numbers), in place of the
      scenario's `[operator]` (which must be 3-DoF). The hand (`[master.hand]`) and
      its approach from home move the handle there, as with a built-in operator.
    - `backward_predictor(n, to, history)`: the master's guess of the slave's force
      h for its sample n (missing, late, not sent or rejected), at the slave's sample
      `to`, from `history`, the values accepted so far (a read-only (k, 4) array, rows
      `[sample, x, y, z]`, oldest first, at most 64); in place of
      `[master.predictor]`'s kind, whose acceptance checks and `horizon_s` still hold.
    - `forward_predictor(n, to, history)`: the slave's guess of the master's position
      v, likewise, in place of `[slave.predictor]`'s kind.

    A callable that raises, or returns anything but three finite numbers, stops the
    run after that sample; CallbackError, naming the callable and the sample, is
    raised once the report is written."""
    hooks = (_hook(operator, _operator, "operator"),
             _hook(backward_predictor, _predictor, "backward_predictor", "backward predictor"),
             _hook(forward_predictor, _predictor, "forward_predictor", "forward predictor"))
    if out is None:
        with tempfile.TemporaryDirectory(prefix="tactile-run-") as tmp:
            r = _run_into(scenario, Path(tmp) / "run", trace_format, hooks, kept=False)
            r.out = None
            return r
    return _run_into(scenario, Path(out), trace_format, hooks, kept=True)


def _run_into(scenario: Scenario, out: Path, trace_format: Optional[str], hooks: tuple,
              kept: bool) -> Run:
    _native.run(*scenario._source(), os.fspath(out), trace_format, *hooks)
    r = Run.read(out)
    if not r.completed:
        said = [e for e in r.summary.get("events", []) if "(the Python API)" not in e]
        events = "; ".join(said[:1])
        where = f"its report is in {out}" if kept else "give out= to keep its report"
        raise RunError(f"the run failed: {events} ({where})")
    return r


def report(*dirs: PathLike, out: Optional[PathLike] = None,
           trace_format: str = "parquet") -> Run:
    """The report of the records in `dirs` (a run's folder, or one folder per node),
    written as `tactile report` writes it into `out` (default, as the command's: the
    folder of the master's record), and read back."""
    if not dirs:
        raise ScenarioError("report: give a run's folder, or one folder per node")
    target = _native.report([os.fspath(d) for d in dirs],
                            None if out is None else os.fspath(out), trace_format)
    return Run.read(target)


Progress = Callable[[int, int, str, str], Any]


def _axis(key: Any, values: Any) -> tuple:
    """One swept key and its values (any non-string iterable: a list, a tuple, a
    NumPy array) as the command's `--set KEY=V1,V2,...`."""
    if not isinstance(key, str) or not key.strip():
        raise ScenarioError(f"sweep: {key!r}: a swept key is a scenario key, a string")
    key = key.strip()
    try:
        values = [] if isinstance(values, (str, bytes)) else list(values)
    except TypeError:
        values = []
    if not values:
        raise ScenarioError(f"sweep: {key}: give its values as a non-empty list "
                            f"(a list of lists for a list-valued key)")
    values = [v.tolist() if hasattr(v, "tolist") and getattr(v, "ndim", 0) > 0 else v
              for v in values]
    return key, values, f"{key}=" + ",".join(_toml_value(key, v) for v in values)


def _terminal_progress() -> Progress:
    """The command's progress line, on standard error."""
    start = time.monotonic()

    def mmss(s: float) -> str:
        return f"{int(s // 60)}:{int(s % 60):02d}"

    def say(ended: int, total: int, run: str, what: str) -> None:
        elapsed = time.monotonic() - start
        left = elapsed / ended * (total - ended)
        print(f"tactile sweep: {ended}/{total} runs, {mmss(elapsed)} elapsed, "
              f"about {mmss(left)} left ({run}: {what})", file=sys.stderr, flush=True)
    return say


def _progress(progress: Union[bool, Progress, None]) -> tuple:
    """The callback for `progress`, and what to close after: a tqdm bar (its
    notebook widget in Jupyter) if tqdm is installed, else the command's line."""
    if progress is False:
        return None, None
    if callable(progress):
        return progress, None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _terminal_progress(), None
    bar = tqdm(desc="tactile sweep", unit="run")

    def update(ended: int, total: int, run: str, what: str) -> None:
        bar.total = total
        bar.set_postfix_str(f"{run}: {what}", refresh=False)
        bar.update(max(0, ended - bar.n))
    return update, bar


def sweep(scenario: Scenario, grid: Mapping[str, Sequence[Any]], seeds: int = 1,
          jobs: Optional[int] = None, out: Optional[PathLike] = None, trace: bool = False,
          trace_format: Optional[str] = "parquet", resume: bool = False,
          progress: Union[bool, Progress, None] = None) -> "pandas.DataFrame":
    """Runs `scenario` once for every combination of `grid`'s values (each key a
    scenario key as `with_set` takes it, its values a list; the first key varies
    slowest), each over `seeds` seeds, `jobs` runs at once (None: the CPUs), as
    `tactile sweep` does, into folder `out` (None: a temporary folder, removed). The
    GIL is released while it runs.

    Returns a pandas.DataFrame, one row per run in the grid's order: `run` (its
    folder's name), `combination`, one column per swept key holding the values as
    given (numbers, strings, lists), `seed` (as the run used it), every metric of
    `sweep.csv`, and `folder` (the run's folder; None with out=None). The columns are
    the same whatever `seeds`. `out` holds the command's files: sweep.csv (these
    rows), sweep-summary.csv (mean and 95 % interval per combination), a plot per
    metric, one folder per run.

    `trace` writes every run's trace (as `trace_format`; None is no trace, as
    `trace=False`); `resume` keeps the runs `out` already holds. `progress`: None shows a tqdm bar if tqdm is installed, else the
    command's line on standard error; False nothing; a callable is called as
    `progress(ended, total, run, what)` after each run (an exception there stops the
    sweep). Bad input raises ScenarioError before any run starts; a failed run
    RunError once the tables are written; Ctrl-C stops the sweep after the runs in
    hand and raises KeyboardInterrupt once the tables of the runs that ended are
    written (`resume=True` runs the rest)."""
    if not isinstance(grid, Mapping) or not grid:
        raise ScenarioError("sweep: give the swept keys as a dict {KEY: [V1, V2, ...]}")
    axes = [_axis(k, v) for k, v in grid.items()]
    if isinstance(seeds, bool) or not isinstance(seeds, numbers.Integral) or seeds < 0:
        raise ScenarioError(f"sweep: seeds={seeds!r}: give 1 to 1000")
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, numbers.Integral)
                             or jobs < 0):
        raise ScenarioError(f"sweep: jobs={jobs!r}: give a whole number, or None")
    import pandas  # before any run: a missing pandas is said at once
    if trace_format is None:
        trace, trace_format = False, "parquet"
    if out is None:
        with tempfile.TemporaryDirectory(prefix="tactile-sweep-") as tmp:
            df = _sweep_into(scenario, axes, int(seeds), jobs, Path(tmp) / "sweep",
                             trace, trace_format, resume, progress)
            df["folder"] = None
            return df
    return _sweep_into(scenario, axes, int(seeds), jobs, Path(out), trace, trace_format,
                       resume, progress)


def _sweep_into(scenario: Scenario, axes: list, seeds: int, jobs: Optional[int], out: Path,
                trace: bool, trace_format: str, resume: bool,
                progress: Union[bool, Progress, None]) -> "pandas.DataFrame":
    tell, bar = _progress(progress)
    try:
        _native.sweep(*scenario._source(), [a[2] for a in axes], seeds,
                      None if jobs is None else int(jobs), os.fspath(out), trace,
                      trace_format, resume, tell)
    finally:
        if bar is not None:
            bar.close()
    return _table(out, axes)


def _table(out: Path, axes: list) -> "pandas.DataFrame":
    """`out/sweep.csv` with each swept key's column holding the values as given,
    looked up by the run's combination (the grid's order, the first key slowest)."""
    import pandas
    keys = [a[0] for a in axes]
    as_text = {k: str for k in keys if k != "seed"}
    df = pandas.read_csv(out / "sweep.csv", dtype=as_text, keep_default_na=False,
                         na_values={c: [""] for c in _metric_columns(out)})
    combos = list(itertools.product(*(a[1] for a in axes)))
    for j, key in enumerate(keys):
        if key != "seed":
            df[key] = pandas.Series([combos[k][j] for k in df["combination"]],
                                    index=df.index, dtype=object)
    df["folder"] = [os.fspath(out.resolve() / r) for r in df["run"]]
    return df


def _metric_columns(out: Path) -> list:
    """sweep.csv's columns after `seed`: the metrics (an empty cell is no value)."""
    with open(out / "sweep.csv", encoding="utf-8", newline="") as f:
        header = next(csv.reader(f))
    return header[header.index("seed") + 1:]
