"""A run in this process and its report, read back from its folder."""
from __future__ import annotations

import json
import os
import tempfile
import warnings
from pathlib import Path
from typing import Any, Optional, Union

from . import _native
from ._loop import Operator, Predictor, hooks
from ._native import RunError, ScenarioError
from ._scenario import Scenario, out_folder, scenario_of

PathLike = Union[str, "os.PathLike[str]"]


class NoTraceWarning(UserWarning):
    """`Run.trace` of a run written without a trace (a sweep's runs, unless
    `trace=True`; `trace_format=None`): the warning says how to get it."""


def _no_trace(out: Optional[Path]) -> str:
    """How to get the trace of a run that has none."""
    if out is not None and (out / "master.rec").is_file():
        return (f"{out} holds no trace: the run was written without one (a sweep writes "
                f"none unless trace=True; run(..., trace_format=None) none either). Its "
                f"records hold every sample: tactile.report({os.fspath(out)!r}, "
                f"out='...') writes the trace from them")
    return ("this run has no trace: it was made with trace_format=None; run it again "
            "with trace_format='parquet' (the default)")


class Run:
    """A run's report, read back from its folder: `summary` (summary.json as a dict),
    `trace` (pyarrow.Table: trace.parquet, or trace.csv; None, with a NoTraceWarning
    saying how to get it, for a run written without one), `joints` (a URDF arm's
    joints.csv as a pyarrow.Table, else None), `bodies` (a physics world's
    bodies.csv as a pyarrow.Table: per sample the tool body and each moving body,
    `sample, body, x, y, z, qx, qy, qz, qw` in the arm's base frame; else None),
    `completed`, and `out` (the folder, or None for a run kept in memory)."""

    def __init__(self, out: Optional[Path], summary: dict, trace: Any, joints: Any,
                 completed: bool, bodies: Any = None):
        self.out = out
        self.summary = summary
        self._trace = trace
        self._hint = None if trace is not None else _no_trace(out)
        self.joints = joints
        self.bodies = bodies
        self.completed = completed

    @property
    def trace(self) -> Any:
        """The trace, a pyarrow.Table; None for a run written without one (a
        NoTraceWarning then says how to get it)."""
        if self._trace is None:
            warnings.warn(self._hint, NoTraceWarning, stacklevel=2)
        return self._trace

    @classmethod
    def read(cls, folder: PathLike) -> "Run":
        """The report in `folder` (summary.json, the trace, joints.csv, bodies.csv);
        `completed` is the summary's (not `failed`)."""
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
        bodies = None
        if (d / "bodies.csv").exists():
            import pyarrow.csv as pc
            bodies = pc.read_csv(d / "bodies.csv")
        return cls(d, summary, trace, joints, not summary.get("failed", False), bodies)

    def __repr__(self) -> str:
        rt = (self.summary.get("round_trip_ns") or {}).get("p50")
        return f"<tactile.Run {self.out or '(in memory)'} completed={self.completed} round_trip_p50_ns={rt}>"


def run(scenario: Scenario, out: Optional[PathLike] = None,
        trace_format: Optional[str] = "parquet",
        operator: Optional[Operator] = None,
        backward_predictor: Optional[Predictor] = None,
        forward_predictor: Optional[Predictor] = None) -> Run:
    """Runs `scenario` in this process, as `tactile run --in-process` does, into
    folder `out` (None: a temporary folder, read into memory and removed, with it the
    report of a run that failed or was interrupted; '' is refused). The GIL is
    released while it runs, except while a callable below runs. Bad input raises
    ScenarioError; a failed run RunError after its report is read; Ctrl-C stops the
    run after the sample in hand (on the main thread, even while a callable below
    blocks: the KeyboardInterrupt is raised inside it) and raises KeyboardInterrupt
    once its report is written. `trace_format` is the command's `--trace-format`
    (parquet, csv, both); None writes no trace and no recording, as `--no-trace`
    (then `Run.trace` is None).

    Python in the loop, each called on the calling thread when the loop needs it:

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

    A callable that raises, or returns anything but three real, finite numbers (text,
    complex numbers, booleans and masked arrays are refused), stops the run after that
    sample; CallbackError, naming the callable and the sample, is raised once the
    report is written."""
    scenario_of(scenario, "run")
    wrapped = hooks(operator, backward_predictor, forward_predictor)
    if out is None:
        with tempfile.TemporaryDirectory(prefix="tactile-run-") as tmp:
            r = _run_into(scenario, Path(tmp) / "run", trace_format, wrapped, kept=False)
        # Its folder is gone, and with it the records a report could be made from.
        r.out, r._hint = None, _no_trace(None)
        return r
    return _run_into(scenario, out_folder(out, "run"), trace_format, wrapped, kept=True)


def _run_into(scenario: Scenario, out: Path, trace_format: Optional[str], wrapped: tuple,
              kept: bool) -> Run:
    _native.run(*scenario._source(), os.fspath(out), trace_format, *wrapped)
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
    folder of the master's record; '' is refused), and read back."""
    if not dirs:
        raise ScenarioError("report: give a run's folder, or one folder per node")
    target = _native.report([os.fspath(d) for d in dirs],
                            None if out is None else os.fspath(out_folder(out, "report")),
                            trace_format)
    return Run.read(target)
