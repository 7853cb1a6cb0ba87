//! The slave as any serial arm from its URDF, simulated: the IK of `tactile-chain`
//! turns the received position into joint references once a sample, a joint-space PD
//! on the references and their velocity (as a joint trajectory controller's) with
//! gravity compensation (the robot's own servo, evaluated at every integration
//! step as a real arm's inner loop runs far faster than the network's samples) drives
//! the joints, and the articulated-body algorithm integrates the URDF's inertias under
//! gravity, the joints' damping and the environment's contact force at the tool.
//! With `servo = "cartesian"` an impedance at the tool replaces the joint PD (the
//! IK's references then only steer the null space), as a torque-controlled arm's
//! Cartesian impedance controller does.
//!
//! The loop carries positions in the master's frame (see `tactile_scenario::ArmConfig`):
//! the tool's target is its home pose moved by `scale` times the master's displacement
//! from `master_home`, its orientation the master's rotation (a 6-DoF sample's, about
//! the base's axes) applied to its home orientation, or held at home for a 3-DoF
//! master. While the operator's clutch is released the references stay where they
//! are (the robot holds); at the next engaged sample the offset between the master's
//! mapped pose and the held reference is captured, so the robot continues from where
//! it held instead of jumping (clutch indexing). The environment sees the tool
//! mapped back into the master's frame, and the contact force it returns acts on the
//! arm's tool as it is (the objects are the master frame's, so a wall keeps its place
//! and stiffness for the operator whatever the arm).

use nalgebra::{Matrix3, Vector3, Vector6};
pub use tactile_chain::spatial::{quaternion, rotation_matrix};
use tactile_chain::{Chain, Dynamics, Frame, Ik, IkConfig, Robot};
use tactile_scenario::shown::{listed, Num};
use tactile_scenario::ArmConfig;

use crate::world::Touch;
use std::sync::Arc;
use tactile_math::joints::{Joints, MAX_JOINTS};

/// The simulated arm and its references.
#[derive(Debug, Clone)]
pub struct UrdfArm {
    chain: Chain,
    ik: Ik,
    dynamics: Dynamics,
    cfg: ArmConfig,
    home_tool: Frame,
    master_home: [f64; 3],
    state: ArmState,
    /// The integration's buffers, made once.
    scratch: sim::Scratch,
    /// The joints held since input went silent, if it is.
    held: Option<Joints>,
    /// The tool's pose reference and its velocity `[linear; angular]` in the base
    /// frame (the Cartesian servo's).
    reference: (Frame, Vector6<f64>),
    /// The clutch is released: the references hold.
    released: bool,
    /// The offsets captured at the last re-engage: the master's mapped pose moved by
    /// these is the target (`None` until the clutch was first released).
    indexing: Option<Indexing>,
    /// The master's base frame in the arm's (`cfg.rotation`), `None` for none.
    frame: Option<Matrix3<f64>>,
    /// Periods whose dynamics failed (the arm then stood still), and the last
    /// failure not yet taken by the slave's log.
    failures: (u64, Option<String>),
    /// The base link and the joints' names, as the live view shares them.
    live_names: (Arc<str>, Arc<[String]>),
}

/// Where the master's mapped pose met the robot's reference at a re-engage: the
/// target is `p + dp` and `r dr`, so the master's rotations since then turn the tool
/// about the base's axes from where it held.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Indexing {
    dp: Vector3<f64>,
    dr: Matrix3<f64>,
}

/// The arm's joints after a step: references, angles, velocities, efforts (inline:
/// copying them costs no allocation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmState {
    /// The IK's joint references, rad or m.
    pub q_ref: Joints,
    /// The references' velocity over the last period (the servo's feedforward), rad/s
    /// or m/s.
    pub qd_ref: Joints,
    /// Joint values, rad or m.
    pub q: Joints,
    /// Joint velocities, rad/s or m/s.
    pub qd: Joints,
    /// The PD's efforts (with gravity compensation) at the step's last integration
    /// step, after the effort limits, N m or N.
    pub tau: Joints,
}

