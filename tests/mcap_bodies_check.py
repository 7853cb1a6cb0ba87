#!/usr/bin/env python3
"""Independent check of how run.mcap draws a physics world's bodies (docs/16).

    python3 tests/mcap_bodies_check.py RUN_DIR --frame FRAME

RUN_DIR holds run.mcap, bodies.csv and scenario.toml (the report of a run with
`[environment] engine = "physics"`). Decoded with mcap_ros2 (not Tactile's code), the
scenario read with tomllib and mesh files with trimesh. Checks, each failure one line
on stderr and exit status 1:
  - every sample's /slave/bodies holds one marker of namespace `bodies` per moving
    body and one of namespace `tool`, in FRAME, each at the pose bodies.csv gives for
    that sample (within 1e-12), of the body's shape and size;
  - /slave/environment holds each static body at the scenario's pose, of its shape and
    size, in FRAME, and the task's target (a pose or insertion task) as a translucent
    sphere of its tolerance at the goal;
  - a mesh body is a TRIANGLE_LIST of its file's triangles, scaled.
Prints `checked N samples, M moving bodies, K static` on success.

Packages: mcap, mcap-ros2-support, numpy, trimesh (tests/requirements.txt).
"""

import argparse
import csv
import math
import os
import sys
import tomllib

import numpy as np
from mcap_ros2.reader import read_ros2_messages

CUBE, SPHERE, CYLINDER, TRIANGLE_LIST = 1, 2, 3, 11


def fail(msg):
    print(f"mcap_bodies_check: {msg}", file=sys.stderr)
    sys.exit(1)


def near(a, b, tol, what):
    if len(a) != len(b) or any(abs(x - y) > tol for x, y in zip(a, b)):
        fail(f"{what}: {list(a)} is not {list(b)}")


def shape_kind(shape):
    """The marker kind and scale a shape is drawn with (a capsule's middle part)."""
    t = shape["type"]
    if t == "box":
        return CUBE, [2 * h for h in shape["half_extents"]]
    if t == "sphere":
        return SPHERE, [2 * shape["radius"]] * 3
    if t in ("cylinder", "capsule"):
        d = 2 * shape["radius"]
        return CYLINDER, [d, d, 2 * shape["half_height"]]
    return TRIANGLE_LIST, [1.0, 1.0, 1.0]


def check_marker(m, shape, frame, pose, what, mesh_dir):
    if m.header.frame_id != frame:
        fail(f"{what}: in frame {m.header.frame_id}, not {frame}")
    kind, scale = shape_kind(shape)
    if m.type != kind:
        fail(f"{what}: a marker of type {m.type}, not {kind}")
    near([m.scale.x, m.scale.y, m.scale.z], scale, 1e-12, f"{what}'s size")
    p, q = m.pose.position, m.pose.orientation
    near([p.x, p.y, p.z], pose[:3], 1e-12, f"{what}'s position")
    near([q.x, q.y, q.z, q.w], pose[3:], 1e-12, f"{what}'s orientation")
    if kind == TRIANGLE_LIST and shape["type"] == "mesh":
        import trimesh

        path = shape["file"]
        if not os.path.isabs(path):
            path = os.path.join(mesh_dir, path)
        tm = trimesh.load(path, force="mesh", process=False)
        scale = shape.get("scale", 1.0)
        want = (np.asarray(tm.vertices)[np.asarray(tm.faces)].reshape(-1, 3)) * scale
        got = np.array([[v.x, v.y, v.z] for v in m.points])
        if got.shape != want.shape:
            fail(f"{what}: {len(got)} triangle corners, the file has {len(want)}")
        if np.max(np.abs(got - want)) > 1e-9:
            fail(f"{what}: its triangles are not the file's")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--frame", required=True)
    a = ap.parse_args()
    with open(os.path.join(a.run, "scenario.toml"), "rb") as f:
        scenario = tomllib.load(f)
    env = scenario["environment"]
    bodies = env.get("bodies", [])
    moving = [b for b in bodies if b.get("kind", "static") != "static"]
    static = [b for b in bodies if b.get("kind", "static") == "static"]
    tool = env.get("tool", {}).get("shape", {"type": "sphere", "radius": 0.005})
    mesh_dir = a.run

    rows = {}
    with open(os.path.join(a.run, "bodies.csv")) as f:
        for r in csv.DictReader(f):
            rows[(int(r["sample"]), r["body"])] = [
                float(r[k]) for k in ("x", "y", "z", "qx", "qy", "qz", "qw")
            ]
    samples = sorted({n for n, _ in rows})
    if not samples:
        fail("bodies.csv holds no sample")

    seen = 0
    env_seen = 0
    path = os.path.join(a.run, "run.mcap")
    with open(path, "rb") as f:
        for m in read_ros2_messages(
            f, topics=["/slave/bodies", "/slave/environment"]
        ):
            topic = m.channel.topic
            if topic == "/slave/environment":
                env_seen += 1
                markers = m.ros_msg.markers
                for k, b in enumerate(bodies):
                    if b.get("kind", "static") != "static":
                        continue
                    mine = [x for x in markers if x.ns == "bodies" and x.id == 3 * k]
                    if len(mine) != 1:
                        fail(f"static body {b['name']}: {len(mine)} markers")
                    pose = list(b.get("position", [0, 0, 0])) + list(
                        b.get("rotation", [0, 0, 0, 1])
                    )
                    check_marker(mine[0], b["shape"], a.frame, pose, b["name"], mesh_dir)
                task = scenario.get("task")
                if task and task["kind"] in ("pose", "insert"):
                    t = [x for x in markers if x.ns == "task"]
                    if len(t) != 1 or t[0].type != SPHERE or t[0].color.a >= 1.0:
                        fail("the task's target is not one translucent sphere")
                    if task["kind"] == "pose":
                        goal, r = task["position"], task["tolerance"]
                    else:
                        ax = np.array(task["axis"], float)
                        goal = list(np.array(task["mouth"]) + ax / np.linalg.norm(ax) * task["depth"])
                        r = task["radial_tolerance"]
                    p = t[0].pose.position
                    near([p.x, p.y, p.z], goal, 1e-12, "the target's position")
                    near([t[0].scale.x], [2 * r], 1e-12, "the target's size")
                continue
            # /slave/bodies: one message a sample, in the order of bodies.csv's.
            markers = m.ros_msg.markers
            n = samples[seen] if seen < len(samples) else None
            if n is None:
                fail("more /slave/bodies messages than samples in bodies.csv")
            seen += 1
            mine = [x for x in markers if x.ns == "tool"]
            if len(mine) != 1:
                fail(f"sample {n}: {len(mine)} tool markers")
            check_marker(mine[0], tool, a.frame, rows[(n, "tool")], f"sample {n}: tool", mesh_dir)
            for b in moving:
                k = bodies.index(b)
                mine = [x for x in markers if x.ns == "bodies" and x.id == 3 * k]
                if len(mine) != 1:
                    fail(f"sample {n}: body {b['name']} has {len(mine)} markers")
                key = (n, b["name"])
                if key not in rows:
                    continue  # recorded in turns: drawn where it last was
                check_marker(mine[0], b["shape"], a.frame, rows[key], f"sample {n}: {b['name']}", mesh_dir)
    if seen != len(samples):
        fail(f"{seen} /slave/bodies messages for {len(samples)} samples in bodies.csv")
    if env_seen == 0:
        fail("no /slave/environment")
    print(f"checked {seen} samples, {len(moving)} moving bodies, {len(static)} static")


if __name__ == "__main__":
    main()
