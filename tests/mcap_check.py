#!/usr/bin/env python3
"""Independent check of the run.mcap that `tactile report` writes beside trace.csv.

    python3 tests/mcap_check.py RUN_DIR [--fk JSON] [--tool-tol METRES]

RUN_DIR holds run.mcap, trace.csv and scenario.toml. --fk is a JSON list of
{"theta": [t1, t2, t3], "xyz": [x, y, z]}: joint angles and the tool position the Rust
kernels' forward kinematics gives for them; the URDF in /robot_description must give the
same position (within 1e-9 m) through the URDF library's own forward kinematics, for both
arms. --tool-tol bounds |FK(theta_sd) - trace tool| for the slave (default 1e-3 m: the
trace's tool comes from the run's arithmetic, which may be the hybrid fixed-point one).

What it checks (the file's spec is docs of issue 20; each failure prints one clear line
on stderr and exits with status 1):
  - the file reads with mcap's reader (CRCs validated), is chunked with lz4 (or zstd), has message
    indexes, chunk indexes, statistics and summary offsets; the header's profile is ros2;
  - exactly the spec's channels, each with message encoding cdr and a ros2msg schema of
    the spec's type, whose text is the rosbag2 concatenation (main type, then
    "MSG: pkg/Type" parts) with every dependency present;
  - the standard types' definitions in the file have the fields of rosbags' ROS 2 Jazzy
    definitions (names, types, array lengths; constants, where given, equal too), and
    tactile_msgs/msg/SampleTiming has the spec's fields;
  - every message decodes with mcap_ros2 and, independently, with rosbags (a typestore
    built from the file's schema texts only), and the two decodings are equal field by
    field;
  - the statistics' counts equal the messages read; per-sample channels have one message
    per trace.csv row, /robot_description and /tf_static one, /slave/environment one at
    the first sample and at every sample n with n % rate_hz == 0;
  - log time - first log time == t_master_tick of the row; header stamps == log time;
  - values equal the trace exactly (==, the trace's floats are shortest round-trip):
    joint positions and efforts, target/handle/tool positions (orientation identity),
    h/q/felt forces (torque zero), every SampleTiming field; joint velocities equal the
    backward difference / t_s within 1e-9 relative; frames as the spec says;
  - /tf + /tf_static: composing base -> link1 -> upper_arm -> elbow -> forearm -> tool
    gives the paper's FK of the row's joint angles within 1e-9 m (both arms), and the
    slave's equals trace tool_1..3 within --tool-tol;
  - /slave/environment: one marker per scenario object (plane: thin CUBE, sphere: SPHERE
    at the centre with diameter 2 r, box: CUBE at the centre with size 2 half_extents);
  - /robot_description parses with yourdfpy; its static transforms equal /tf_static; its
    FK equals the paper's FK at the first, middle and last row and the --fk positions.

Python packages (pinned, as CI installs them):
  pip install mcap==1.6.0 mcap-ros2-support==0.6.0 rosbags==0.11.9 \
      lxml==6.1.3 six==1.17.0 trimesh==5.2.0
  pip install --no-deps yourdfpy==0.0.60
(yourdfpy's declared dependency trimesh[easy] pulls scipy, shapely, ...; it needs only
trimesh's core, lxml and six to load a URDF without meshes and do forward kinematics.)
Needs Python >= 3.11 (tomllib).
"""

import argparse
import csv
import io
import json
import math
import os
import re
import sys

try:
    import tomllib

    import yourdfpy
    from mcap.reader import make_reader
    from mcap.records import Chunk
    from mcap.stream_reader import StreamReader
    from mcap_ros2.decoder import DecoderFactory
    from rosbags.interfaces import Nodetype
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
except ImportError as e:  # pragma: no cover
    print(f"mcap-check: FAIL: missing Python module ({e}); install the packages listed at "
          "the top of tests/mcap_check.py", file=sys.stderr)
    sys.exit(1)


class CheckFailed(Exception):
    pass


def fail(msg):
    raise CheckFailed(msg)


# Device geometry, metres: the scenario's `device` (set by set_geometry), the paper's
# lengths until then.
PRESETS = {
    "paper": (0.132, 0.132, 0.025, 0.035),
    "omni": (0.135, 0.135, 0.025, 0.035),
}
L1, L2, L3, A = PRESETS["paper"]
L4 = L1 + A


def set_geometry(device):
    """Takes the lengths of the scenario's `device`: a preset name or a table."""
    global L1, L2, L3, A, L4
    if isinstance(device, str):
        if device not in PRESETS:
            fail(f"scenario device {device!r} is not a preset this checker knows")
        L1, L2, L3, A = PRESETS[device]
    else:
        L1, L2, L3, A = (float(device[k]) for k in ("l1", "l2", "l3", "a"))
    L4 = L1 + A

