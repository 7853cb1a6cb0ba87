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

A run's folder is the command's: `tactile report` and every tool read it the same.
"""
from __future__ import annotations

import json
import math
import numbers
import os
import tempfile
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

from . import _native
from ._native import RunError, ScenarioError

__all__ = ["Scenario", "Run", "run", "report", "ScenarioError", "RunError"]

PathLike = Union[str, "os.PathLike[str]"]


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


def run(scenario: Scenario, out: Optional[PathLike] = None,
        trace_format: str = "parquet") -> Run:
    """Runs `scenario` in this process, as `tactile run --in-process` does, into
    folder `out` (None: a temporary folder, read into memory and removed, with it the
    report of a run that failed or was interrupted). The GIL is released while it
    runs. Bad input raises ScenarioError; a failed run RunError after its report is
    read; Ctrl-C stops the run after the sample in hand and raises
    KeyboardInterrupt once its report is written."""
    if out is None:
        with tempfile.TemporaryDirectory(prefix="tactile-run-") as tmp:
            r = _run_into(scenario, Path(tmp) / "run", trace_format, kept=False)
            r.out = None
            return r
    return _run_into(scenario, Path(out), trace_format, kept=True)


def _run_into(scenario: Scenario, out: Path, trace_format: str, kept: bool) -> Run:
    _native.run(*scenario._source(), os.fspath(out), trace_format)
    r = Run.read(out)
    if not r.completed:
        events = "; ".join(r.summary.get("events", [])[:1])
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
