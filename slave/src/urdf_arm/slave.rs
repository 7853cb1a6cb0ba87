//! A URDF arm as the slave's arm ([`SlaveArm`]): its IK follows the target through the
//! map, a real arm's measured joints replace the simulation, and its failed dynamics
//! periods are counted and said once.

use super::UrdfArm;
use crate::slave_arm::SlaveArm;
use crate::world::Touch;
use std::sync::Arc;
use tactile_math::joints::Joints;
use tactile_math::kernels;
use tactile_messages::samples::Flags;
use tactile_records::slave::{ArmJoints, HoldStep, SlaveCounters};
use tactile_ros::view::{ArmSample, SampleView, SlaveView};

impl SlaveArm for UrdfArm {
    fn follow(
        &mut self,
        position: [f64; 3],
        rotation: Option<[f64; 4]>,
        released: bool,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> Flags {
        if released {
            self.release();
            return Flags::NONE;
        }
        count_followed(c, UrdfArm::follow(self, position, rotation, dt))
    }

    fn advance(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> u32 {
        if let Some(q) = measured {
            self.set_measured(q, dt);
            return 0;
        }
        let clamps = UrdfArm::advance(self, dt, touch);
        c.torque_clamps += u64::from(clamps);
        log_first_failure(self);
        clamps
    }

    fn hold(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> HoldStep {
        let h = match measured {
            Some(q) => self.hold_measured(q, dt),
            None => {
                let h = UrdfArm::hold(self, dt, touch);
                log_first_failure(self);
                h
            }
        };
        c.holds += u64::from(h.started);
        c.held_steps += 1;
        c.torque_clamps += u64::from(h.clamps);
        c.hold_drift_max_m = c.hold_drift_max_m.max(h.drift_m);
        HoldStep {
            step: c.held_steps,
            tool: h.tool,
        }
    }

    fn end_hold(&mut self) {
        UrdfArm::end_hold(self);
    }

    fn clutch_shift(&self) -> [f64; 3] {
        UrdfArm::clutch_shift(self)
    }

    /// A URDF arm's kernels are f64 (tactile-chain): its FK is the truth.
    fn tool(&self) -> ([f64; 3], [f64; 3]) {
        let tool = UrdfArm::tool(self);
        (tool, tool)
    }

    fn tool_frame(&self) -> tactile_world::Pose {
        let (position, rotation) = self.tool_frame_in_base();
        tactile_world::Pose { position, rotation }
    }

    fn point_to_master(&self, p: [f64; 3]) -> [f64; 3] {
        UrdfArm::point_to_master(self, p)
    }

    fn contact_force(&self, surface: [f64; 3], tool: [f64; 3], stiffness: [f64; 3]) -> [f64; 3] {
        self.felt_environment(kernels::fbf(surface, tool, stiffness))
    }

    fn felt(&self, f: [f64; 3]) -> [f64; 3] {
        UrdfArm::felt(self, f)
    }

    fn reference(&self) -> Joints {
        self.state().q_ref
    }

    fn counters(&self, c: SlaveCounters) -> SlaveCounters {
        SlaveCounters {
            dynamics_failed: self.dynamics_failures(),
            ..c
        }
    }

    fn joints(&self, torque: [f64; 3], master: Option<[f64; 4]>) -> ArmJoints {
        let a = self.state();
        let (offset, offset_rotation) = self.offsets();
        ArmJoints {
            q_ref: a.q_ref,
            q: a.q,
            tau: a.tau,
            torque,
            target_rotation: self.target_rotation(),
            tool_rotation: self.tool_rotation(),
            target_position: self.target_position(),
            tool_position: self.tool_in_base(),
            released: self.released(),
            master_rotation: master.unwrap_or([0.0, 0.0, 0.0, 1.0]),
            offset,
            offset_rotation,
        }
    }

    fn live(&self, view: SlaveView) -> SampleView {
        let a = self.state();
        let (base, names) = self.live_names();
        SampleView {
            arm: Some(ArmSample {
                base: Arc::clone(base),
                names: Arc::clone(names),
                q: a.q,
                effort: a.tau,
                tool: self.tool_in_base(),
                force: view.force,
            }),
            ..SampleView::default()
        }
    }
}

/// The arm's first failed dynamics step, logged with its cause (the slave's handler
/// logs how many more each second): a run whose arm stands still says why.
fn log_first_failure(arm: &mut UrdfArm) {
    if let Some(e) = arm.take_failure() {
        if arm.dynamics_failures() == 1 {
            tracing::warn!(
                "slave.arm: the dynamics failed ({e}): the arm stands still while they do"
            );
        }
    }
}

/// Counts what a URDF arm's IK call did; the flags it sets on h(n).
fn count_followed(c: &mut SlaveCounters, f: super::Followed) -> Flags {
    c.ik_joint_limited += u64::from(f.joint_limited);
    c.ik_velocity_limited += u64::from(f.velocity_limited);
    c.ik_damped += u64::from(f.damped);
    let mut flags = Flags::NONE;
    if f.unreachable {
        flags |= Flags::IK_CLAMPED;
        c.ik_clamped += 1;
    }
    if f.refused {
        flags |= Flags::REJECTED;
        c.rejected += 1;
    }
    if f.workspace_clamped {
        flags |= Flags::IK_CLAMPED;
        c.workspace_clamped += 1;
    }
    flags
}