ARMS = ("master", "slave")
FK_TOL = 1e-9
VEL_REL_TOL = 1e-9

TYPES = {
    "/robot_description": "std_msgs/msg/String",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/master/joint_states": "sensor_msgs/msg/JointState",
    "/slave/joint_states": "sensor_msgs/msg/JointState",
    "/master/target": "geometry_msgs/msg/PoseStamped",
    "/master/handle": "geometry_msgs/msg/PoseStamped",
    "/slave/tool": "geometry_msgs/msg/PoseStamped",
    "/slave/force": "geometry_msgs/msg/WrenchStamped",
    "/master/force": "geometry_msgs/msg/WrenchStamped",
    "/master/felt": "geometry_msgs/msg/WrenchStamped",
    "/slave/environment": "visualization_msgs/msg/MarkerArray",
    "/tactile/timing": "tactile_msgs/msg/SampleTiming",
    # A physics world's bodies: none in the analytic scenes this script reads
    # (tests/mcap_bodies_check.py reads a physics run's).
    "/slave/bodies": "visualization_msgs/msg/MarkerArray",
}
ONCE = ("/robot_description", "/tf_static")
NONE = ("/slave/bodies",)
PER_SAMPLE = tuple(t for t in TYPES
                   if t not in ONCE and t not in NONE and t != "/slave/environment")

SAMPLE_TIMING = "tactile_msgs/msg/SampleTiming"
SAMPLE_TIMING_MSG = """uint64 sample
bool answered
int64 round_trip_ns
int64 overhead_ns
uint32[3] delay_forward
uint32[3] delay_backward
uint32 flags_forward
uint32 flags_backward
uint32 flags_master
float64[3] observer_master
float64[3] observer_slave
"""

# Marker constants (visualization_msgs/msg/Marker).
CUBE, SPHERE, ADD = 1, 2, 0


# ---------------------------------------------------------------------------------------
# Small helpers


