"""A sweep in this process, as `tactile sweep` runs it, and a sweep's folder read back
as a pandas.DataFrame."""
from __future__ import annotations

import csv
import json
import numbers
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, List, Mapping, Optional, Sequence, Union

from . import _native
from ._native import RunError, ScenarioError
from ._scenario import Scenario, _sets_fit, _toml_value, out_folder, scenario_of

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, int, str, str], Any]

# The largest count the compiled half takes (a usize): beyond it Python would raise
# OverflowError, not say which argument.
_USIZE = 2**64 - 1


def _key(key: Any) -> str:
    if not isinstance(key, str):
        raise TypeError(f"sweep: {key!r}: a swept key is a scenario key, a str (or a "
                        "tuple of them, paired)")
    if not key.strip():
        raise ScenarioError(f"sweep: {key!r}: a swept key is a scenario key, not blank")
    return key.strip()


def _values(key: Any, values: Any) -> list:
    """A key's values (any non-string iterable: a list, a tuple, a NumPy array), a
    NumPy array's rows as lists."""
    try:
        values = [] if isinstance(values, (str, bytes)) else list(values)
    except TypeError:
        values = []
    if not values:
        raise ScenarioError(f"sweep: {key}: give its values as a non-empty list "
                            f"(a list of lists for a list-valued key)")
    return [v.tolist() if hasattr(v, "tolist") and getattr(v, "ndim", 0) > 0 else v
            for v in values]


def _axis(key: str, values: list) -> str:
    return f"{key}=" + ",".join(_toml_value(key.lstrip("+"), v) for v in values)


def _sets(grid: Mapping) -> List[str]:
    """The grid as the command's `--set KEY=V1,V2,...`: a tuple of keys is paired, its
    values tuples, one value per key (`--set K1=... --set +K2=...`)."""
    sets = []
    for key, values in grid.items():
        if not isinstance(key, tuple):
            k = _key(key)
            sets.append(_axis(k, _values(k, values)))
            continue
        keys = [_key(k) for k in key]
        if len(keys) < 2:
            raise ScenarioError(f"sweep: {key!r}: paired keys are two or more")
        rows = _values(key, values)
        for row in rows:
            if not isinstance(row, (tuple, list)) or len(row) != len(keys):
                raise ScenarioError(f"sweep: {key!r}: each value is a tuple of {len(keys)}, "
                                    f"one per key, not {row!r}")
        sets.extend(_axis(("+" if j else "") + k, [row[j] for row in rows])
                    for j, k in enumerate(keys))
    return sets


def _count(what: str, v: Any, say: str) -> int:
    """A whole-number argument: TypeError for another type, ScenarioError naming it
    for a value no count can be."""
    if isinstance(v, bool) or not isinstance(v, numbers.Integral):
        raise TypeError(f"sweep: {what}={v!r}: give a whole number ({say})")
    if v < 0 or v > _USIZE:
        raise ScenarioError(f"sweep: {what}={v!r}: {say}")
    return int(v)


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
    if progress is not None and progress is not True:
        raise TypeError(f"sweep: progress={progress!r}: give None or True (shown), False "
                        "(nothing) or a function")
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


