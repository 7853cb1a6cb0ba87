"""A box pushed across a table at constant speed, in MuJoCo: the independent engine
tactile-world's push test is held to (common/world/src/tests/mujoco.rs).

The table is a plane, the box a free body, the pusher a ball on a mocap body moving
at constant speed along x below the box's centre (pushed at its centre height, the
box rocks on its front edge in MuJoCo's soft contacts, and the mean push falls 5 %
under mu m g; lower, it slides flat) (a kinematic pusher: MuJoCo
moves it exactly, as the arm's tool frame moves in Tactile). Friction is MuJoCo's
pyramidal cone with the table's and the box's coefficient (both the same); the
pusher's contact takes its own small friction (priority). Prints JSON: the mean
push force over the run's second half (N, the contact force on the box along x)
and how far the box slid (m).
"""
import argparse
import json

import mujoco
import numpy as np

XML = """
<mujoco>
  <option timestep="{step}" gravity="0 0 -9.81" cone="pyramidal"/>
  <worldbody>
    <geom name="table" type="plane" size="1 1 0.1" friction="{mu} 0.005 0.0001"/>
    <body name="box" pos="0 0 {half}">
      <freejoint/>
      <geom name="box" type="box" size="{half} {half} {half}" mass="{mass}" friction="{mu} 0.005 0.0001"/>
    </body>
    <body name="pusher" mocap="true" pos="{start} 0 {height}">
      <geom name="pusher" type="sphere" size="{radius}" friction="0.01 0.005 0.0001" priority="1" contype="1" conaffinity="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--mass", type=float, required=True)
    p.add_argument("--mu", type=float, required=True)
    p.add_argument("--speed", type=float, required=True)
    p.add_argument("--seconds", type=float, required=True)
    p.add_argument("--half", type=float, required=True)
    p.add_argument("--radius", type=float, required=True)
    p.add_argument("--start", type=float, required=True)
    p.add_argument("--height", type=float, required=True)
    p.add_argument("--step", type=float, default=2.5e-4)
    a = p.parse_args()
    m = mujoco.MjModel.from_xml_string(XML.format(**vars(a)))
    d = mujoco.MjData(m)
    box = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "box")
    pusher = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "pusher")
    x0 = d.xpos[m.body("box").id][0]
    steps = int(round(a.seconds / a.step))
    forces = []
    f6 = np.zeros(6)
    for k in range(steps):
        d.mocap_pos[0][0] = a.start + a.speed * (k + 1) * a.step
        mujoco.mj_step(m, d)
        push = 0.0
        for i in range(d.ncon):
            c = d.contact[i]
            if {c.geom1, c.geom2} != {box, pusher}:
                continue
            mujoco.mj_contactForce(m, d, i, f6)
            # The contact frame's rows are its axes in the world; the force acts on
            # geom2 along +normal (on geom1 opposite).
            world = c.frame.reshape(3, 3).T @ f6[:3]
            push += world[0] if c.geom2 == box else -world[0]
        forces.append(push)
    half = forces[len(forces) // 2:]
    slid = d.xpos[m.body("box").id][0] - x0
    print(json.dumps({"force": float(np.mean(half)), "slid": float(slid)}))


if __name__ == "__main__":
    main()
