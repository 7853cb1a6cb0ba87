"""A LeRobot dataset written by `tactile export lerobot`, read by pyarrow and pandas
(tests/lerobot.rs): every column's type and length against meta/info.json, the
episodes' and tasks' tables as LeRobot reads them, stats.json against pandas' own
statistics, and each frame's values against the run's trace.csv (and joints.csv for a
URDF arm) at the sample at or before the frame, as float32.

    python3 lerobot_check.py DATASET FPS RUN...

RUN... are the episodes' run folders in episode order (each with its trace.csv).
Prints "lerobot ok: E episodes, F frames" and exits 0, or fails an assertion.
"""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

root, fps, runs = Path(sys.argv[1]), int(sys.argv[2]), [Path(p) for p in sys.argv[3:]]
info = json.loads((root / "meta/info.json").read_text())
assert info["codebase_version"] == "v3.0", info["codebase_version"]
assert info["fps"] == fps, info["fps"]
features = info["features"]

# Every data file, in order, as one table.
files = sorted((root / "data").glob("chunk-*/file-*.parquet"))
assert files, "no data file"
table = pa.concat_tables([pq.read_table(f) for f in files])
assert table.num_rows == info["total_frames"], (table.num_rows, info["total_frames"])
assert set(table.column_names) == set(features), (table.column_names, list(features))

# Each column's type and each vector's length against info.json.
arrow_of = {"float32": pa.float32(), "int64": pa.int64()}
for name, ft in features.items():
    col = table.column(name)
    want = arrow_of[ft["dtype"]]
    if ft["shape"] == [1]:
        assert col.type == want, (name, col.type)
        assert ft["names"] is None, name
    else:
        assert pa.types.is_list(col.type) and col.type.value_type == want, (name, col.type)
        lengths = pa.compute.list_value_length(col).to_numpy()
        assert (lengths == ft["shape"][0]).all(), (name, set(lengths))
        assert len(ft["names"]) == ft["shape"][0], name
        assert len(ft["info"]["units"]) == ft["shape"][0], name
    assert col.null_count == 0, name

df = table.to_pandas()
tasks = pd.read_parquet(root / "meta/tasks.parquet")
assert list(tasks["task_index"]) == list(range(len(tasks))), tasks
assert len(tasks) == info["total_tasks"]
episodes = pd.read_parquet(root / "meta/episodes")
assert len(episodes) == info["total_episodes"] == len(runs), (len(episodes), len(runs))
assert info["splits"] == {"train": f"0:{len(episodes)}"}

# The frames: indices consecutive, each episode's where its row says, timestamps k / fps.
assert (df["index"].to_numpy() == np.arange(len(df))).all()
for _, ep in episodes.iterrows():
    part = df[df["episode_index"] == ep["episode_index"]]
    assert len(part) == ep["length"], (ep["episode_index"], len(part), ep["length"])
    assert part["index"].iloc[0] == ep["dataset_from_index"]
    assert part["index"].iloc[-1] + 1 == ep["dataset_to_index"]
    assert (part["frame_index"].to_numpy() == np.arange(len(part))).all()
    want_t = (np.arange(len(part)) / fps).astype(np.float32)
    assert (part["timestamp"].to_numpy() == want_t).all(), ep["episode_index"]
    task = tasks.index[tasks["task_index"] == part["task_index"].iloc[0]][0]
    assert list(ep["tasks"]) == [task], (list(ep["tasks"]), task)


def matrix(frame, name):
    return np.stack(frame[name].to_numpy()).astype(np.float64)


# stats.json against pandas' and numpy's own (population std, as LeRobot's numpy).
stats = json.loads((root / "meta/stats.json").read_text())
assert set(stats) == set(features), (set(stats), set(features))
for name, ft in features.items():
    m = matrix(df, name) if ft["shape"] != [1] else df[[name]].to_numpy(np.float64)
    s = stats[name]
    assert s["count"] == [len(df)], (name, s["count"])
    for key, want in [
        ("min", m.min(0)),
        ("max", m.max(0)),
        ("mean", pd.DataFrame(m).mean().to_numpy()),
        ("std", pd.DataFrame(m).std(ddof=0).to_numpy()),
    ]:
        got = np.array(s[key])
        assert np.allclose(got, want, rtol=1e-9, atol=1e-9), (name, key, got, want)

