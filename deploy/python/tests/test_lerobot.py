"""tactile.export_lerobot against the command's export: a sweep's DataFrame says which
episode each run became, the dataset equals `tactile export lerobot`'s file for
file, and bad input is the command's (ScenarioError, nothing written)."""
import json
import os
import subprocess
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import tactile

ROOT = Path(os.environ["TACTILE_ROOT"])
PAPER = ROOT / "deploy" / "scenarios" / "paper.toml"


def test_a_sweeps_runs_become_its_episodes_as_the_command_writes_them(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 120})
    df = tactile.sweep(sc, {"network.forward.delay_ms": [0, 20, 40]}, out=tmp_path / "s",
                       progress=False)
    eps = tactile.export_lerobot(df, tmp_path / "py", fps=20, task="track")
    assert list(eps["episode_index"]) == [0, 1, 2]
    assert list(eps["run"]) == list(df["run"])
    table = pq.read_table(tmp_path / "py" / "meta" / "episodes").to_pandas()
    assert [json.loads(s)["network.forward.delay_ms"] for s in table["tactile/swept"]] == \
        ["0", "20", "40"]
    assert list(table["length"]) == [24, 24, 24]
    assert [list(t) for t in table["tasks"]] == [["track"]] * 3
    # The command writes the same dataset from the sweep's folder.
    subprocess.run([os.environ["TACTILE_BIN"], "export", "lerobot", str(tmp_path / "s"),
                    "--out", str(tmp_path / "cmd"), "--fps", "20", "--task", "track"],
                   check=True, capture_output=True)
    for f in ["meta/info.json", "meta/stats.json"]:
        assert (tmp_path / "py" / f).read_text() == (tmp_path / "cmd" / f).read_text(), f
    data = "data/chunk-000/file-000.parquet"
    assert pq.read_table(tmp_path / "py" / data).equals(pq.read_table(tmp_path / "cmd" / data))


def test_a_run_exports_and_bad_input_is_refused(tmp_path):
    sc = tactile.Scenario.load(PAPER).with_set({"samples": 50})
    run = tactile.run(sc, out=tmp_path / "r")
    eps = tactile.export_lerobot(run, tmp_path / "ds", fps=100)
    assert list(eps["frames"]) == [50]
    assert eps["damaged_at_sample"].isna().all()
    with pytest.raises(tactile.ScenarioError, match="not empty"):
        tactile.export_lerobot(run, tmp_path / "ds", fps=100)
    with pytest.raises(tactile.ScenarioError, match="above"):
        tactile.export_lerobot([tmp_path / "r"], tmp_path / "fast", fps=1000)
    with pytest.raises(tactile.ScenarioError, match="--fps 0"):
        tactile.export_lerobot(tmp_path / "r", tmp_path / "none", fps=0)
    with pytest.raises(tactile.ScenarioError, match="no master.rec"):
        tactile.export_lerobot(tmp_path, tmp_path / "none", fps=10)
    assert not (tmp_path / "fast").exists() and not (tmp_path / "none").exists()
    assert not list(tmp_path.glob(".*.partial"))
