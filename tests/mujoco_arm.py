"""A robot arm simulated by MuJoCo from its URDF, as the arm stand-in of
tests/ros2_standin.py drives it (`--mujoco URDF`): an implementation of the arm's
kinematics, dynamics and contact independent of Tactile's (MuJoCo's own URDF import,
its own integrator and soft contacts).

The URDF's meshes are dropped (MuJoCo would need the package's files): the links keep
their inertias, and the only collision is a sphere at the tool's origin against a
wall (a box) whose top is where the test says. Each joint has a position actuator
(ros2_control's position interface, a stiff servo) and every body is gravity
compensated (as the arm's controller does), so a joint goes where it is commanded,
yielding only to contact. The contact force on the tool, as a force-torque sensor
at the tool estimates it (Franka's external wrench), is given in any link's frame.
"""
import re

import mujoco
import numpy as np

# A stiff position servo (N m/rad, N m s/rad), critically damped for the Panda's
# links; 1 ms steps, as the stand-in's loop.
KP, KV, STEP = 3000.0, 120.0, 1e-3


class MujocoArm:
    def __init__(self, urdf_path, names, initial, tool, wall_below, radius=0.01):
        """The arm of `urdf_path` (joints `names` at `initial`), its `tool` link
        touching a wall whose surface lies `wall_below` m under the tool's start."""
        xml = open(urdf_path).read()
        xml = re.sub(r"<visual>.*?</visual>", "", xml, flags=re.S)
        xml = re.sub(r"<collision>.*?</collision>", "", xml, flags=re.S)
        # Joints off the arm (a gripper's fingers) held rigid.
        for j in re.findall(r'<joint name="([^"]+)" type="(?:prismatic|revolute|continuous)"', xml):
            if j not in names:
                xml = re.sub(rf'(<joint name="{j}" )type="\w+"', r'\1type="fixed"', xml)
        xml = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler discardvisual="true" '
                     r'fusestatic="false" balanceinertia="true"/></mujoco>', xml, count=1)
        spec = mujoco.MjSpec.from_string(xml)
        spec.option.timestep = STEP
        # The servo's damping integrated implicitly: explicit, kv would make a light
        # link (a UR wrist's) unstable at 1 ms steps.
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        for b in spec.bodies:
            b.gravcomp = 1.0
        for n in names:
            a = spec.add_actuator()
            a.name, a.target = n, n
            a.trntype = mujoco.mjtTrn.mjTRN_JOINT
            a.set_to_position(kp=KP, kv=KV)
        hand = spec.body(tool)
        hand.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[radius, 0, 0], name="tool_tip")
        wall = spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.3, 0.01],
                                       name="wall")
        self.m = spec.compile()
        self.d = mujoco.MjData(self.m)
        self.qadr = [self.m.joint(n).qposadr[0] for n in names]
        self.d.qpos[self.qadr] = initial
        self.d.ctrl[:] = initial
        mujoco.mj_forward(self.m, self.d)
        # The wall under the tool: its top `radius` below the surface the tool's
        # origin meets, so the sphere touches when the origin reaches it.
        x, y, z = self.d.body(tool).xpos
        wall.pos = [x, y, z - wall_below - radius - 0.01]
        self.m = spec.compile()
        self.d = mujoco.MjData(self.m)
        self.d.qpos[self.qadr] = initial
        self.d.ctrl[:] = initial
        mujoco.mj_forward(self.m, self.d)
        self.tool = tool
        self.tip = self.m.geom("tool_tip").id

    def step(self, target, velocity):
        """One step toward the joint reference `target` moving at `velocity`: a
        position actuator's force is kp (ctrl - q) - kv q', so commanding target +
        (kv / kp) velocity makes it kp (target - q) + kv (velocity - q'), a PD with
        the velocity feedforward a trajectory controller gives."""
        self.d.ctrl[:] = [q + KV / KP * v for q, v in zip(target, velocity)]
        mujoco.mj_step(self.m, self.d)

    def q(self):
        return [float(x) for x in self.d.qpos[self.qadr]]

    def tool_position(self):
        return [float(x) for x in self.d.body(self.tool).xpos]

    def contact_force(self):
        """The environment's force on the tool, N, in the world (the arm's base)."""
        total = np.zeros(3)
        f6 = np.zeros(6)
        for i in range(self.d.ncon):
            c = self.d.contact[i]
            if self.tip not in (c.geom1, c.geom2):
                continue
            mujoco.mj_contactForce(self.m, self.d, i, f6)
            # In the contact frame (rows: normal, tangents), the force geom1 exerts on
            # geom2 along the normal from geom1 to geom2.
            world = c.frame.reshape(3, 3).T @ f6[:3]
            total += world if c.geom2 == self.tip else -world
        return total

    def force_in(self, link):
        """The contact force in `link`'s frame (the base's for the world)."""
        f = self.contact_force()
        if link in ("", "world"):
            return [float(x) for x in f]
        r = self.d.body(link).xmat.reshape(3, 3)
        return [float(x) for x in r.T @ f]
