#!/usr/bin/env python3
"""Stand-ins for a haptic device's ROS 2 driver and a robot under ros2_control, on
rmw_zenoh's wire format, written only with eclipse-zenoh and rosbags (CDR from the
real ROS 2 message definitions, RIHS01 hashes computed by rosbags): an implementation
independent of Tactile's, for tests/ros2.rs.

  device: publishes sensor_msgs/JointState at 1 kHz along a trajectory (CSV of t and
          the driver's joint values), reads the WrenchStamped forces back; at set
          times publishes junk, or forged samples (another type hash, no or a short
          attachment, a joint named twice), then goes silent; with --humble on
          Humble's key (TypeHashNotSupported). Its clock starts at the first force.
  robot:  follows Float64MultiArray joint commands with first-order dynamics and
          publishes its JointState at 1 kHz.
  viewer: RViz started after the run began: once the run's /tf flows it waits, then
          subscribes to /robot_description and /tf_static as rmw_zenoh does for a
          transient-local subscription (an AdvancedSubscriber asking the publishers'
          caches for their history), and reads the tokens' QoS.
  arm:    an arm of any number of joints under ros2_control: follows a forward
          position controller's Float64MultiArray (the joints in order) or a
          joint_trajectory_controller's JointTrajectory (joints by name; the point
          reached over its time_from_start), first-order or simulated by MuJoCo
          (tests/mujoco_arm.py: its dynamics and a wall's contact), and publishes its
          JointState at 1 kHz with its joints in reverse order and a gripper joint
          among them; optionally a WrenchStamped in a named frame (MuJoCo's contact
          force on the tool, or a constant). Or, as MoveIt Servo or
          cartesian_controllers, takes PoseStamped targets and does its own IK
          (Pinocchio, tests/servo_ik.py).

Both declare rmw_zenoh's liveliness tokens, check every attachment they receive
(33 bytes: seq, timestamp, 16-byte gid), and write a JSON report on exit.
"""
import argparse
import json
import math
import os
import signal
import sys
import threading
import time

import numpy as np
import zenoh
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from zenoh.ext import Int64, z_deserialize, z_serialize

TS = get_typestore(Stores.ROS2_JAZZY)
TIMING = (
    "uint64 sample\nbool answered\nint64 round_trip_ns\nint64 overhead_ns\n"
    "uint32[3] delay_forward\nuint32[3] delay_backward\nuint32 flags_forward\n"
    "uint32 flags_backward\nuint32 flags_master\nfloat64[3] observer_master\n"
    "float64[3] observer_slave\n"
)
TS.register(get_types_from_msg(TIMING, "tactile_msgs/msg/SampleTiming"))

JOINT_STATE = "sensor_msgs/msg/JointState"
WRENCH = "geometry_msgs/msg/WrenchStamped"
ARRAY = "std_msgs/msg/Float64MultiArray"
TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
POSE = "geometry_msgs/msg/PoseStamped"
TF = "tf2_msgs/msg/TFMessage"
STRING = "std_msgs/msg/String"


def dds(ty):
    pkg, kind, name = ty.split("/")
    return f"{pkg}::{kind}::dds_::{name}_"


HUMBLE = "TypeHashNotSupported"  # Humble's rmw_zenoh: no type hashes


def key(domain, topic, ty, hash_=None):
    return f"{domain}/{topic.strip('/')}/{dds(ty)}/{hash_ or TS.hash_rihs01(ty)}"


def ty_of_key(k):
    """The ROS type of a data key expression, from its DDS name."""
    parts = k.split("/")
    pkg, kind, _, name = parts[-2].split("::")
    return f"{pkg}/{kind}/{name[:-1]}", "/" + "/".join(parts[1:-2])