def same(a, b):
    """Exact equality of plain values, NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


def first_difference(a, b, path=""):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a:
            if k not in b:
                return f"{path}.{k}: missing in one"
            d = first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{path}: lengths {len(a)} and {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if same(a, b) else f"{path}: {a!r} != {b!r}"


def xyz(d):
    return [d["x"], d["y"], d["z"]]


def paper_fk(t1, t2, t3):
    return [
        -math.sin(t1) * (L2 * math.sin(t3) + L1 * math.cos(t2)),
        -L2 * math.cos(t3) + L1 * math.sin(t2) + L3,
        L2 * math.cos(t1) * math.sin(t3) + L1 * math.cos(t1) * math.cos(t2) - L4,
    ]


def max_diff(a, b):
    return max(abs(x - y) for x, y in zip(a, b))


def quat_matrix(q):
    x, y, z, w = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def apply(transform, p):
    """p in the child frame -> p in the parent frame."""
    r = quat_matrix(transform[0])
    t = transform[1]
    return [sum(r[i][j] * p[j] for j in range(3)) + t[i] for i in range(3)]


def plain_tf(tf, where):
    rot = tf["transform"]["rotation"]
    q = [rot["x"], rot["y"], rot["z"], rot["w"]]
    norm = math.sqrt(sum(c * c for c in q))
    if abs(norm - 1.0) > 1e-9:
        fail(f"{where}: transform {tf['header']['frame_id']} -> {tf['child_frame_id']} has "
             f"a quaternion of norm {norm!r}, not 1")
    return (q, xyz(tf["transform"]["translation"]))


# ---------------------------------------------------------------------------------------
# Schemas: parse the rosbag2 concatenation, compare with rosbags' Jazzy definitions


SEPARATOR = re.compile(r"^={80}[ \t\r]*$", re.M)


def full_name(short):
    """pkg/Type -> pkg/msg/Type."""
    parts = short.strip().split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return short.strip()


def parse_schema_text(name, text):
    """The ros2msg text -> {typename: (consts, fields)} as rosbags parses each part."""
    parts = SEPARATOR.split(text)
    types = {}
    for i, part in enumerate(parts):
        if i == 0:
            typename, body = name, part
        else:
            body = part.lstrip("\r\n")
            head, _, body = body.partition("\n")
            if not head.startswith("MSG: "):
                fail(f"schema {name}: dependency part {i} does not start with 'MSG: pkg/Type' "
                     f"(starts with {head[:40]!r})")
            short = head[len("MSG: "):].strip()
            if "/msg/" in short:
                fail(f"schema {name}: dependency header 'MSG: {short}' should name the type "
                     "without /msg/ (rosbag2 way)")
            typename = full_name(short)
        if typename in types:
            fail(f"schema {name}: type {typename} is defined twice")
        try:
            parsed = get_types_from_msg(body, typename)
        except Exception as e:
            fail(f"schema {name}: rosbags cannot parse the part for {typename}: {e}")
        types.update(parsed)
    for typename, (_, fields) in types.items():
        for fname, desc in fields:
            for ref in referenced_types(desc):
                if ref not in types:
                    fail(f"schema {name}: {typename}.{fname} uses {ref}, which the schema text "
                         "does not define (missing 'MSG: ...' part)")
    return types


def referenced_types(desc):
    nodetype, detail = desc
    if nodetype == Nodetype.NAME:
        return [detail]
    if nodetype in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return referenced_types(detail[0])
    return []


def compare_with_reference(schema_name, types, jazzy, timing_ref):
    for typename, (consts, fields) in types.items():
        if typename == SAMPLE_TIMING:
            ref_consts, ref_fields = timing_ref
        elif typename in jazzy.fielddefs:
            ref_consts, ref_fields = jazzy.fielddefs[typename]
        else:
            fail(f"schema {schema_name}: type {typename} is neither a ROS 2 Jazzy type nor "
                 f"{SAMPLE_TIMING}")
        if list(fields) != list(ref_fields):
            got = [(f, fmt_desc(d)) for f, d in fields]
            want = [(f, fmt_desc(d)) for f, d in ref_fields]
            fail(f"schema {schema_name}: {typename} has fields {got}, ROS 2 Jazzy's "
                 f"(rosbags) are {want}")
        ref = {c[0]: c for c in ref_consts}
        for c in consts:
            if ref.get(c[0]) != c:
                fail(f"schema {schema_name}: {typename} constant {c} differs from the "
                     f"reference {ref.get(c[0])}")


def fmt_desc(desc):
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        return detail[0] + (f"<={detail[1]}" if detail[1] else "")
    if nodetype == Nodetype.NAME:
        return detail
    inner = fmt_desc(detail[0])
    if nodetype == Nodetype.ARRAY:
        return f"{inner}[{detail[1]}]"
    return f"{inner}[]" if not detail[1] else f"{inner}[<={detail[1]}]"


# ---------------------------------------------------------------------------------------
# Decoded objects -> plain Python values, walking the rosbags field definitions


def plain(obj, typename, fielddefs):
    _, fields = fielddefs[typename]
    return {name: plain_field(getattr(obj, name), desc, fielddefs) for name, desc in fields}


def plain_field(value, desc, fielddefs):
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        return plain_base(value, detail[0])
    if nodetype == Nodetype.NAME:
        return plain(value, detail, fielddefs)
    return [plain_field(v, detail[0], fielddefs) for v in value]


def plain_base(value, basetype):
    if basetype == "string" or basetype == "wstring":
        return str(value)
    if basetype == "bool":
        return bool(value)
    if basetype.startswith("float"):
        return float(value)
    return int(value)


# ---------------------------------------------------------------------------------------
# The run


class Trace:
    def __init__(self, path):
        try:
            with open(path, newline="") as f:
                reader = csv.reader(f)
                self.columns = next(reader)
                self.rows = [r for r in reader if r]
        except (OSError, StopIteration) as e:
            fail(f"cannot read {path}: {e}")
        self.index = {c: i for i, c in enumerate(self.columns)}
        if not self.rows:
            fail(f"{path} has no rows")
        for i, r in enumerate(self.rows):
            if len(r) != len(self.columns):
                fail(f"{path}: row {i} has {len(r)} cells, the header {len(self.columns)}")

    def col(self, name):
        if name not in self.index:
            fail(f"trace.csv has no column {name}")
        return self.index[name]

    def f(self, k, name):
        return float(self.rows[k][self.col(name)])

    def i(self, k, name):
        return int(self.rows[k][self.col(name)])

    def f3(self, k, name):
        return [self.f(k, f"{name}_{a}") for a in (1, 2, 3)]

    def i3(self, k, name):
        return [self.i(k, f"{name}_{a}") for a in (1, 2, 3)]


def load_urdf(text):
    try:
        robot = yourdfpy.URDF.load(io.BytesIO(text.encode()), build_scene_graph=True,
                                   load_meshes=False, build_collision_scene_graph=False)
    except Exception as e:
        fail(f"/robot_description: yourdfpy cannot parse the URDF: {e}")
    if robot.robot.name != "tactile":
        fail(f"/robot_description: robot name {robot.robot.name!r}, expected 'tactile'")
    joints = {j.name: j for j in robot.robot.joints}
    links = {l.name for l in robot.robot.links}
    if "world" not in links:
        fail("/robot_description: no link 'world'")
    for arm in ARMS:
        for link in ("base", "link1", "upper_arm", "elbow", "forearm", "tool"):
            if f"{arm}_{link}" not in links:
                fail(f"/robot_description: no link {arm}_{link}")
        for j in ("joint1", "joint2", "elbow_joint", "joint3", "tool_joint"):
            if f"{arm}_{j}" not in joints:
                fail(f"/robot_description: no joint {arm}_{j}")
        mimic = joints[f"{arm}_elbow_joint"].mimic
        if mimic is None or mimic.joint != f"{arm}_joint2" or mimic.multiplier != -1.0:
            fail(f"/robot_description: {arm}_elbow_joint should mimic {arm}_joint2 with "
                 f"multiplier -1 (has {mimic})")
        actuated = set(robot.actuated_joint_names)
        for j in ("joint1", "joint2", "joint3"):
            if f"{arm}_{j}" not in actuated:
                fail(f"/robot_description: {arm}_{j} is not an actuated joint")
    return robot


def urdf_tool(robot, arm, theta):
    """Tool position in the arm's base by yourdfpy's own FK. yourdfpy handles the mimic
    joint itself: update_cfg() re-evaluates every mimic joint from the joint it mimics,
    so only the three actuated joints are set here."""
    robot.update_cfg({f"{arm}_joint{i + 1}": float(theta[i]) for i in range(3)})
    m = robot.get_transform(frame_to=f"{arm}_tool", frame_from=f"{arm}_base")
    return [float(m[0][3]), float(m[1][3]), float(m[2][3])]


def urdf_pose(robot, parent, child):
    m = robot.get_transform(frame_to=child, frame_from=parent)
    return [[float(m[i][j]) for j in range(4)] for i in range(4)]


def check_file_structure(path, compression="lz4"):
    counts = {}
    compressions = set()
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, emit_chunks=True, validate_crcs=True).records:
                name = type(record).__name__
                counts[name] = counts.get(name, 0) + 1
                if isinstance(record, Chunk):
                    compressions.add(record.compression)
        except Exception as e:
            fail(f"run.mcap: not a readable MCAP file (record stream): {e}")
    for name in ("Header", "Chunk", "MessageIndex", "ChunkIndex", "Statistics", "SummaryOffset",
                 "DataEnd", "Footer"):
        if not counts.get(name):
            fail(f"run.mcap: has no {name} record (chunked, indexed, with statistics and "
                 f"summary offsets expected); records: {counts}")
    if counts.get("Message"):
        fail(f"run.mcap: {counts['Message']} messages are outside chunks")
    if compressions != {compression}:
        fail(f"run.mcap: chunk compressions {sorted(compressions)}, expected {compression} only")


def run(args):
    run_dir = args.run_dir
    mcap_path = os.path.join(run_dir, "run.mcap")
    trace = Trace(os.path.join(run_dir, "trace.csv"))
    try:
        with open(os.path.join(run_dir, "scenario.toml"), "rb") as f:
            scenario = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        fail(f"cannot read scenario.toml: {e}")
    rate_hz = float(scenario["rate_hz"])
    set_geometry(scenario.get("device", "paper"))
    t_s = 1.0 / rate_hz
    objects = scenario.get("environment", {}).get("objects", [])
    try:
        fk_configs = json.loads(args.fk) if args.fk else []
        for c in fk_configs:
            if len(c["theta"]) != 3 or len(c["xyz"]) != 3:
                raise ValueError("theta and xyz need three values each")
    except (ValueError, KeyError, TypeError) as e:
        fail(f"--fk: not a JSON list of {{\"theta\": [..3], \"xyz\": [..3]}}: {e}")
    rows = len(trace.rows)
    if scenario.get("mode", "realtime") == "lockstep":
        # Lockstep: log times are nominal, n t_s (as the writer computes it in f64).
        t_s_ns = (1.0 / rate_hz) * 1e9
        nominal = [int(trace.i(k, "n") * t_s_ns) for k in range(rows)]
        ticks = [t - nominal[0] for t in nominal]
    else:
        ticks = [trace.i(k, "t_master_tick") for k in range(rows)]
    env_rows = [k for k in range(rows) if k == 0 or trace.i(k, "n") % rate_hz == 0]

    check_file_structure(mcap_path, args.compression)

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    timing_ref = get_types_from_msg(SAMPLE_TIMING_MSG, SAMPLE_TIMING)[SAMPLE_TIMING]
    factory = DecoderFactory()

    f = open(mcap_path, "rb")
    try:
        reader = make_reader(f, validate_crcs=True)
        header = reader.get_header()
        if header.profile != "ros2":
            fail(f"run.mcap: header profile {header.profile!r}, expected 'ros2'")
        if not header.library.startswith("tactile"):
            fail(f"run.mcap: header library {header.library!r}, expected 'tactile <version>'")
        summary = reader.get_summary()
        if summary is None:
            fail("run.mcap: no summary section")
        if summary.statistics is None:
            fail("run.mcap: the summary has no statistics")
        if not summary.chunk_indexes:
            fail("run.mcap: the summary has no chunk indexes")

        # Channels and schemas.
        by_topic = {}
        for ch in summary.channels.values():
            if ch.topic in by_topic:
                fail(f"run.mcap: two channels for topic {ch.topic}")
            by_topic[ch.topic] = ch
        if set(by_topic) != set(TYPES):
            fail(f"run.mcap: channels {sorted(by_topic)}; expected exactly {sorted(TYPES)} "
                 f"(missing {sorted(set(TYPES) - set(by_topic))}, extra "
                 f"{sorted(set(by_topic) - set(TYPES))})")
        decoders = {}   # channel id -> (mcap_ros2 decoder, rosbags typestore, typename)
        for topic, ch in by_topic.items():
            schema = summary.schemas.get(ch.schema_id)
            if schema is None:
                fail(f"{topic}: no schema (schema id {ch.schema_id})")
            if ch.message_encoding != "cdr":
                fail(f"{topic}: message encoding {ch.message_encoding!r}, expected 'cdr'")
            if schema.encoding != "ros2msg":
                fail(f"{topic}: schema encoding {schema.encoding!r}, expected 'ros2msg'")
            if schema.name != TYPES[topic]:
                fail(f"{topic}: schema {schema.name!r}, expected {TYPES[topic]!r}")
            try:
                text = schema.data.decode("utf-8")
            except UnicodeDecodeError as e:
                fail(f"{topic}: schema text is not UTF-8: {e}")
            types = parse_schema_text(schema.name, text)
            compare_with_reference(schema.name, types, jazzy, timing_ref)
            store = get_typestore(Stores.EMPTY)
            try:
                store.register(types)
            except Exception as e:
                fail(f"{topic}: rosbags cannot register the schema's types: {e}")
            try:
                decoder = factory.decoder_for(ch.message_encoding, schema)
            except Exception as e:
                fail(f"{topic}: mcap_ros2 cannot build a decoder from the schema: {e}")
            if decoder is None:
                fail(f"{topic}: mcap_ros2 has no decoder for this channel")
            decoders[ch.id] = (decoder, store, schema.name)

        # Counts, from the statistics first (checked against the messages read below).
        for topic, ch in by_topic.items():
            want = (1 if topic in ONCE else len(env_rows) if topic == "/slave/environment"
                    else 0 if topic in NONE else rows)
            got = summary.statistics.channel_message_counts.get(ch.id, 0)
            if got != want:
                what = ("" if topic in ONCE else " (first sample and every n % rate_hz == 0)"
                        if topic == "/slave/environment" else " (one per trace.csv row)")
                fail(f"{topic}: {got} messages, expected {want}{what}")

        # The one-off messages first: the URDF and the static transforms.
        once = {}
        for topic in ONCE:
            msgs = [decode(m, ch, decoders) for _, ch, m in
                    reader.iter_messages(topics=[topic], log_time_order=True)]
            if len(msgs) != 1:
                fail(f"{topic}: {len(msgs)} messages, expected 1")
            once[topic] = msgs[0]
        robot = load_urdf(once["/robot_description"][1]["data"])
        static = {}
        expected_static = {("world", "master_base"), ("world", "slave_base"),
                           ("master_forearm", "master_tool"), ("slave_forearm", "slave_tool")}
        log0, tfs = once["/tf_static"]
        for tf in tfs["transforms"]:
            check_stamp(tf["header"], log0, "/tf_static")
            static[(tf["header"]["frame_id"], tf["child_frame_id"])] = plain_tf(tf, "/tf_static")
        if set(static) != expected_static or len(tfs["transforms"]) != 4:
            fail(f"/tf_static: transforms {sorted(static)}, expected {sorted(expected_static)}")
        for (parent, child), tf in static.items():
            m = urdf_pose(robot, parent, child)
            r = quat_matrix(tf[0])
            d = max(max_diff([m[i][3] for i in range(3)], tf[1]),
                    max(max_diff(m[i][:3], r[i]) for i in range(3)))
            if d > FK_TOL:
                fail(f"/tf_static: {parent} -> {child} differs from the URDF's by {d:.3g}")

        # The URDF's FK against the kernels' (--fk) and the paper's.
        for c in fk_configs:
            for arm in ARMS:
                got = urdf_tool(robot, arm, c["theta"])
                if max_diff(got, c["xyz"]) > FK_TOL:
                    fail(f"/robot_description: yourdfpy FK of {arm}_tool at theta "
                         f"{c['theta']} is {got}, the kernels' FK {c['xyz']} "
                         f"(differ by {max_diff(got, c['xyz']):.3g} m)")
        for k in sorted({0, rows // 2, rows - 1}):
            for arm, col in (("master", "theta_md"), ("slave", "theta_sd")):
                th = trace.f3(k, col)
                got, want = urdf_tool(robot, arm, th), paper_fk(*th)
                if max_diff(got, want) > FK_TOL:
                    fail(f"/robot_description: yourdfpy FK of {arm}_tool at row {k} "
                         f"{th} is {got}, the paper's FK {want}")

        # Every message, in log-time order.
        state = Checks(trace, ticks, rate_hz, t_s, objects, static, args.tool_tol, env_rows)
        total = 0
        per_channel = {}
        first_log = None
        for _, ch, m in reader.iter_messages(log_time_order=True):
            total += 1
            per_channel[ch.id] = per_channel.get(ch.id, 0) + 1
            if first_log is None:
                first_log = m.log_time
            if ch.topic in ONCE:
                continue
            state.message(ch.topic, decode(m, ch, decoders))
        if first_log != log0 or once["/robot_description"][0] != log0:
            fail("run.mcap: /robot_description and /tf_static should be logged at the first "
                 "sample's time (the file's first log time)")
        state.finish(first_log)

        stats = summary.statistics
        if stats.message_count != total:
            fail(f"statistics: message_count {stats.message_count}, {total} messages read")
        for cid, n in per_channel.items():
            if stats.channel_message_counts.get(cid) != n:
                fail(f"statistics: channel {cid} count {stats.channel_message_counts.get(cid)}, "
                     f"{n} messages read")
        if stats.channel_count != len(by_topic):
            fail(f"statistics: channel_count {stats.channel_count}, {len(by_topic)} channels")
        if stats.message_start_time != first_log or stats.message_end_time != state.last_log:
            fail(f"statistics: message times {stats.message_start_time}..{stats.message_end_time}"
                 f", messages from {first_log} to {state.last_log}")
    finally:
        f.close()
    skipped = f", {state.tool_skipped} rows without slave data" if state.tool_skipped else ""
    print(f"mcap-check: {len(by_topic)} channels, {total} messages, all decoded, values "
          f"equal the trace ({rows} rows, slave tool within {state.tool_max:.2g} m of the "
          f"trace{skipped})")


def decode(m, ch, decoders):
    decoder, store, typename = decoders[ch.id]
    try:
        a = decoder(m.data)
    except Exception as e:
        fail(f"{ch.topic}: mcap_ros2 cannot decode the message logged at {m.log_time}: {e}")
    try:
        b = store.deserialize_cdr(m.data, typename)
    except Exception as e:
        fail(f"{ch.topic}: rosbags cannot decode the message logged at {m.log_time}: {e}")
    pa = plain(a, typename, store.fielddefs)
    pb = plain(b, typename, store.fielddefs)
    d = first_difference(pa, pb)
    if d:
        fail(f"{ch.topic}: mcap_ros2 and rosbags decode the message logged at {m.log_time} "
             f"differently: {d}")
    return (m.log_time, pb)


def check_stamp(header, log_time, where):
    st = header["stamp"]
    if not 0 <= st["nanosec"] < 1_000_000_000:
        fail(f"{where}: header stamp nanosec {st['nanosec']} out of range")
    if st["sec"] * 1_000_000_000 + st["nanosec"] != log_time:
        fail(f"{where}: header stamp {st['sec']}.{st['nanosec']:09d} != log time {log_time}")


class Checks:
    """Per-topic checks of the streamed messages against the trace's rows."""

    def __init__(self, trace, ticks, rate_hz, t_s, objects, static, tool_tol, env_rows):
        self.trace = trace
        self.ticks = ticks
        self.rate_hz = rate_hz
        self.t_s = t_s
        self.objects = objects
        self.static = static
        self.tool_tol = tool_tol
        self.env_rows = env_rows
        self.count = {t: 0 for t in TYPES}
        self.logs = {t: [] for t in TYPES}
        self.tool_max = 0.0
        self.tool_skipped = 0
        self.last_log = None

    def message(self, topic, decoded):
        log_time, msg = decoded
        self.last_log = log_time
        k = self.count[topic]
        self.count[topic] += 1
        self.logs[topic].append(log_time)
        if topic in NONE:
            fail(f"{topic}: a message in an analytic scene's recording")
        if topic == "/slave/environment":
            if k >= len(self.env_rows):
                fail(f"/slave/environment: more than the {len(self.env_rows)} messages expected")
            self.environment(self.env_rows[k], log_time, msg)
            return
        if k >= len(self.trace.rows):
            fail(f"{topic}: more messages than the {len(self.trace.rows)} trace rows")
        where = f"{topic} message {k} (trace row n={self.trace.rows[k][self.trace.col('n')]})"
        getattr(self, "t_" + topic.strip("/").replace("/", "_"))(k, log_time, msg, where)

    def finish(self, first_log):
        for topic in TYPES:
            if topic in ONCE or topic in NONE:
                continue
            want = len(self.env_rows) if topic == "/slave/environment" else len(self.trace.rows)
            if self.count[topic] != want:
                fail(f"{topic}: {self.count[topic]} messages, expected {want}")
            rows = self.env_rows if topic == "/slave/environment" else range(len(self.trace.rows))
            for k, log_time in zip(rows, self.logs[topic]):
                if log_time - first_log != self.ticks[k]:
                    fail(f"{topic}: the message for trace row {k} is logged at first + "
                         f"{log_time - first_log} ns, t_master_tick is {self.ticks[k]}")

    # --- per topic ---

    def equal3(self, got, want, what, where):
        for a, (g, w) in enumerate(zip(got, want)):
            if not same(float(g), w):
                fail(f"{where}: {what}[{a}] = {g!r}, trace {w!r}")

    def joints(self, arm, col, eff, k, log_time, msg, where):
        check_stamp(msg["header"], log_time, where)
        names = [f"{arm}_joint{i}" for i in (1, 2, 3)]
        if msg["name"] != names:
            fail(f"{where}: names {msg['name']}, expected {names}")
        for field in ("position", "velocity", "effort"):
            if len(msg[field]) != 3:
                fail(f"{where}: {field} has {len(msg[field])} values, expected 3")
        th = self.trace.f3(k, col)
        self.equal3(msg["position"], th, "position", where)
        self.equal3(msg["effort"], self.trace.f3(k, eff), "effort", where)
        if k == 0:
            want = [0.0, 0.0, 0.0]
            self.equal3(msg["velocity"], want, "velocity", where)
        else:
            prev = self.trace.f3(k - 1, col)
            for a in range(3):
                want = (th[a] - prev[a]) / self.t_s
                got = msg["velocity"][a]
                if abs(got - want) > VEL_REL_TOL * max(abs(got), abs(want)):
                    fail(f"{where}: velocity[{a}] = {got!r}, backward difference "
                         f"(theta(n) - theta(n-1)) / t_s = {want!r}")

    def t_master_joint_states(self, k, log_time, msg, where):
        self.joints("master", "theta_md", "tau", k, log_time, msg, where)

    def t_slave_joint_states(self, k, log_time, msg, where):
        self.joints("slave", "theta_sd", "u", k, log_time, msg, where)

    def pose(self, frame, col, k, log_time, msg, where):
        check_stamp(msg["header"], log_time, where)
        if msg["header"]["frame_id"] != frame:
            fail(f"{where}: frame {msg['header']['frame_id']!r}, expected {frame!r}")
        self.equal3(xyz(msg["pose"]["position"]), self.trace.f3(k, col), "position", where)
        o = msg["pose"]["orientation"]
        if [o["x"], o["y"], o["z"], o["w"]] != [0.0, 0.0, 0.0, 1.0]:
            fail(f"{where}: orientation {o}, expected (0, 0, 0, 1)")

    def t_master_target(self, k, log_time, msg, where):
        self.pose("master_base", "target", k, log_time, msg, where)

    def t_master_handle(self, k, log_time, msg, where):
        self.pose("master_base", "handle", k, log_time, msg, where)

    def t_slave_tool(self, k, log_time, msg, where):
        self.pose("slave_base", "tool", k, log_time, msg, where)

    def wrench(self, frame, col, k, log_time, msg, where):
        check_stamp(msg["header"], log_time, where)
        if msg["header"]["frame_id"] != frame:
            fail(f"{where}: frame {msg['header']['frame_id']!r}, expected {frame!r}")
        self.equal3(xyz(msg["wrench"]["force"]), self.trace.f3(k, col), "force", where)
        if xyz(msg["wrench"]["torque"]) != [0.0, 0.0, 0.0]:
            fail(f"{where}: torque {msg['wrench']['torque']}, expected zero")

    def t_slave_force(self, k, log_time, msg, where):
        self.wrench("slave_base", "h", k, log_time, msg, where)

    def t_master_force(self, k, log_time, msg, where):
        self.wrench("master_base", "q", k, log_time, msg, where)

    def t_master_felt(self, k, log_time, msg, where):
        self.wrench("master_base", "felt", k, log_time, msg, where)

    def t_tactile_timing(self, k, log_time, msg, where):
        tr = self.trace
        want = {
            "sample": tr.i(k, "n"),
            "answered": tr.i(k, "received") != 0,
            "round_trip_ns": tr.i(k, "round_trip_ns"),
            "overhead_ns": tr.i(k, "overhead_ns"),
            "delay_forward": tr.i3(k, "delay_f"),
            "delay_backward": tr.i3(k, "delay_b"),
            "flags_forward": tr.i(k, "flags_f"),
            "flags_backward": tr.i(k, "flags_b"),
            "flags_master": tr.i(k, "flags_m"),
            "observer_master": tr.f3(k, "observer_m"),
            "observer_slave": tr.f3(k, "observer_s"),
        }
        d = first_difference(msg, want)
        if d:
            fail(f"{where}: differs from the trace: {d}")

    def t_tf(self, k, log_time, msg, where):
        chain = ("base", "link1", "upper_arm", "elbow", "forearm")
        expected = {(f"{arm}_{a}", f"{arm}_{b}") for arm in ARMS for a, b in zip(chain, chain[1:])}
        tfs = {}
        for tf in msg["transforms"]:
            check_stamp(tf["header"], log_time, where)
            tfs[(tf["header"]["frame_id"], tf["child_frame_id"])] = plain_tf(tf, where)
        if set(tfs) != expected or len(msg["transforms"]) != len(expected):
            fail(f"{where}: transforms {sorted(tfs)}, expected {sorted(expected)}")
        for arm, col in (("master", "theta_md"), ("slave", "theta_sd")):
            p = [0.0, 0.0, 0.0]
            p = apply(self.static[(f"{arm}_forearm", f"{arm}_tool")], p)
            for a, b in reversed(list(zip(chain, chain[1:]))):
                p = apply(tfs[(f"{arm}_{a}", f"{arm}_{b}")], p)
            th = self.trace.f3(k, col)
            want = paper_fk(*th)
            if max_diff(p, want) > FK_TOL:
                fail(f"{where}: {arm}_tool in {arm}_base by the transforms is {p}, the paper's "
                     f"FK of {col} {th} is {want} (differ by {max_diff(p, want):.3g} m)")
            if arm == "slave":
                tool = self.trace.f3(k, "tool")
                if tool == [0.0, 0.0, 0.0]:
                    # The slave recorded no step for this sample: its columns stay zero.
                    self.tool_skipped += 1
                    continue
                d = max_diff(p, tool)
                self.tool_max = max(self.tool_max, d)
                if not d <= self.tool_tol:
                    fail(f"{where}: slave_tool by the transforms is {p}, trace tool {tool} "
                         f"(differ by {d:.3g} m > --tool-tol {self.tool_tol})")

    def environment(self, k, log_time, msg):
        where = f"/slave/environment at trace row {k}"
        markers = msg["markers"]
        if len(markers) != len(self.objects):
            fail(f"{where}: {len(markers)} markers, scenario has {len(self.objects)} objects")
        ids = set()
        for i, (m, o) in enumerate(zip(markers, self.objects)):
            w = f"{where}, marker {i} ({o.get('kind')})"
            check_stamp(m["header"], log_time, w)
            if m["header"]["frame_id"] != "slave_base":
                fail(f"{w}: frame {m['header']['frame_id']!r}, expected 'slave_base'")
            if (m["ns"], m["id"]) in ids:
                fail(f"{w}: duplicate ns/id {(m['ns'], m['id'])}")
            ids.add((m["ns"], m["id"]))
            if m["action"] != ADD:
                fail(f"{w}: action {m['action']}, expected ADD (0)")
            q = m["pose"]["orientation"]
            norm = math.sqrt(q["x"] ** 2 + q["y"] ** 2 + q["z"] ** 2 + q["w"] ** 2)
            if abs(norm - 1) > 1e-9:
                fail(f"{w}: orientation {q} is not a unit quaternion")
            if not m["color"]["a"] > 0:
                fail(f"{w}: colour alpha {m['color']['a']} (invisible)")
            scale = xyz(m["scale"])
            kind = o.get("kind")
            if kind == "plane":
                if m["type"] != CUBE:
                    fail(f"{w}: type {m['type']}, expected CUBE ({CUBE})")
                if not (min(scale) > 0 and min(scale) * 10 <= max(scale)):
                    fail(f"{w}: scale {scale} is not a thin slab")
            elif kind == "sphere":
                if m["type"] != SPHERE:
                    fail(f"{w}: type {m['type']}, expected SPHERE ({SPHERE})")
                self.near(xyz(m["pose"]["position"]), o["center"], "position", w)
                self.near(scale, [2 * o["radius"]] * 3, "scale", w)
            elif kind == "box":
                if m["type"] != CUBE:
                    fail(f"{w}: type {m['type']}, expected CUBE ({CUBE})")
                self.near(xyz(m["pose"]["position"]), o["center"], "position", w)
                self.near(scale, [2 * e for e in o["half_extents"]], "scale", w)
            else:
                fail(f"scenario.toml: unknown environment object kind {kind!r}")

    @staticmethod
    def near(got, want, what, where):
        if max_diff(got, want) > 1e-9:
            fail(f"{where}: {what} {got}, expected {want}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir", help="directory with run.mcap, trace.csv and scenario.toml")
    ap.add_argument("--fk", help='JSON: [{"theta": [t1, t2, t3], "xyz": [x, y, z]}, ...]')
    ap.add_argument("--compression", default="lz4", choices=["lz4", "zstd"],
                    help="the chunks' compression expected (default lz4)")
    ap.add_argument("--tool-tol", type=float, default=1e-3,
                    help="bound on |FK(theta_sd) - trace tool|, m (default 1e-3)")
    args = ap.parse_args()
    try:
        run(args)
    except CheckFailed as e:
        print(f"mcap-check: FAIL: {e}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
