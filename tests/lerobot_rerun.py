"""A LeRobot dataset written by `tactile export lerobot`, opened by the Rerun SDK's
own LeRobot importer (the one `rerun DATASET` uses), its recording saved to an .rrd
and read back with Rerun's chunk reader (tests/lerobot.rs): one recording per
episode, every feature with one row per frame on the `frame_index` timeline, its
entries named as info.json names them, its values pyarrow's.

    python3 lerobot_rerun.py DATASET RRD

Prints "rerun ok: E episodes, F frames" and exits 0, or fails an assertion.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import rerun as rr
from rerun.chunk import RrdReader

root, rrd = Path(sys.argv[1]), sys.argv[2]
info = json.loads((root / "meta/info.json").read_text())
vectors = [k for k, ft in info["features"].items() if ft["shape"] != [1]]
data = pq.read_table(root / "data").to_pandas()

rr.init("tactile_lerobot_check", spawn=False)
rr.save(rrd)
rr.log_file_from_path(root)
rr.disconnect()

reader = RrdReader(rrd)
episodes = {}
for store in reader.recordings():
    if not store.recording_id.startswith("episode_"):
        continue
    k = int(store.recording_id.removeprefix("episode_"))
    found = {}
    for chunk in reader.stream(store=store):
        b = chunk.to_record_batch()
        cols = b.schema.names
        name = chunk.entity_path.lstrip("/")
        if "SeriesLines:names" in cols:
            got = b.column(cols.index("SeriesLines:names"))[0].as_py()
            assert got == info["features"][name]["names"], (name, got)
        if "Scalars:scalars" in cols:
            frames = b.column(cols.index("frame_index")).to_pylist()
            values = b.column(cols.index("Scalars:scalars")).to_pylist()
            for f, v in zip(frames, values):
                found.setdefault(name, {})[f] = v
    episodes[k] = found

assert sorted(episodes) == list(range(info["total_episodes"])), sorted(episodes)
frames = 0
for k, found in episodes.items():
    part = data[data["episode_index"] == k].reset_index(drop=True)
    assert set(found) == set(vectors), (k, set(found), vectors)
    for name in vectors:
        assert sorted(found[name]) == list(range(len(part))), (k, name, len(found[name]))
        want = np.stack(part[name].to_numpy()).astype(np.float64)
        got = np.array([found[name][f] for f in range(len(part))])
        assert (got == want).all(), (k, name)
    frames += len(part)
assert frames == info["total_frames"], (frames, info["total_frames"])
print(f"rerun ok: {len(episodes)} episodes, {frames} frames")