class Node:
    """A Zenoh session as an rmw_zenoh node: tokens, publishers with attachments."""

    def __init__(self, name, listen, domain, tls=None):
        c = zenoh.Config()
        c.insert_json5("mode", '"peer"')
        c.insert_json5("scouting/multicast/enabled", "false")
        c.insert_json5("listen/endpoints", json.dumps(listen))
        if tls:  # mutual TLS as Zenoh's own configuration gives it: CA, certificate, key
            ca, cert, key = tls.split(",")
            t = "transport/link/tls"
            c.insert_json5(f"{t}/root_ca_certificate", json.dumps(ca))
            for side in ("listen", "connect"):
                c.insert_json5(f"{t}/{side}_certificate", json.dumps(cert))
                c.insert_json5(f"{t}/{side}_private_key", json.dumps(key))
            c.insert_json5(f"{t}/enable_mtls", "true")
        # No shared memory: Tactile's sessions have none, and a stand-in killed at the
        # end of a test would leave its segment in /dev/shm.
        c.insert_json5("transport/shared_memory/enabled", "false")
        self.s = zenoh.open(c)
        self.domain = domain
        self.name = name
        self.zid = str(self.s.zid())
        self.eid = 1
        self.tokens = [self.s.liveliness().declare_token(
            f"@ros2_lv/{domain}/{self.zid}/0/0/NN/%/%/{name}")]
        self.bad_attachments = []

    def token(self, kind, topic, ty, hash_=None):
        k = (f"@ros2_lv/{self.domain}/{self.zid}/0/{self.eid}/{kind}/%/%/{self.name}/"
             f"{topic.replace('/', '%')}/{dds(ty)}/{hash_ or TS.hash_rihs01(ty)}/::,10:,:,:,,")
        self.eid += 1
        self.tokens.append(self.s.liveliness().declare_token(k))

    def publisher(self, topic, ty, hash_=None):
        self.token("MP", topic, ty, hash_)
        pub = self.s.declare_publisher(key(self.domain, topic, ty, hash_))
        gid = bytes((self.eid * 7 + i) % 256 for i in range(16))
        seq = [0]

        def put(msg):
            seq[0] += 1
            att = z_serialize((Int64(seq[0]), Int64(time.time_ns()), gid))
            pub.put(bytes(TS.serialize_cdr(msg, ty)), attachment=att)

        return put

    def subscribe(self, topic, ty, on, sent=False):
        """Calls on(message, arrival time) for each sample, checking its attachment;
        with `sent`, on(message, arrival time, the publisher's send time in ns from its
        attachment, or None)."""
        self.token("MS", topic, ty)
        last = {}

        def cb(sample):
            stamp = self.check(str(sample.key_expr), sample.attachment, last)
            try:
                msg = TS.deserialize_cdr(sample.payload.to_bytes(), ty)
            except Exception as e:  # noqa: BLE001 - reported, never fatal
                self.bad_attachments.append(f"{topic}: undecodable payload: {e}")
                return
            if sent:
                on(msg, time.monotonic(), stamp)
            else:
                on(msg, time.monotonic())

        return self.s.declare_subscriber(f"{self.domain}/{topic.strip('/')}/{dds(ty)}/*", cb)

    def check(self, k, att, last):
        """rmw_zenoh's attachment: seq from 1 rising by one per publisher, a recent
        timestamp, a 16-byte gid. Returns its timestamp (ns), or None."""
        if att is None:
            self.bad_attachments.append(f"{k}: no attachment")
            return None
        raw = att.to_bytes()
        if len(raw) != 33:
            self.bad_attachments.append(f"{k}: attachment of {len(raw)} bytes")
            return None
        seq, stamp, gid = z_deserialize(tuple[Int64, Int64, bytes], att)
        seq, stamp = int(seq), int(stamp)
        if len(gid) != 16 or abs(stamp - time.time_ns()) > 5e9:
            self.bad_attachments.append(f"{k}: gid {gid.hex()} stamp {stamp}")
        prev = last.get(gid)
        if (prev is None and seq < 1) or (prev is not None and seq <= prev):
            self.bad_attachments.append(f"{k}: seq {seq} after {prev}")
        last[gid] = seq
        return stamp

    def tokens_seen(self):
        replies = self.s.liveliness().get("@ros2_lv/**", timeout=2.0)
        return sorted(str(r.ok.key_expr) for r in replies if r.ok is not None)


