"""Runs and sweeps as a LeRobot v3.0 dataset, as `tactile export lerobot` writes it
(docs/17-lerobot.md)."""
from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any, Iterable, Optional, Union

from . import _native
from ._native import ScenarioError
from ._scenario import out_folder

PathLike = Union[str, "os.PathLike[str]"]


def _folder(run: Any) -> str:
    """A run's folder: a path, or a `Run` (its `out`)."""
    out = getattr(run, "out", run)
    if out is None:
        raise ScenarioError("export_lerobot: a run without a folder (run with out=...)")
    return os.fspath(out)


def export_lerobot(runs: Union[PathLike, Iterable[Any], "pandas.DataFrame"], out: PathLike,
                   fps: int = 50, task: Optional[str] = None) -> "pandas.DataFrame":
    """Writes `runs` as a LeRobot v3.0 dataset into the new folder `out` (a folder
    that holds anything is refused): one episode per run, frames at `fps` (each the
    sample at or before its time; at most the runs' sample rate), every episode's task
    `task` (None: each run's scenario's name).

    `runs` is a run's or a sweep's folder, a `Run`, a list of them, or the DataFrame
    `sweep` or `read_sweep` returns (its runs in its rows' order). Returns a
    pandas.DataFrame, one row per episode: for a sweep's DataFrame, that DataFrame
    with `episode_index` added (which episode each run became); else `episode_index`,
    `run` (its folder), `frames`, `task` and `damaged_at_sample` (where a damaged
    record ended the episode, else None; a warning says so)."""
    import pandas

    sweep = runs if isinstance(runs, pandas.DataFrame) else None
    if sweep is not None:
        if "folder" not in sweep.columns or sweep["folder"].isna().any():
            raise ScenarioError("export_lerobot: the sweep's runs have no folders "
                                "(a sweep run with out=None keeps none)")
        folders = [os.fspath(f) for f in sweep["folder"]]
    elif isinstance(runs, (str, os.PathLike)) or hasattr(runs, "out"):
        folders = [_folder(runs)]
    else:
        folders = [_folder(r) for r in runs]
    if isinstance(fps, bool) or not isinstance(fps, int) or fps < 0 or fps > 0xFFFFFFFF:
        raise ScenarioError(f"export_lerobot: fps={fps!r}: give a whole number of frames per second")
    target = out_folder(out, "export_lerobot")
    episodes, said = _native.export_lerobot(folders, os.fspath(target), fps, task)
    for w in said:
        warnings.warn(w, stacklevel=2)
    if sweep is not None:
        df = sweep.copy()
        df["episode_index"] = range(len(df))
        return df
    return pandas.DataFrame({
        "episode_index": range(len(episodes)),
        "run": [os.fspath(Path(e[0])) for e in episodes],
        "frames": [e[1] for e in episodes],
        "task": [e[2] for e in episodes],
        "damaged_at_sample": [e[3] for e in episodes],
    })
