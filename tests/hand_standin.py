#!/usr/bin/env python3
"""Stand-ins for 6-DoF haptic devices' ROS 2 drivers on rmw_zenoh's wire format,
written with eclipse-zenoh and rosbags only (tests/ros2_standin.py's node; the
omni_msgs types registered from their .msg text), for tests/hand.rs.

  touch: an omni_common driver (a Geomagic Touch): sensor_msgs/JointState of its six
         joints (waist, shoulder, elbow, yaw, pitch, roll) at 1 kHz along a
         trajectory (CSV: t, the six joints, the grey button), the grey button as
         omni_msgs/OmniButtonEvent sent only when it changes, and the force taken back
         as omni_msgs/OmniFeedback.
  fd:    a Force Dimension driver (ICube's forcedimension_ros2): the handle as
         geometry_msgs/PoseStamped in fd_base at 1 kHz along a trajectory (CSV: t, x,
         y, z, qx, qy, qz, qw, clutch), the clutch as std_msgs/Bool at 1 kHz, and the
         force taken back as the effort controller's std_msgs/Float64MultiArray.

The trajectory's clock starts at the first force received (the loop running). Each
writes a JSON report: the forces received (t, fx, fy, fz), when each row was first
published, and the tokens Tactile's node declared, checked as rmw_zenoh parses them.
"""
import argparse
import json
import os
import sys
import time

import numpy as np
from rosbags.typesys import get_types_from_msg

import ros2_standin as rs  # beside this script

TS = rs.TS
TS.register(get_types_from_msg("int32 grey_button\nint32 white_button\n",
                               "omni_msgs/msg/OmniButtonEvent"))
TS.register(get_types_from_msg("geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 position\n",
                               "omni_msgs/msg/OmniFeedback"))
BUTTON = "omni_msgs/msg/OmniButtonEvent"
FEEDBACK = "omni_msgs/msg/OmniFeedback"
BOOL = "std_msgs/msg/Bool"
TOUCH_JOINTS = ["waist", "shoulder", "elbow", "yaw", "pitch", "roll"]


def rows_of(path):
    return [[float(x) for x in line.split(",")] for line in open(path)
            if line.strip() and not line.startswith("t")]


def held(rows, t):
    """The last row at or before t (a button, a clutch: no interpolation)."""
    last = rows[0]
    for r in rows:
        if r[0] > t:
            break
        last = r
    return last


def pose_stamped(frame, p, q):
    Header = TS.types["std_msgs/msg/Header"]
    return TS.types[rs.POSE](
        header=Header(stamp=rs.stamp(time.time_ns()), frame_id=frame),
        pose=TS.types["geometry_msgs/msg/Pose"](
            position=TS.types["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=p[2]),
            orientation=TS.types["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])))


def run(a, publish, force_topic, force_type, force_of):
    """Publishes along the trajectory at 1 kHz from the first force on; records the
    forces; writes the report."""
    node = rs.Node(a.name, a.listen, a.domain)
    rows = rows_of(a.trajectory)
    put = publish(node)
    forces, first = [], {}

    def on_force(msg, t):
        first.setdefault("t0", t)
        forces.append([t - first["t0"]] + force_of(msg))

    sub = node.subscribe(force_topic, force_type, on_force)
    stop = rs.stopping()
    state = {"tokens": []}

    def step():
        t0 = first.get("t0")
        t = 0.0 if t0 is None else time.monotonic() - t0
        if t0 is not None and t > a.end_after:
            return False
        if t0 is not None and not state["tokens"] and t > 0.5:
            state["tokens"] = node.tokens_seen()
        put(rows, t)
        return True

    rs.at_rate(1000.0, stop, a.end_after + 60.0, step)
    time.sleep(0.2)
    entities, problems = rs.check_tokens(state["tokens"], a.domain)
    report = {"forces": forces, "entities": entities, "token_problems": problems,
              "bad_attachments": node.bad_attachments}
    del sub
    with open(a.report, "w") as f:
        json.dump(report, f)
    node.s.close()


def touch(a):
    def publish(node):
        joints = node.publisher(a.joint_topic, rs.JOINT_STATE)
        button = node.publisher(a.button_topic, BUTTON)
        last = {"grey": None}

        def put(rows, t):
            values = rs.interpolate(rows, t)[:6]
            # The driver's own order, and another joint a message may carry.
            joints(rs.joint_state(TOUCH_JOINTS[::-1] + ["gripper"], values[::-1] + [0.0]))
            grey = int(held(rows, t)[7])
            if grey != last["grey"] and (last["grey"] is not None or grey):
                button(TS.types[BUTTON](grey_button=grey, white_button=0))
            last["grey"] = grey
        return put

    def force_of(msg):
        return [msg.force.x, msg.force.y, msg.force.z]

    run(a, publish, a.force_topic, FEEDBACK, force_of)


def fd(a):
    def publish(node):
        pose = node.publisher(a.pose_topic, rs.POSE)
        clutch = node.publisher(a.clutch_topic, BOOL)

        def put(rows, t):
            v = rs.interpolate(rows, t)
            q = np.array(v[3:7])
            pose(pose_stamped("fd_base", v[:3], list(q / np.linalg.norm(q))))
            clutch(TS.types[BOOL](data=bool(held(rows, t)[8])))
        return put

    def force_of(msg):
        return list(msg.data)

    run(a, publish, a.force_topic, rs.ARRAY, force_of)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="role", required=True)
    for role in ("touch", "fd"):
        q = sub.add_parser(role)
        q.add_argument("--listen", action="append", required=True)
        q.add_argument("--domain", type=int, default=0)
        q.add_argument("--trajectory", required=True)
        q.add_argument("--force-topic", required=True)
        q.add_argument("--end-after", type=float, required=True)
        q.add_argument("--report", required=True)
    t = sub.choices["touch"]
    t.add_argument("--joint-topic", default="/phantom/joint_states")
    t.add_argument("--button-topic", default="/phantom/button")
    f = sub.choices["fd"]
    f.add_argument("--pose-topic", default="/fd/ee_pose")
    f.add_argument("--clutch-topic", default="/fd/fd_clutch")
    a = p.parse_args()
    a.name = {"touch": "omni_state", "fd": "fd_standin"}[a.role]
    {"touch": touch, "fd": fd}[a.role](a)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