def check_tokens(tokens, domain):
    """Every token of a Tactile node parsed as rmw_zenoh's graph cache parses it:
    `@ros2_lv/<domain>/<zid>/<nid>/<eid>/<kind>/<enclave>/<ns>/<node>[/<topic>/<type>/
    <hash>/<qos>]`, the hash the one rosbags computes for the type. Returns the
    entities as [node, kind, topic, type] and the problems found."""
    entities, problems = [], []
    for t in tokens:
        f = t.split("/")
        if len(f) < 9 or not f[8].startswith("tactile_"):
            continue
        if f[0] != "@ros2_lv" or f[1] != str(domain) or not all(x for x in f):
            problems.append(f"{t}: malformed")
            continue
        if not (f[3].isdigit() and f[4].isdigit()) or f[6] != "%" or f[7] != "%":
            problems.append(f"{t}: ids, enclave or namespace")
        kind = f[5]
        if kind == "NN":
            if len(f) != 9 or f[3] != f[4]:
                problems.append(f"{t}: a node token")
            entities.append([f[8], kind, "", ""])
            continue
        if kind not in ("MP", "MS") or len(f) != 13:
            problems.append(f"{t}: an entity token")
            continue
        topic = f[9].replace("%", "/")
        pkg, k, dds_, name = f[10].split("::")
        ty = f"{pkg}/{k}/{name[:-1]}"
        if dds_ != "dds_" or not name.endswith("_"):
            problems.append(f"{t}: type name")
        elif f[11] != TS.hash_rihs01(ty):
            problems.append(f"{t}: hash {f[11]} is not rosbags' {TS.hash_rihs01(ty)}")
        if f[12] != "::,10:,:,:,,":
            problems.append(f"{t}: qos {f[12]}")
        entities.append([f[8], kind, topic, ty])
    return entities, problems


def stamp(ns):
    return TS.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)


def joint_state(names, values):
    Header = TS.types["std_msgs/msg/Header"]
    return TS.types[JOINT_STATE](
        header=Header(stamp=stamp(time.time_ns()), frame_id=""),
        name=list(names),
        position=np.array(values, dtype=np.float64),
        velocity=np.array([], dtype=np.float64),
        effort=np.array([], dtype=np.float64),
    )


def wrench_stamped(frame, force, torque=(0.0, 0.0, 0.0)):
    """A WrenchStamped now in `frame`: `force` and `torque`."""
    Header = TS.types["std_msgs/msg/Header"]
    V = TS.types["geometry_msgs/msg/Vector3"]
    return TS.types[WRENCH](
        header=Header(stamp=stamp(time.time_ns()), frame_id=frame),
        wrench=TS.types["geometry_msgs/msg/Wrench"](
            force=V(x=force[0], y=force[1], z=force[2]), torque=V(x=torque[0], y=torque[1], z=torque[2])))


def stopping():
    flag = threading.Event()
    for s in (signal.SIGTERM, signal.SIGINT):
        signal.signal(s, lambda *_: flag.set())
    return flag


def at_rate(hz, stop, until, step):
    """Calls step(t) every 1/hz s on an absolute schedule until step returns False,
    `until` seconds pass, or a signal."""
    t0 = time.monotonic()
    k = 0
    while not stop.is_set() and time.monotonic() - t0 < until:
        if step() is False:
            return
        k += 1
        delay = t0 + k / hz - time.monotonic()
        if delay > 0:
            time.sleep(delay)


def interpolate(rows, t):
    if t <= rows[0][0]:
        return rows[0][1:]
    for a, b in zip(rows, rows[1:]):
        if a[0] <= t <= b[0]:
            s = (t - a[0]) / (b[0] - a[0])
            return [x + s * (y - x) for x, y in zip(a[1:], b[1:])]
    return rows[-1][1:]