/// What one IK call did, for the slave's flags and counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Followed {
    /// The target is out of reach (error left that speed does not explain).
    pub unreachable: bool,
    /// A joint limit clamped the reference.
    pub joint_limited: bool,
    /// The velocity limit shortened the reference's step.
    pub velocity_limited: bool,
    /// The IK damped (near a singularity).
    pub damped: bool,
    /// The IK refused the call (a non-finite input): the reference held.
    pub refused: bool,
    /// The target was outside the workspace box and clamped onto it.
    pub workspace_clamped: bool,
}

/// What one period of holding did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Holding {
    /// This period started the hold (the input just went silent).
    pub started: bool,
    /// Joints that hit their effort limit.
    pub clamps: u32,
    /// How far the tool is from where it was held, m (master's frame).
    pub drift_m: f64,
    /// The tool in the master's frame, m.
    pub tool: [f64; 3],
}

impl UrdfArm {
    /// The arm of `cfg` from the URDF text `xml`, at rest at its home posture;
    /// `master_home` is the master's position that maps onto the tool's home pose.
    pub fn new(cfg: &ArmConfig, xml: &str, master_home: [f64; 3]) -> Result<Self, String> {
        let robot = Robot::parse(xml).map_err(|e| e.to_string())?;
        UrdfArm::of_robot(cfg, &robot, master_home)
    }

    /// The arm of `cfg` from its URDF's model `robot` (parsed once), at rest at its
    /// home posture; `master_home` as for [`UrdfArm::new`].
    pub fn of_robot(cfg: &ArmConfig, robot: &Robot, master_home: [f64; 3]) -> Result<Self, String> {
        let chain = Chain::new(robot, &cfg.base, &cfg.tip).map_err(|e| e.to_string())?;
        let dof = chain.dof();
        for (field, v) in [("home", &cfg.home), ("kp", &cfg.kp), ("kd", &cfg.kd)] {
            if v.len() != dof {
                return Err(format!(
                    "field `slave.arm.{field}`: has {} values; the chain from `{}` to `{}` has {dof} joints ({})",
                    v.len(),
                    cfg.base,
                    cfg.tip,
                    listed(chain.dofs.iter().map(|d| d.name.as_str()))
                ));
            }
        }
        if dof > MAX_JOINTS {
            return Err(format!(
                "the chain from `{}` to `{}` has {dof} joints; an arm may have at most {MAX_JOINTS}",
                cfg.base, cfg.tip
            ));
        }
        for (d, q) in chain.dofs.iter().zip(&cfg.home) {
            if *q < d.lower || *q > d.upper {
                return Err(format!(
                    "field `slave.arm.home`: {} for joint `{}` is outside its limits [{}, {}]",
                    Num(*q),
                    d.name,
                    Num(d.lower),
                    Num(d.upper)
                ));
            }
        }
        let dynamics =
            Dynamics::new(&chain, Vector3::from(cfg.gravity)).map_err(|e| e.to_string())?;
        // One step at home, at rest: dynamics that fail there (a link's mass on its
        // own joint's axis, nothing to turn) would fail at every step of the run.
        let zero = vec![0.0; dof];
        match dynamics.aba(&cfg.home, &zero, &zero) {
            Ok(a) if a.iter().all(|a| a.is_finite()) => {}
            Ok(_) => return Err("slave.arm: the dynamics at home are not finite".into()),
            Err(e) => return Err(format!("slave.arm: at home: {e}")),
        }
        let ik_cfg = IkConfig {
            max_iterations: cfg.ik.max_iterations as usize,
            orientation_weight: cfg.ik.orientation_weight,
            damping_max: cfg.ik.damping_max,
            singular_threshold: cfg.ik.singular_threshold,
            posture: Some(cfg.home.clone()),
            posture_gain: cfg.ik.posture_gain,
            velocity_scale: cfg.ik.velocity_scale,
            ..IkConfig::default()
        };
        let ik = Ik::new(&chain, ik_cfg).map_err(|e| e.to_string())?;
        let home_tool = chain.fk(&cfg.home);
        if let (Some(w), p) = (&cfg.workspace, home_tool.p) {
            if w.clamp(p.into()).1 {
                return Err(format!(
                    "field `slave.arm.workspace`: the tool's home [{}, {}, {}] m is outside the box {:?} to {:?}: the robot would move at the first sample",
                    Num(p.x), Num(p.y), Num(p.z), w.min, w.max
                ));
            }
        }
        let too_many = |e: tactile_math::joints::TooManyJoints| e.to_string();
        let (home, zeros) = (
            Joints::from_slice(&cfg.home).map_err(too_many)?,
            Joints::zeros(dof).map_err(too_many)?,
        );
        let state = ArmState {
            q_ref: home,
            qd_ref: zeros,
            q: home,
            qd: zeros,
            tau: zeros,
        };
        Ok(UrdfArm {
            scratch: sim::Scratch::new(&chain, &ik),
            ik,
            dynamics,
            cfg: cfg.clone(),
            home_tool,
            master_home,
            reference: (home_tool, Vector6::zeros()),
            state,
            held: None,
            released: false,
            indexing: None,
            frame: (!cfg.rotation.is_identity())
                .then(|| Matrix3::from_fn(|i, j| cfg.rotation.matrix()[i][j])),
            failures: (0, None),
            live_names: (
                Arc::from(chain.base.as_str()),
                chain.dofs.iter().map(|d| d.name.clone()).collect(),
            ),
            chain,
        })
    }

