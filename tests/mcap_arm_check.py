#!/usr/bin/env python3
"""Independent check of how run.mcap draws a URDF slave arm ([slave.arm]).

    python3 tests/mcap_arm_check.py RUN_DIR --base LINK --tip LINK

RUN_DIR holds run.mcap and joints.csv (the report of a run with [slave.arm]). Decoded
with mcap_ros2 (not Tactile's code), the URDF read by yourdfpy (its own parser and
forward kinematics). Checks, each failure one line on stderr and exit status 1:
  - /robot_description parses and holds the master's tool and every link of the arm;
  - /tf_static has one transform per fixed joint of that URDF (plus the mount of the
    robot in the world), each equal to yourdfpy's;
  - at every sample, /slave/joint_states names the chain's joints and its positions are
    joints.csv's q columns exactly;
  - at samples spread over the run, composing /tf_static and that sample's /tf from the
    world to the tip equals yourdfpy's FK at the sample's joint states within 1e-9 m
    and 1e-9 rad, and so does the master's tool;
  - /slave/tool, in the base frame, is the tip's position yourdfpy gives within 1e-9 m;
  - the environment markers are in the base frame.
With --handles-only: /master/handle's orientation is joints.csv's master_rot at every
sample: a rotation (norm within 1e-6 of one), normalized within 1e-12 of what the
slave took (equal to the master's at zero delay), and nothing else.

Packages: as tests/mcap_check.py (mcap, mcap-ros2-support, yourdfpy, numpy).
"""

import argparse
import csv
import io
import os
import sys

import numpy as np
import yourdfpy
from mcap_ros2.reader import read_ros2_messages


def fail(msg):
    print(f"mcap_arm_check: {msg}", file=sys.stderr)
    sys.exit(1)


def matrix(t):
    """A geometry_msgs TransformStamped as a 4x4 matrix."""
    t = t.transform
    x, y, z, w = t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = [t.translation.x, t.translation.y, t.translation.z]
    return m


def compose(edges, frame, root="world"):
    """frame in root, walking the child -> (parent, transform) map up."""
    m = np.eye(4)
    for _ in range(len(edges) + 1):
        if frame == root:
            return m
        if frame not in edges:
            fail(f"no transform has {frame} as its child")
        parent, t = edges[frame]
        m = t @ m
        frame = parent
    fail("the transforms loop")


def close(a, b, what):
    dp = np.linalg.norm(a[:3, 3] - b[:3, 3])
    dr = np.linalg.norm(a[:3, :3] - b[:3, :3])
    if dp > 1e-9 or dr > 1e-9:
        fail(f"{what}: differ by {dp:.3g} m, {dr:.3g} in rotation")