def device(a):
    node = Node("touch_standin", a.listen, a.domain, a.tls)
    rows = [[float(x) for x in line.split(",")] for line in open(a.trajectory)
            if line.strip() and not line.startswith("t")]
    names = a.names.split(",")
    publish_names = [a.extra_joint] + names[::-1]  # another order, one more joint
    put_joints = node.publisher(a.joint_topic, JOINT_STATE, HUMBLE if a.humble else None)
    raw_pub = node.s.declare_publisher(key(a.domain, a.joint_topic, JOINT_STATE))
    send_forged, forged = forger(node, a, raw_pub, names, publish_names)
    forces = []
    first = {}

    def on_force(msg, t):
        first.setdefault("t0", t)
        f = msg.wrench.force
        forces.append([t - first["t0"], f.x, f.y, f.z, msg.header.frame_id])

    sub = node.subscribe(a.force_topic, WRENCH, on_force)
    live = {}
    live_errors = []

    def on_live(sample):
        try:
            ty, topic = ty_of_key(str(sample.key_expr))
            TS.deserialize_cdr(sample.payload.to_bytes(), ty)
            live[topic] = live.get(topic, 0) + 1
        except Exception as e:  # noqa: BLE001
            live_errors.append(f"{sample.key_expr}: {e}")

    live_sub = node.s.declare_subscriber(f"{a.domain}/**", on_live) if a.live else None
    stop = stopping()
    junk = {"bytes": 0, "nan": 0, "missing": 0, "range": 0}
    state = {"tokens": [], "silent_from": None}

    def send_junk(kind):
        k = f"junk{junk[kind]}"
        if kind == "bytes":  # not CDR at all, with a valid attachment
            raw_pub.put(b"\x00\x01\x00\x00\xff\xff", attachment=z_serialize(
                (Int64(1), Int64(time.time_ns()), bytes(16))))
        elif kind == "nan":
            put_joints(joint_state(publish_names, [0.0, math.nan, 0.0, 0.0]))
        elif kind == "missing":
            put_joints(joint_state([a.extra_joint] + names[:2], [0.0, 0.0, 0.0]))
        else:  # a joint far outside any range: 1e6 driver units
            put_joints(joint_state(publish_names, [0.0, 0.0, 1e6, 0.0]))
        junk[kind] += 1
        return k

    def step():
        t0 = first.get("t0")
        t = 0.0 if t0 is None else time.monotonic() - t0
        if t0 is not None and t > a.end_after:
            return False
        if t0 is not None and not state["tokens"] and t > 0.5:
            state["tokens"] = node.tokens_seen()
        if t0 is not None and t >= a.silent_at:
            state["silent_from"] = state["silent_from"] or t
            return True
        if t0 is not None and a.junk_at <= t and sum(junk.values()) < 4 * a.junk_each:
            send_junk(["bytes", "nan", "missing", "range"][sum(junk.values()) % 4])
        values = interpolate(rows, t)
        if t0 is not None and send_forged(t, values):
            return True
        put_joints(joint_state(publish_names, [0.0] + list(values)[::-1]))
        return True

    at_rate(1000.0, stop, a.end_after + 60.0, step)
    time.sleep(0.2)
    entities, token_problems = check_tokens(state["tokens"], a.domain)
    report = {
        "entities": entities,
        "token_problems": token_problems,
        "forces": forces,
        "silent_from": state["silent_from"],
        "junk": junk,
        "forged": forged,
        "tokens": state["tokens"],
        "bad_attachments": node.bad_attachments,
        "live": live,
        "live_errors": live_errors[:20],
        "zid": node.zid,
    }
    del sub, live_sub
    with open(a.report, "w") as f:
        json.dump(report, f)
    node.s.close()


FORGED = ["hash", "noattach", "short", "dup"]


