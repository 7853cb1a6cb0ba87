"""A Servo-like arm for tests/ros2_standin.py: what MoveIt Servo or FZI
cartesian_controllers do with a geometry_msgs/PoseStamped target, their own IK, here
Pinocchio's (an implementation independent of Tactile's tactile-chain).

Each pose is checked as those stacks check it: its frame_id must be the robot's base
link (cartesian_controllers' robot_base_link, Servo's planning frame), its stamp on
the robot's clock (Servo halts on a command older than 0.1 s), its numbers finite and
its quaternion a rotation; then damped least squares from the last solution finds the
joints that put the tool there.
"""
import math

import numpy as np
import pinocchio as pin

STALE_NS = 100_000_000  # MoveIt Servo's incoming_command_timeout default, 0.1 s


class ServoIk:
    def __init__(self, urdf, names, tool, frame):
        self.model = pin.buildModelFromUrdf(urdf)
        self.data = self.model.createData()
        if not self.model.existFrame(tool):
            raise SystemExit(f"{urdf} has no frame {tool}")
        self.fid = self.model.getFrameId(tool)
        missing = [n for n in names if not self.model.existJointName(n)]
        if missing:
            raise SystemExit(f"{urdf} has no joints {missing}")
        ids = [self.model.getJointId(n) for n in names]
        if any(self.model.joints[j].nq != 1 for j in ids):
            raise SystemExit("only revolute and prismatic joints (one coordinate each)")
        self.iq = [self.model.joints[j].idx_q for j in ids]
        self.iv = [self.model.joints[j].idx_v for j in ids]
        self.q = pin.neutral(self.model)
        self.frame = frame
        self.residual_max = 0.0

    def check(self, msg, now_ns):
        """Why a pose would be refused, or None."""
        h = msg.header
        if h.frame_id != self.frame:
            return f"frame_id {h.frame_id!r}, not {self.frame!r}"
        age = now_ns - (h.stamp.sec * 10**9 + h.stamp.nanosec)
        if abs(age) > STALE_NS:
            return f"stale: stamped {age / 1e6:.1f} ms from the robot's clock"
        p, o = msg.pose.position, msg.pose.orientation
        v = [p.x, p.y, p.z, o.x, o.y, o.z, o.w]
        if not all(math.isfinite(x) for x in v):
            return f"not finite: {v}"
        if abs(math.sqrt(o.x**2 + o.y**2 + o.z**2 + o.w**2) - 1.0) > 1e-6:
            return f"not a rotation: {v[3:]}"
        return None

    def solve(self, q0, msg):
        """The joints (in `names` order) that put the tool at the pose, from q0."""
        p, o = msg.pose.position, msg.pose.orientation
        target = pin.SE3(pin.Quaternion(o.w, o.x, o.y, o.z).matrix(), np.array([p.x, p.y, p.z]))
        q = self.q.copy()
        q[self.iq] = q0
        err = np.zeros(6)
        for _ in range(50):
            pin.framesForwardKinematics(self.model, self.data, q)
            err = pin.log6(self.data.oMf[self.fid].actInv(target)).vector
            if np.linalg.norm(err) < 1e-12:
                break
            jac = pin.computeFrameJacobian(self.model, self.data, q, self.fid, pin.LOCAL)[:, self.iv]
            q[self.iq] += jac.T @ np.linalg.solve(jac @ jac.T + 1e-12 * np.eye(6), err)
        self.residual_max = max(self.residual_max, float(np.linalg.norm(err)))
        return [float(x) for x in q[self.iq]]

    def tool(self, qa):
        """The tool's position at joints qa, m."""
        q = self.q.copy()
        q[self.iq] = qa
        pin.framesForwardKinematics(self.model, self.data, q)
        return [float(x) for x in self.data.oMf[self.fid].translation]
