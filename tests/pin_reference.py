"""Reference kinematics and dynamics from Pinocchio (the `pin` wheel) for the arms of
example-robot-data, as JSON on stdout: tests/chain.rs compares tactile-chain with it.

For each arm: its URDF's path, base and tip links, and at random configurations the
tip's pose in the base frame, the tip's Jacobian (LOCAL_WORLD_ALIGNED, turned into the
base's axes), the accelerations of the articulated-body algorithm under random
efforts and the efforts of RNEA for random accelerations. Joints off the base-to-tip
path (the Panda's fingers) are locked at zero, as tactile-chain carries them.
"""

import argparse
import json
import os

import numpy as np
import pinocchio as pin

ARMS = [
    ("panda", "panda_description/urdf/panda.urdf", "panda_link0", "panda_hand"),
    ("ur5", "ur_description/urdf/ur5_robot.urdf", "base_link", "tool0"),
    ("xarm7", "xarm_description/urdf/xarm7.urdf", "link_base", "link_eef"),
    # Kinova's Jaco2 (6 joints, three of them continuous; its fingers fixed).
    ("jaco2", "kinova_description/robots/kinova.urdf", "base", "j2s6s200_end_effector"),
    ("ur3", "ur_description/urdf/ur3_robot.urdf", "base_link", "tool0"),
    ("ur10", "ur_description/urdf/ur10_robot.urdf", "base_link", "tool0"),
    # Unitree's Z1 (6 joints; its gripper locked).
    ("z1", "z1_description/urdf/z1.urdf", "link00", "gripperStator"),
    # The SO-101 (5 joints; its jaw locked). The SO-100 loads too, but Pinocchio
    # 4.1's buildReducedModel cannot lock its jaw: a joint and a link are both `gripper`.
    ("so101", "so_arm_description/urdf/so101.urdf", "base_link", "gripper_frame_link"),
]


def robots_dir():
    share = os.path.join(os.path.dirname(pin.__file__), "..", "..", "..", "..")
    for base in [os.path.join(p, "cmeel.prefix", "share") for p in __import__("site").getsitepackages()] + [share]:
        d = os.path.join(base, "example-robot-data", "robots")
        if os.path.isdir(d):
            return os.path.abspath(d)
    raise SystemExit("example-robot-data's robots folder not found")


def chain_model(path, base, tip):
    full = pin.buildModelFromUrdf(path)
    fid = full.getFrameId(tip, pin.BODY)
    on_path = set()
    j = full.frames[fid].parentJoint
    while j != 0:
        on_path.add(j)
        j = full.parents[j]
    lock = [j for j in range(1, full.njoints) if j not in on_path]
    return pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full


def random_angles(rng, model):
    """One value per degree of freedom, within the limits; a continuous joint's (two
    of Pinocchio's q, cos and sin) anywhere in [-pi, pi]."""
    out = []
    for j in model.joints[1:]:
        lo = model.lowerPositionLimit[j.idx_q]
        hi = model.upperPositionLimit[j.idx_q]
        out.append(rng.uniform(-np.pi, np.pi) if j.nq == 2 else lo + (hi - lo) * rng.random())
    return np.array(out)


def pin_q(model, angles):
    """Pinocchio's configuration for one value per degree of freedom."""
    q = []
    for j, a in zip(model.joints[1:], angles):
        q += [np.cos(a), np.sin(a)] if j.nq == 2 else [a]
    return np.array(q)


def arm_cases(rng, name, rel, base, tip, n):
    path = os.path.join(robots_dir(), rel)
    model = chain_model(path, base, tip)
    data = model.createData()
    b, t = model.getFrameId(base, pin.BODY), model.getFrameId(tip, pin.BODY)
    cases = []
    for _ in range(n):
        angles = random_angles(rng, model)
        q = pin_q(model, angles)
        qd = rng.uniform(-1.0, 1.0, model.nv)
        tau = rng.uniform(-5.0, 5.0, model.nv)
        qdd_in = rng.uniform(-2.0, 2.0, model.nv)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        obase = data.oMf[b]
        rel_tip = obase.inverse() * data.oMf[t]
        jac = pin.computeFrameJacobian(model, data, q, t, pin.LOCAL_WORLD_ALIGNED)
        rt = obase.rotation.T
        jac = np.vstack([rt @ jac[:3], rt @ jac[3:]])
        qdd = pin.aba(model, data, q, qd, tau)
        tau_rnea = pin.rnea(model, data, q, qd, qdd_in)
        cases.append({
            "q": angles.tolist(), "qd": qd.tolist(), "tau": tau.tolist(), "qdd_in": qdd_in.tolist(),
            "p": rel_tip.translation.tolist(), "r": rel_tip.rotation.tolist(),
            "jacobian": jac.tolist(), "qdd": qdd.tolist(), "tau_rnea": tau_rnea.tolist(),
        })
    gravity = (obase.rotation.T @ model.gravity.linear).tolist()
    names = [model.names[j] for j in range(1, model.njoints)]
    return {"name": name, "urdf": path, "base": base, "tip": tip, "joints": names,
            "gravity": gravity, "cases": cases}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--cases", type=int, default=50)
    ap.add_argument("--robots-dir", action="store_true", help="print the URDFs' folder and stop")
    a = ap.parse_args()
    if a.robots_dir:
        print(robots_dir())
        return
    rng = np.random.default_rng(a.seed)
    arms = [arm_cases(rng, *arm, a.cases) for arm in ARMS]
    print(json.dumps({"pinocchio": pin.__version__, "arms": arms}))


if __name__ == "__main__":
    main()