def forger(node, a, raw_pub, names, publish_names):
    """From --forge-at, --forge-each samples of each FORGED kind, the kinds 1.1 s
    apart (each the first dropped of its second in the node's log): JointStates whose
    first joint is 0.5 driver units off the trajectory, on another type hash's key (a
    valid attachment), on the right key without an attachment or with 20 bytes of
    one, or naming that joint twice, the wrong value first. After each, 15 ms without
    a good message, so a forged one taken would be the newest at a tick."""
    other = node.s.declare_publisher(key(a.domain, a.joint_topic, JOINT_STATE, "RIHS01_" + "0" * 64))
    forged = {k: 0 for k in FORGED}
    quiet = {"until": 0.0}

    def send(t, values):
        if t < quiet["until"]:
            return True
        k = int((t - a.forge_at) / 1.1) if t >= a.forge_at else len(FORGED)
        if k >= len(FORGED) or forged[FORGED[k]] >= a.forge_each:
            return False
        kind = FORGED[k]
        good = [0.0] + list(values)[::-1]  # publish_names' order: names[0] is last
        bad = good[:-1] + [good[-1] + 0.5]
        cdr = bytes(TS.serialize_cdr(joint_state(publish_names, bad), JOINT_STATE))
        att = z_serialize((Int64(1), Int64(time.time_ns()), bytes(16)))
        if kind == "hash":
            other.put(cdr, attachment=att)
        elif kind == "noattach":
            raw_pub.put(cdr)
        elif kind == "short":
            raw_pub.put(cdr, attachment=att.to_bytes()[:20])
        else:
            twice = joint_state([names[0]] + publish_names, [bad[-1]] + good)
            raw_pub.put(bytes(TS.serialize_cdr(twice, JOINT_STATE)), attachment=att)
        forged[kind] += 1
        quiet["until"] = t + 0.015
        return True

    return send, forged


def robot(a):
    node = Node("arm_standin", a.listen, a.domain)
    names = a.names.split(",")
    put = node.publisher(a.joint_topic, JOINT_STATE)
    cmd = {"value": None, "count": 0, "bad": 0, "t0": None, "after_silence": []}
    theta = [0.0, 0.0, 0.0]

    def on_cmd(msg, _t):
        data = list(msg.data)
        if len(data) != 3 or not all(math.isfinite(x) for x in data):
            cmd["bad"] += 1
            return
        cmd["value"] = data
        cmd["theta_at_last"] = list(theta)
        cmd["count"] += 1
        cmd["t0"] = cmd["t0"] or time.monotonic()
        cmd["last"] = time.monotonic()
        if time.monotonic() - cmd["t0"] >= a.silent_at:
            cmd["after_silence"].append(data)

    sub = node.subscribe(a.command_topic, ARRAY, on_cmd)
    stop = stopping()
    dt = 1e-3
    alpha = 1.0 - math.exp(-dt / a.tau)

    put_wrench = node.publisher(a.wrench_topic, WRENCH) if a.wrench_topic else None
    state = {"last_before": None}

    def step():
        if a.idle_exit and cmd["t0"] is not None and time.monotonic() - cmd["last"] > a.idle_exit:
            return False  # the run is over: commands stopped
        if cmd["value"] is not None:
            for i in range(3):
                theta[i] += alpha * (cmd["value"][i] - theta[i])
        if cmd["t0"] is not None and time.monotonic() - cmd["t0"] >= a.silent_at:
            return True
        state["last_before"] = cmd["value"]
        put(joint_state(["gripper"] + names, [0.0] + theta))
        if put_wrench:
            put_wrench(wrench_stamped("base", a.wrench))
        return True

    at_rate(1000.0, stop, a.duration, step)
    del sub
    with open(a.report, "w") as f:
        json.dump({"commands": cmd["count"], "bad_commands": cmd["bad"], "theta": theta,
                   "after_silence": cmd["after_silence"], "last_before": state["last_before"],
                   "last_command": cmd["value"], "theta_at_last": cmd.get("theta_at_last"),
                   "bad_attachments": node.bad_attachments}, f)
    node.s.close()


