"""Type stubs of tactile._native, the package's compiled half (deploy/python/src/lib.rs)."""
from pathlib import Path
from typing import Any, Callable, List, Optional, Tuple

PAPER_SCENARIO: str
MAX_SCENARIO_BYTES: int

class ScenarioError(ValueError):
    """A scenario, a --set or an input the command would refuse (exit status 2)."""

class RunError(RuntimeError):
    """A run or a report that failed (exit status 1)."""

def read_scenario(path: str) -> Tuple[str, Path, str]: ...
def check(text: str, base_dir: str, name: str, path: Optional[str],
          sets: List[str]) -> Tuple[str, List[str]]: ...
def check_sets(text: str, base_dir: str, name: str, path: Optional[str],
               sets: List[str]) -> None: ...
def sweep_grid(sets: List[str]) -> Tuple[List[Tuple[str, bool, List[str]]], List[List[int]]]: ...
def run(text: str, base_dir: str, name: str, path: Optional[str], sets: List[str],
        out: str, trace_format: Optional[str],
        operator: Optional[Callable[[int, float, float, float, float], Tuple[float, float, float]]],
        backward_predictor: Optional[Callable[[int, int, bytes], Tuple[float, float, float]]],
        forward_predictor: Optional[Callable[[int, int, bytes], Tuple[float, float, float]]]) -> None: ...
def report(dirs: List[str], out: Optional[str], trace_format: str) -> Path: ...
def export_lerobot(runs: List[str], out: str, fps: int, task: Optional[str]
                   ) -> Tuple[List[Tuple[Path, int, str, Optional[int]]], List[str]]: ...
def sweep(text: str, base_dir: str, name: str, path: Optional[str], sets: List[str],
          swept: List[str], seeds: int, jobs: Optional[int], out: str, trace: bool,
          trace_format: str, resume: bool,
          progress: Optional[Callable[[int, int, str, str], Any]]) -> int: ...