def check_handles(run, msgs):
    """A 6-DoF master's orientation: /master/handle turns as joints.csv's master_rot
    (the rotation the slave took; equal to the master's at zero delay) at every
    sample. Returns how many were turned."""
    with open(os.path.join(run, "joints.csv")) as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    rcols = [header.index(f"master_rot_{c}") for c in "xyzw"]
    handles = msgs["/master/handle"]
    if len(handles) != len(rows):
        fail(f"{len(handles)} handles, {len(rows)} joints.csv rows")
    turned = 0
    for k, (h, row) in enumerate(zip(handles, rows)):
        o = h.pose.orientation
        want = [float(row[c]) for c in rcols]
        got = np.array([o.x, o.y, o.z, o.w])
        if abs(np.linalg.norm(got) - 1.0) > 1e-6:
            fail(f"sample {k}: /master/handle's orientation {got} is not a rotation")
        # The slave normalizes what it takes: equal, normalized, to rounding.
        if np.abs(got / np.linalg.norm(got) - want).max() > 1e-12:
            fail(f"sample {k}: /master/handle turned {[o.x, o.y, o.z, o.w]}, joints.csv says {want}")
        turned += want != [0.0, 0.0, 0.0, 1.0]
    return turned


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--base", required=True)
    ap.add_argument("--tip", required=True)
    ap.add_argument("--handles-only", action="store_true",
                    help="check only the handle's orientation against joints.csv")
    a = ap.parse_args()
    msgs = {}
    for m in read_ros2_messages(os.path.join(a.run, "run.mcap")):
        msgs.setdefault(m.channel.topic, []).append(m.ros_msg)
    if a.handles_only:
        print(f"mcap_arm_check: {check_handles(a.run, msgs)} handles turned")
        return
    desc = msgs["/robot_description"]
    if len(desc) != 1:
        fail(f"{len(desc)} /robot_description messages, not 1")
    urdf = yourdfpy.URDF.load(io.StringIO(desc[0].data), load_meshes=False, build_scene_graph=True)
    links = set(urdf.link_map)
    for need in ["world", "master_tool", a.base, a.tip]:
        if need not in links:
            fail(f"/robot_description has no link {need}")
    static = {t.child_frame_id: (t.header.frame_id, matrix(t)) for t in msgs["/tf_static"][0].transforms}
    fixed = [j for j in urdf.robot.joints if j.type == "fixed"]
    if sorted(static) != sorted(j.child for j in fixed):
        fail(f"/tf_static children {sorted(static)} are not the URDF's fixed joints' {sorted(j.child for j in fixed)}")
    for j in fixed:
        if static[j.child][0] != j.parent:
            fail(f"/tf_static: {j.child}'s parent is {static[j.child][0]}, the URDF says {j.parent}")
        close(static[j.child][1], j.origin, f"/tf_static {j.parent} -> {j.child}")
    with open(os.path.join(a.run, "joints.csv")) as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    qcols = [k for k, h in enumerate(header) if h.startswith("q_") and not h.startswith("q_ref")]
    states, tfs, tools = msgs["/slave/joint_states"], msgs["/tf"], msgs["/slave/tool"]
    masters = msgs["/master/joint_states"]
    if not (len(states) == len(tfs) == len(tools) == len(rows)):
        fail(f"{len(states)} joint states, {len(tfs)} /tf, {len(tools)} tools, {len(rows)} joints.csv rows")
    names = states[0].name
    if len(names) != len(qcols):
        fail(f"/slave/joint_states names {len(names)} joints, joints.csv has {len(qcols)}")
    for k, (js, row) in enumerate(zip(states, rows)):
        if list(js.name) != list(names):
            fail(f"sample {k}: joint names changed")
        want = [float(row[c]) for c in qcols]
        if list(js.position) != want:
            fail(f"sample {k}: joint positions {list(js.position)} are not joints.csv's {want}")
    spread = sorted(set(list(range(0, len(rows), max(1, len(rows) // 40))) + [len(rows) - 1]))
    for k in spread:
        # yourdfpy updates only the joints whose value is not np.isclose to the one it
        # holds (atol 1e-8): a joint at 1e-10 rad from the last would stay where it
        # was. Half a radian away first, so every joint takes its value.
        cfg = dict(zip(names, states[k].position))
        cfg.update(zip(masters[k].name, masters[k].position))
        urdf.update_cfg({n: q + 0.5 for n, q in cfg.items()})
        urdf.update_cfg(cfg)
        edges = dict(static)
        edges.update({t.child_frame_id: (t.header.frame_id, matrix(t)) for t in tfs[k].transforms})
        for link in [a.tip, "master_tool"]:
            close(compose(edges, link), urdf.get_transform(link, "world"), f"sample {k}: world -> {link}")
        tip_in_base = urdf.get_transform(a.tip, a.base)[:3, 3]
        p = tools[k].pose.position
        if tools[k].header.frame_id != a.base:
            fail(f"sample {k}: /slave/tool in {tools[k].header.frame_id}, not {a.base}")
        d = np.linalg.norm(tip_in_base - [p.x, p.y, p.z])
        if d > 1e-9:
            fail(f"sample {k}: /slave/tool is {d:.3g} m from the URDF's tip")
    for arr in msgs.get("/slave/environment", []):
        for mk in arr.markers:
            if mk.header.frame_id != a.base:
                fail(f"an environment marker is in {mk.header.frame_id}, not {a.base}")
    print(f"mcap_arm_check: {len(rows)} samples, {len(spread)} drawn and compared, {len(fixed)} fixed joints")


if __name__ == "__main__":
    main()