def arm(a):
    node = Node("arm_standin", a.listen, a.domain)
    names = a.names.split(",")
    n = len(names)
    q = [float(x) for x in a.initial.split(",")]
    if len(q) != n:
        sys.exit(f"--initial has {len(q)} values for {n} joints")
    put = node.publisher(a.joint_topic, JOINT_STATE)
    rep = {"commands": 0, "bad_commands": [], "first": None, "last": None,
           "max_step": [0.0] * n, "lowest": [math.inf] * n, "highest": [-math.inf] * n,
           "point_times": set(), "q_at_last": None, "t_last": None}
    target = {"q": None, "qd": [0.0] * n}

    def take(values):
        if len(values) != n or not all(math.isfinite(x) for x in values):
            rep["bad_commands"].append(list(values))
            return
        if rep["last"] is not None:
            # The reference's velocity, one command a period (the servo's feedforward).
            target["qd"] = [(v - w) / a.period for v, w in zip(values, rep["last"])]
            # The steps before this command (the last may be the end's hold, at the
            # joints measured, which a robot pressed into a wall lags its reference by).
            rep["max_step_before_last"] = list(rep["max_step"])
            rep["max_step"] = [max(m, abs(v - w)) for m, v, w in zip(rep["max_step"], values, rep["last"])]
        rep["lowest"] = [min(m, v) for m, v in zip(rep["lowest"], values)]
        rep["highest"] = [max(m, v) for m, v in zip(rep["highest"], values)]
        rep["first"] = rep["first"] or list(values)
        rep["last"] = list(values)
        rep["q_at_last"] = list(q)
        # MuJoCo's contact force when the command before the last came (the last may
        # be the end's hold, after which the robot relaxes).
        rep["force_before_last"] = rep.get("force_at_last")
        rep["force_at_last"] = target.get("force")
        rep["commands"] += 1
        rep["t_last"] = time.monotonic()
        target["q"] = list(values)

    def on_array(msg, _t):
        take(list(msg.data))

    def on_trajectory(msg, _t):
        if len(msg.points) != 1:
            rep["bad_commands"].append(f"{len(msg.points)} points")
            return
        pt = msg.points[0]
        by_name = dict(zip(msg.joint_names, pt.positions))
        if sorted(by_name) != sorted(names) or len(pt.positions) != len(msg.joint_names):
            rep["bad_commands"].append(f"joints {list(msg.joint_names)}")
            return
        rep["point_times"].add(pt.time_from_start.sec * 10**9 + pt.time_from_start.nanosec)
        take([by_name[j] for j in names])

    def on_pose(msg, _t, sent_ns):
        # Servo measures a command's age when it takes it. This stand-in, starved by a
        # suite that loads both cores, may take it 100 ms late; the age is measured at
        # the moment the sample left Tactile (its rmw attachment's stamp, on the same
        # clock), which is what the stamp promises. Without one, on arrival.
        why = servo.check(msg, sent_ns if sent_ns is not None else time.time_ns())
        if why:
            rep["bad_commands"].append(why)
            return
        p, o = msg.pose.position, msg.pose.orientation
        rep["poses"].append([p.x, p.y, p.z, o.x, o.y, o.z, o.w])
        take(servo.solve(target["q"] or q, msg))

    if a.command_type == "pose":
        from servo_ik import ServoIk  # beside this script
        servo = ServoIk(a.ik_urdf, names, a.tool, a.pose_frame)
        rep["poses"] = []
        sub = node.subscribe(a.command_topic, POSE, on_pose, sent=True)
    elif a.command_type == "trajectory":
        sub = node.subscribe(a.command_topic, TRAJECTORY, on_trajectory)
    else:
        sub = node.subscribe(a.command_topic, ARRAY, on_array)
    put_wrench = node.publisher(a.wrench_topic, WRENCH) if a.wrench_topic else None
    live = {"count": 0, "names": None, "q": None, "frames": set(), "errors": []}

    def on_live(sample):
        """The slave's live view: its joint states and the frames of its tool."""
        try:
            ty, topic = ty_of_key(str(sample.key_expr))
            msg = TS.deserialize_cdr(sample.payload.to_bytes(), ty)
        except Exception as e:  # noqa: BLE001 - reported, never fatal
            live["errors"].append(f"{sample.key_expr}: {e}")
            return
        if topic == "/slave/joint_states":
            live["count"] += 1
            live["names"], live["q"] = list(msg.name), list(msg.position)
        elif topic == "/slave/tool":
            live["frames"].add(msg.header.frame_id)

    live_sub = node.s.declare_subscriber(f"{a.domain}/slave/**", on_live) if a.live else None
    stop = stopping()
    alpha = 1.0 - math.exp(-1e-3 / a.tau)
    sim = None
    if a.mujoco:
        from mujoco_arm import MujocoArm  # beside this script
        sim = MujocoArm(a.mujoco, names, q, a.tool, a.wall_below)
        start = list(q)  # held until the first command, as a controller holds at start
        rep["tool0"] = sim.tool_position()
        rep["max_force"] = 0.0

    def step():
        if a.idle_exit and rep["t_last"] is not None and time.monotonic() - rep["t_last"] > a.idle_exit:
            return False
        if sim:
            if target["q"] is None:
                sim.step(start, [0.0] * n)
            else:
                # No command for two periods: the reference stands still.
                moving = time.monotonic() - rep["t_last"] < 2 * a.period
                sim.step(target["q"], target["qd"] if moving else [0.0] * n)
            q[:] = sim.q()
        elif target["q"] is not None:
            for i in range(n):
                q[i] += alpha * (target["q"][i] - q[i])
        put(joint_state(["gripper"] + names[::-1], [0.0] + q[::-1]))
        if put_wrench:
            force = a.wrench
            if sim:
                force = sim.force_in(a.wrench_frame)
                rep["max_force"] = max(rep["max_force"], math.hypot(*force))
                target["force"] = list(force)
            put_wrench(wrench_stamped(a.wrench_frame, force, a.torque))
        return True

    at_rate(1000.0, stop, a.duration, step)
    del sub, live_sub
    live["frames"] = sorted(live["frames"])
    rep["live"] = live
    rep["q"] = q
    if sim:
        rep["tool"] = sim.tool_position()
    if a.command_type == "pose":
        rep["tool"] = servo.tool(q)
        rep["ik_residual_max"] = servo.residual_max
    rep["point_times"] = sorted(rep["point_times"])
    if not rep["commands"]:
        rep["lowest"] = rep["highest"] = None  # no command: JSON has no infinity
    rep["bad_commands"] = rep["bad_commands"][:20]
    rep["bad_attachments"] = node.bad_attachments
    rep.pop("t_last")
    with open(a.report, "w") as f:
        json.dump(rep, f)
    node.s.close()