    /// The base link and the joints' names, shared with the live view.
    pub fn live_names(&self) -> &(Arc<str>, Arc<[String]>) {
        &self.live_names
    }

    /// The joints now.
    pub fn state(&self) -> &ArmState {
        &self.state
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The tool's target in the arm's base frame for the master's `position` and,
    /// from a 6-DoF master, `rotation` (a unit quaternion `[x, y, z, w]` relative to
    /// the operator's home), moved by the clutch's offsets.
    /// A target outside the workspace box is clamped onto it (the second value says
    /// so).
    pub fn target(&self, position: [f64; 3], rotation: Option<[f64; 4]>) -> (Frame, bool) {
        let mut t = self.unclamped_target(position, rotation);
        let (p, clamped) = self.cfg.clamp(t.p.into());
        t.p = Vector3::from(p);
        (t, clamped)
    }

    /// [`UrdfArm::target`] before the workspace box: the master's turn, in its base's
    /// axes, is the same turn about the arm's base's axes it maps to.
    fn unclamped_target(&self, position: [f64; 3], rotation: Option<[f64; 4]>) -> Frame {
        let home = self.home_tool.p.into();
        let r = match (rotation, &self.frame) {
            (Some(q), None) => rotation_matrix(q) * self.home_tool.r,
            (Some(q), Some(m)) => m * rotation_matrix(q) * m.transpose() * self.home_tool.r,
            (None, _) => self.home_tool.r,
        };
        let p = Vector3::from(self.cfg.to_robot(home, self.master_home, position));
        match self.indexing {
            Some(ix) => Frame {
                r: r * ix.dr,
                p: p + ix.dp,
            },
            None => Frame { r, p },
        }
    }

    /// The tool's orientation relative to its home, about the base's axes, as `[x, y,
    /// z, w]`: what a 6-DoF master's rotation is compared with.
    pub fn tool_rotation(&self) -> [f64; 4] {
        let r = self.chain.fk(&self.state.q).r * self.home_tool.r.transpose();
        quaternion(&r)
    }

    /// The orientation reference relative to the tool's home, `[x, y, z, w]`.
    pub fn target_rotation(&self) -> [f64; 4] {
        quaternion(&(self.reference.0.r * self.home_tool.r.transpose()))
    }

    /// The position reference in the base frame, m: the last target (mapped, offset,
    /// clamped into the box), or what the robot holds while released or silent.
    pub fn target_position(&self) -> [f64; 3] {
        self.reference.0.p.into()
    }

    /// The clutch's offsets captured at the last engage: position (m, base frame) and
    /// orientation `[x, y, z, w]`; zero and the identity before the first release.
    pub fn offsets(&self) -> ([f64; 3], [f64; 4]) {
        match &self.indexing {
            Some(ix) => (ix.dp.into(), quaternion(&ix.dr)),
            None => ([0.0; 3], [0.0, 0.0, 0.0, 1.0]),
        }
    }

    /// Where the clutch's position offset puts the tool relative to the master's
    /// handle, m in the master's frame: the target a handle at `x` sends the arm to is
    /// at `x` plus this before the workspace box (zero before the first release).
    pub fn clutch_shift(&self) -> [f64; 3] {
        let dp = self.indexing.as_ref().map_or([0.0; 3], |ix| ix.dp.into());
        self.cfg.shift_to_master(dp)
    }

    /// True while the operator's clutch is released.
    pub fn released(&self) -> bool {
        self.released
    }

    /// The clutch is released this sample: the references stay (the robot holds).
    pub fn release(&mut self) {
        if !self.released {
            // What the arm holds is its joints' reference, which a limited or refused
            // IK step may have left short of the last target: the engage continues
            // from there.
            self.reference.0 = self.chain.fk(&self.state.q_ref);
        }
        self.released = true;
        self.state.qd_ref.iter_mut().for_each(|v| *v = 0.0);
        self.reference.1 = Vector6::zeros();
    }

    /// At the first engaged sample after a release, the offsets that put the master's
    /// mapped pose where the robot's reference held.
    fn engage(&mut self, position: [f64; 3], rotation: Option<[f64; 4]>) {
        if !std::mem::take(&mut self.released) {
            return;
        }
        self.indexing = None;
        let raw = self.unclamped_target(position, rotation);
        let held = self.reference.0;
        self.indexing = Some(Indexing {
            dp: held.p - raw.p,
            dr: raw.r.transpose() * held.r,
        });
    }

    /// The tool (FK of the joints) mapped into the master's frame, m.
    pub fn tool(&self) -> [f64; 3] {
        self.to_master(&self.chain.fk(&self.state.q).p)
    }

    /// The tool (FK of the joints) in the arm's base frame, m.
    pub fn tool_in_base(&self) -> [f64; 3] {
        self.chain.fk(&self.state.q).p.into()
    }

    /// The tool frame in the base frame: FK's position and orientation `[x, y, z, w]`
    /// (not relative to home: a physics world built around the arm takes it as is).
    pub fn tool_frame_in_base(&self) -> ([f64; 3], [f64; 4]) {
        let f = self.chain.fk(&self.state.q);
        (f.p.into(), quaternion(&f.r))
    }

    /// A point of the base frame in the master's, m.
    pub fn point_to_master(&self, p: [f64; 3]) -> [f64; 3] {
        self.to_master(&Vector3::from(p))
    }

    /// A displacement's length in the master's workspace, m.
    fn master_distance(&self, d: Vector3<f64>) -> f64 {
        match self.cfg.scale {
            tactile_scenario::Scale::Uniform(s) => d.norm() / s,
            tactile_scenario::Scale::PerAxis(s) => Vector3::from_fn(|k, _| d[k] / s[k]).norm(),
        }
    }

    /// A force at the tool in the base's axes (a sensor's) as the operator is to feel
    /// it: in the master's axes, scaled (`slave.arm.rotation`, `force_scale`).
    pub fn felt(&self, f: [f64; 3]) -> [f64; 3] {
        self.cfg.force_to_master(f)
    }

    /// The environment's force, evaluated in the master's axes, as the operator is to
    /// feel it: scaled.
    pub fn felt_environment(&self, f: [f64; 3]) -> [f64; 3] {
        f.map(|v| self.cfg.force_scale * v)
    }

    fn to_master(&self, p: &Vector3<f64>) -> [f64; 3] {
        let home = self.home_tool.p.into();
        self.cfg.to_master(home, self.master_home, (*p).into())
    }

    /// IK toward the master's `position` (and `rotation`, from a 6-DoF master), one
    /// period of `dt` from the last reference (the reference is a smooth path the
    /// servo follows, as a trajectory generator's).
    pub fn follow(&mut self, position: [f64; 3], rotation: Option<[f64; 4]>, dt: f64) -> Followed {
        self.engage(position, rotation);
        let (target, workspace_clamped) = self.target(position, rotation);
        let v = (target.p - self.reference.0.p) / dt;
        let w = match rotation.is_some() || self.indexing.is_some() {
            true => {
                tactile_chain::spatial::log_rotation(&(target.r * self.reference.0.r.transpose()))
                    / dt
            }
            false => Vector3::zeros(),
        };
        self.reference = (target, Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z));
        // Into the arm's IK workspace and an inline buffer: a call allocates nothing.
        let mut q = self.state.q_ref;
        let ws = &mut self.scratch.ik;
        match self
            .ik
            .step_into(ws, &self.state.q_ref, &target, dt, &mut q)
        {
            Ok(s) => {
                for ((v, new), old) in self
                    .state
                    .qd_ref
                    .iter_mut()
                    .zip(&q)
                    .zip(self.state.q_ref.iter())
                {
                    *v = (new - old) / dt;
                }
                self.state.q_ref = q;
                Followed {
                    unreachable: s.unreachable,
                    joint_limited: s.clamped,
                    velocity_limited: s.velocity_limited,
                    damped: s.damping > 0.0,
                    refused: false,
                    workspace_clamped,
                }
            }
            Err(_) => Followed {
                refused: true,
                workspace_clamped,
                ..Followed::default()
            },
        }
    }