def sweep(scenario: Scenario, grid: Mapping[Any, Sequence[Any]], seeds: int = 1,
          jobs: Optional[int] = None, out: Optional[PathLike] = None, trace: bool = False,
          trace_format: Optional[str] = "parquet", resume: bool = False,
          progress: Union[bool, Progress, None] = None) -> "pandas.DataFrame":
    """Runs `scenario` once for every combination of `grid`'s values (each key a
    scenario key as `with_set` takes it, its values a list; the first key varies
    slowest; a tuple of keys is paired, its values tuples), each over `seeds` seeds,
    `jobs` runs at once (None: the CPUs), as `tactile sweep` does, into folder `out`
    (None: a temporary folder, removed; '' is refused). The GIL is released while it
    runs.

    Returns what `read_sweep(out)` reads: a pandas.DataFrame, one row per run in the
    grid's order: `run` (its folder's name), `combination`, one column per swept key
    holding its values (int64 or float64 for numbers, str, bool, lists), `seed` (as
    the run used it), every metric of `sweep.csv`, and `folder` (the run's folder;
    None with out=None). The columns are the same whatever `seeds`. `out` holds the
    command's files: sweep.csv (these rows), sweep-summary.csv (mean and 95 % interval
    per combination), a plot per metric, one folder per run.

    A pair of keys moves together, value for value, instead of combining:
    `{("network.forward.delay_ms", "network.backward.delay_ms"): [(0, 0), (5, 5)]}`
    runs the two round trips split evenly both ways (the command's `--set
    network.forward.delay_ms=0,5 --set +network.backward.delay_ms=0,5`). A value given
    twice, or two values that give the same scenario (10 and 10.0000001 ms, both 10
    samples at 1 kHz), is refused.

    `trace` writes every run's trace (as `trace_format`; None is no trace, as
    `trace=False`); `resume` keeps the runs `out` already holds (a sweep the command
    started too). `progress`: None or True shows a tqdm bar if tqdm is installed,
    else the command's line on standard error; False nothing; a callable is called
    as `progress(ended, total, run, what)` after each run (an exception there stops
    the sweep). Bad input raises ScenarioError (TypeError for an argument of the
    wrong type) before any run starts; a failed run RunError once the tables are
    written; Ctrl-C stops the sweep after the runs in hand and raises
    KeyboardInterrupt once the tables of the runs that ended are written
    (`resume=True` runs the rest)."""
    scenario_of(scenario, "sweep")
    if not isinstance(grid, Mapping):
        raise TypeError(f"sweep: give the grid as a dict {{KEY: [V1, V2, ...]}}, not a "
                        f"{type(grid).__name__}")
    if not grid:
        raise ScenarioError("sweep: give the swept keys as a dict {KEY: [V1, V2, ...]}")
    sets = _sets(grid)
    _sets_fit(sets, "sweep")
    seeds = _count("seeds", seeds, "give 1 to 1000")
    if jobs is not None:
        jobs = _count("jobs", jobs, "give 1 or more, or None for the CPUs")
    import pandas  # noqa: F401 - before any run: a missing pandas is said at once
    if trace_format is None:
        trace, trace_format = False, "parquet"
    if out is None:
        with tempfile.TemporaryDirectory(prefix="tactile-sweep-") as tmp:
            df = _sweep_into(scenario, sets, seeds, jobs, Path(tmp) / "sweep", trace,
                             trace_format, resume, progress)
            df["folder"] = None
            return df
    return _sweep_into(scenario, sets, seeds, jobs, out_folder(out, "sweep"), trace,
                       trace_format, resume, progress)


def _sweep_into(scenario: Scenario, sets: list, seeds: int, jobs: Optional[int], out: Path,
                trace: bool, trace_format: str, resume: bool,
                progress: Union[bool, Progress, None]) -> "pandas.DataFrame":
    tell, bar = _progress(progress)
    try:
        _native.sweep(*scenario._source(), sets, seeds, jobs, os.fspath(out), trace,
                      trace_format, resume, tell)
    finally:
        if bar is not None:
            bar.close()
    return read_sweep(out)


def read_sweep(folder: PathLike) -> "pandas.DataFrame":
    """A sweep's folder read back, whichever front end ran it (`tactile sweep` or
    `tactile.sweep`, whole, resumed or merged): the DataFrame `sweep` returns, from
    its `sweep.json` and `sweep.csv`, the runs that ended (the per-combination means
    and intervals are `pandas.read_csv(folder + "/sweep-summary.csv")`)."""
    import pandas
    d = Path(folder)
    try:
        spec = json.loads((d / "sweep.json").read_text(encoding="utf-8"))
        with open(d / "sweep.csv", encoding="utf-8", newline="") as f:
            header = next(csv.reader(f))
    except (OSError, ValueError, StopIteration) as e:
        raise RunError(f"{d}: no sweep to read ({e})") from None
    axes, combos = _native.sweep_grid(spec["sets"])
    keys = [k for k, _, _ in axes if k != "seed"]
    metrics = header[header.index("seed") + 1:]
    df = pandas.read_csv(d / "sweep.csv", dtype={k: str for k in keys},
                         keep_default_na=False, na_values={c: [""] for c in metrics})
    for j, (key, _, values) in enumerate(axes):
        if key != "seed":
            typed = [json.loads(v) for v in values]
            df[key] = pandas.Series([typed[combos[k][j]] for k in df["combination"]],
                                    index=df.index, dtype=_dtype(typed))
    df["folder"] = [os.fspath(d.resolve() / r) for r in df["run"]]
    return df


def _dtype(values: list) -> Optional[str]:
    """A swept key's column type: int64 or float64 for numbers, bool for booleans,
    object for lists; None (pandas infers: str) for the rest."""
    if all(type(v) is int for v in values) and all(-2**63 <= v < 2**63 for v in values):
        return "int64"
    if all(type(v) in (int, float) for v in values):
        return "float64"
    if all(type(v) is bool for v in values):
        return "bool"
    if any(isinstance(v, (list, dict)) for v in values):
        return "object"
    return None