def viewer(a):
    node = Node("viewer_standin", a.listen, a.domain)
    rep = {"description": None, "static": [], "tf": 0, "tf_frames": set(), "qos": {},
           "errors": []}
    got = threading.Event()

    def decoded(sample, ty):
        try:
            return TS.deserialize_cdr(sample.payload.to_bytes(), ty)
        except Exception as e:  # noqa: BLE001 - reported, never fatal
            rep["errors"].append(f"{sample.key_expr}: {e}")
            return None

    def on_tf(sample):
        msg = decoded(sample, TF)
        if msg is not None:
            rep["tf"] += 1
            rep["tf_frames"].update(t.child_frame_id for t in msg.transforms)
            got.set()

    def on_description(sample):
        msg = decoded(sample, STRING)
        if msg is not None:
            rep["description"] = msg.data

    def on_static(sample):
        msg = decoded(sample, TF)
        if msg is not None:
            rep["static"] = sorted([t.header.frame_id, t.child_frame_id] for t in msg.transforms)

    tf_sub = node.s.declare_subscriber(f"{a.domain}/tf/{dds(TF)}/*", on_tf)
    if not got.wait(a.duration):
        rep["errors"].append("no /tf came")
    time.sleep(a.late)
    history = zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=1)
    latched = [
        zenoh.ext.declare_advanced_subscriber(
            node.s, f"{a.domain}/{topic}/{dds(ty)}/*", on, history=history,
            subscriber_detection=True)
        for topic, ty, on in [("robot_description", STRING, on_description),
                              ("tf_static", TF, on_static)]
    ]
    end = time.monotonic() + a.duration
    while time.monotonic() < end and (rep["description"] is None or not rep["static"]):
        time.sleep(0.05)
    for k in node.tokens_seen():
        parts = k.split("/")
        # @ros2_lv/domain/zid/nid/eid/kind/%/namespace/node/topic/type/hash/qos
        if len(parts) > 12 and parts[5] == "MP":
            rep["qos"][parts[9].replace("%", "/")] = parts[12]
    del tf_sub, latched
    rep["tf_frames"] = sorted(rep["tf_frames"])
    with open(a.report, "w") as f:
        json.dump(rep, f)
    node.s.close()


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="role", required=True)
    for role in ("device", "robot", "arm", "viewer"):
        q = sub.add_parser(role)
        q.add_argument("--listen", action="append", required=True)
        q.add_argument("--domain", type=int, default=0)
        q.add_argument("--names", required=True)
        q.add_argument("--joint-topic", required=True)
        q.add_argument("--report", required=True)
        q.add_argument("--tls", default="", help="CA,CERT,KEY (PEM): mutual TLS on tls/ endpoints")
    d = sub.choices["device"]
    d.add_argument("--force-topic", required=True)
    d.add_argument("--trajectory", required=True)
    d.add_argument("--extra-joint", default="yaw")
    d.add_argument("--junk-at", type=float, default=1e9)
    d.add_argument("--junk-each", type=int, default=0)
    d.add_argument("--silent-at", type=float, default=1e9)
    d.add_argument("--forge-at", type=float, default=1e9)
    d.add_argument("--forge-each", type=int, default=0)
    d.add_argument("--humble", action="store_true",
                   help="publish the joint states on Humble's key (TypeHashNotSupported)")
    d.add_argument("--end-after", type=float, required=True)
    d.add_argument("--live", action="store_true")
    r = sub.choices["robot"]
    r.add_argument("--command-topic", required=True)
    r.add_argument("--tau", type=float, default=0.02)
    r.add_argument("--duration", type=float, required=True)
    r.add_argument("--silent-at", type=float, default=1e9)
    r.add_argument("--idle-exit", type=float, default=0.0,
                   help="exit this many seconds after the last command (0: never)")
    r.add_argument("--wrench-topic", default="")
    r.add_argument("--wrench", type=float, nargs=3, default=[0.0, 0.0, 0.0])
    m = sub.choices["arm"]
    m.add_argument("--command-topic", required=True)
    m.add_argument("--command-type", choices=["positions", "trajectory", "pose"], default="positions")
    m.add_argument("--ik-urdf", default="", help="pose: the arm's URDF for the IK")
    m.add_argument("--pose-frame", default="", help="pose: the frame_id poses must have")
    m.add_argument("--initial", required=True, help="the joints' start, comma-separated")
    m.add_argument("--tau", type=float, default=0.02)
    m.add_argument("--period", type=float, default=1e-3, help="the commands' period, s")
    m.add_argument("--duration", type=float, required=True)
    m.add_argument("--idle-exit", type=float, default=0.0)
    m.add_argument("--wrench-topic", default="")
    m.add_argument("--wrench-frame", default="")
    m.add_argument("--wrench", type=float, nargs=3, default=[0.0, 0.0, 0.0])
    m.add_argument("--torque", type=float, nargs=3, default=[0.0, 0.0, 0.0])
    m.add_argument("--live", action="store_true", help="take the slave's live view")
    m.add_argument("--mujoco", default="", help="simulate the arm of this URDF in MuJoCo")
    m.add_argument("--tool", default="", help="the link whose contact force is measured")
    m.add_argument("--wall-below", type=float, default=1.0,
                   help="the wall's surface this far under the tool's start, m (MuJoCo)")
    v = sub.choices["viewer"]
    v.add_argument("--late", type=float, default=1.0,
                   help="seconds after the first /tf before subscribing to the latched topics")
    v.add_argument("--duration", type=float, default=30.0)
    a = p.parse_args()
    {"device": device, "robot": robot, "arm": arm, "viewer": viewer}[a.role](a)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    # Zenoh's threads can keep the interpreter from exiting: the report is written.
    os._exit(0)
