"""Tactile from Python: load a scenario, change it as `--set` does, check it, run it
in-process and read its report back, through the same libraries as the `tactile`
command (no subprocess, no second copy of the loop).

    import tactile
    sc = tactile.Scenario.shipped("paper")   # or Scenario.load("deploy/scenarios/paper.toml")
    sc = sc.with_set({"samples": 3000, "control.kind": "tdpa"})
    sc.check()                       # the command's errors, as ScenarioError
    run = tactile.run(sc, out="runs/a")
    run.summary["round_trip_ns"]["p50"]
    run.trace                        # pyarrow.Table, trace.parquet's columns
    df = tactile.sweep(sc, {"network.forward.delay_ms": [0, 10, 50],
                            "control.kind": ["none", "tdpa"]}, seeds=3)
    df = tactile.read_sweep("runs/wall")     # a finished sweep's folder, read back
    eps = tactile.export_lerobot(df, "datasets/wall", fps=50)  # a LeRobot v3.0 dataset

A run's folder is the command's: `tactile report` and every tool read it the same.
"""
from __future__ import annotations

from ._lerobot import export_lerobot
from ._loop import CallbackError, Operator, Predictor
from ._native import RunError, ScenarioError
from ._run import NoTraceWarning, Run, report, run
from ._scenario import Scenario
from ._sweep import Progress, read_sweep, sweep

__all__ = ["Scenario", "Run", "run", "sweep", "read_sweep", "report", "ScenarioError",
           "RunError", "CallbackError", "NoTraceWarning", "Operator", "Predictor",
           "Progress", "export_lerobot"]