    /// One period of `dt` with no input: the servo holds the joints where they were
    /// when the input went silent, the arm integrated as in [`UrdfArm::advance`].
    pub fn hold(&mut self, dt: f64, touch: Touch<'_>) -> Holding {
        let started = self.held.is_none();
        let q = self.state.q;
        let from = self.held.get_or_insert(q);
        self.state.q_ref.copy_from_slice(from);
        self.state.qd_ref.iter_mut().for_each(|v| *v = 0.0);
        let held = self.chain.fk(&self.state.q_ref);
        self.reference = (held, Vector6::zeros());
        let p0 = held.p;
        let clamps = self.advance(dt, touch);
        let p = self.chain.fk(&self.state.q).p;
        Holding {
            started,
            clamps,
            // Measured in the master's frame, as the paper arm's drift is.
            drift_m: self.master_distance(p - p0),
            tool: self.to_master(&p),
        }
    }

    /// A real arm's joints, measured (`[slave.arm]` over ROS 2): they are the state,
    /// their velocity the difference over `dt`; the robot's own controller follows
    /// the reference, so no effort is known.
    pub fn set_measured(&mut self, q: &[f64], dt: f64) {
        let s = &mut self.state;
        if q.len() != s.q.len() {
            return;
        }
        for ((v, new), old) in s.qd.iter_mut().zip(q).zip(s.q.iter()) {
            *v = (new - old) / dt;
        }
        s.q.copy_from_slice(q);
        s.tau.iter_mut().for_each(|t| *t = 0.0);
    }

    /// One period with no input for a real arm measured at `q`: it is commanded the
    /// reference it had when the input went silent.
    pub fn hold_measured(&mut self, q: &[f64], dt: f64) -> Holding {
        let started = self.held.is_none();
        let q_ref = self.state.q_ref;
        let from = self.held.get_or_insert(q_ref);
        self.state.q_ref.copy_from_slice(from);
        self.state.qd_ref.iter_mut().for_each(|v| *v = 0.0);
        self.set_measured(q, dt);
        let p0 = self.chain.fk(&self.state.q_ref).p;
        let p = self.chain.fk(&self.state.q).p;
        Holding {
            started,
            clamps: 0,
            drift_m: self.master_distance(p - p0),
            tool: self.to_master(&p),
        }
    }

    /// Input is back: the next silence holds where the joints are then.
    pub fn end_hold(&mut self) {
        self.held = None;
    }

    /// Periods whose dynamics failed so far (the arm stood still in each).
    pub fn dynamics_failures(&self) -> u64 {
        self.failures.0
    }

    /// The last failure of the dynamics since this was last called, if any.
    pub fn take_failure(&mut self) -> Option<String> {
        self.failures.1.take()
    }
}

mod sim;

mod slave;

#[cfg(test)]
mod tests;