# Values round-trip: each frame equals its sample's row of trace.csv (and joints.csv)
# as float32, the sample at or before the frame's time.
names = {k: features[k]["names"] for k in features if features[k]["shape"] != [1]}
checked = 0
for (_, ep), run in zip(episodes.iterrows(), runs):
    part = df[df["episode_index"] == ep["episode_index"]].reset_index(drop=True)
    trace = pd.read_csv(run / "trace.csv")
    scenario = (run / "scenario.toml").read_text()
    rate = float([l for l in scenario.splitlines() if l.startswith("rate_hz")][0].split("=")[1])
    joints = pd.read_csv(run / "joints.csv") if (run / "joints.csv").exists() else None
    # A sample whose slave did not step (its v(n) lost) has no slave columns: the
    # frame holds the slave's last values (zeros before its first step).
    slave = [f"{c}_{i}" for c in ("theta_sd", "theta_ref", "u", "h") for i in (1, 2, 3)]
    if joints is None:
        stepped = (trace[slave[:9]] != 0).any(axis=1)
    else:
        stepped = trace["n"].isin(joints["n"])
        joints = joints.set_index("n").reindex(trace["n"]).ffill().fillna(0.0).reset_index()
    trace[slave] = trace[slave].where(stepped).ffill().fillna(0.0)
    for k in range(len(part)):
        n = math.floor(k * rate / fps)
        row = trace.iloc[n]
        assert row["n"] == n
        state = part["observation.state"][k]
        force = part["observation.force"][k]
        net = part["observation.network"][k]
        want_state = [row[f"handle_{i}"] for i in (1, 2, 3)]
        want_force = [row[f"felt_{i}"] for i in (1, 2, 3)] + [row[f"h_{i}"] for i in (1, 2, 3)]
        if joints is None:
            want_q = [row[f"theta_sd_{i}"] for i in (1, 2, 3)]
            want_ref = [row[f"theta_ref_{i}"] for i in (1, 2, 3)]
            want_tau = [row[f"u_{i}"] for i in (1, 2, 3)]
        else:
            j = joints.iloc[n]
            dof = len(names["action"])
            want_q = [j[f"q_{i}"] for i in range(1, dof + 1)]
            want_ref = [j[f"q_ref_{i}"] for i in range(1, dof + 1)]
            want_tau = [j[f"tau_{i}"] for i in range(1, dof + 1)]
            want_force += [j[f"h_torque_{i}"] for i in (1, 2, 3)]
        assert list(state[:3]) == list(np.float32(want_state)), (k, state[:3], want_state)
        assert list(state[7:]) == list(np.float32(want_q)), (k, state[7:], want_q)
        assert list(part["action"][k]) == list(np.float32(want_ref)), k
        assert list(part["observation.effort"][k]) == list(np.float32(want_tau)), k
        assert list(force[: len(want_force)]) == list(np.float32(want_force)), (k, force, want_force)
        delay_f = max(row[f"delay_f_{i}"] for i in (1, 2, 3)) * 1e3 / rate
        delay_b = max(row[f"delay_b_{i}"] for i in (1, 2, 3)) * 1e3 / rate
        assert net[0] == np.float32(delay_f) and net[1] == np.float32(delay_b), (k, net)
        assert net[2] == int(row["flags_f"]) & 1 and net[3] == int(row["flags_b"]) & 1, (k, net)
        assert net[4] == (0.0 if row["received"] == 1 else 1.0), (k, net)
        assert net[5] == np.float32(row["round_trip_ns"] * 1e-6), (k, net)
        checked += 1

# Each episode's run and conditions, for tests/lerobot.rs to hold against the runs.
said = []
for _, ep in episodes.iterrows():
    def value(column):
        v = ep[column]
        return None if v is None or (isinstance(v, float) and math.isnan(v)) else v

    said.append(
        {
            "run": ep["tactile/run"],
            "tasks": list(ep["tasks"]),
            "swept": json.loads(ep["tactile/swept"]),
            "control": ep["tactile/control"],
            "delay_forward_ms": value("tactile/delay_forward_ms"),
            "loss_backward": value("tactile/loss_backward"),
            "task_success": None if value("tactile/task_success") is None else bool(ep["tactile/task_success"]),
            "completion_s": value("tactile/completion_s"),
            "damaged_at_sample": None if value("tactile/damaged_at_sample") is None else int(ep["tactile/damaged_at_sample"]),
        }
    )
print("episodes: " + json.dumps(said))
print(f"lerobot ok: {len(episodes)} episodes, {len(df)} frames, {checked} frames against the traces")
