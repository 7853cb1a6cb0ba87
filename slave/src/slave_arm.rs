//! The slave's arm, whichever it is: the paper's three joints
//! ([`crate::paper_arm::PaperArm`], its HSD kernels in the scenario's arithmetic) or
//! any serial arm from its URDF ([`crate::urdf_arm::UrdfArm`]), simulated or a real robot's measured joints. The slave's step
//! ([`crate::hsd::Slave`]) is written once against this trait: it follows the
//! channel's target, moves (or is measured), holds while the input is silent, and
//! says where its tool is and what force the operator is to feel.

use crate::world::Touch;
use tactile_math::joints::Joints;
use tactile_messages::samples::Flags;
use tactile_records::slave::{ArmJoints, HoldStep, SlaveCounters};
use tactile_ros::view::{SampleView, SlaveView};

/// The slave's arm. Positions and forces are in the master's frame, as the loop
/// carries them; each arm maps them into its own.
pub trait SlaveArm: std::fmt::Debug + Send {
    /// IK toward the channel's `position` (and a 6-DoF master's `rotation`); while the
    /// operator's clutch is `released`, the references hold. Counts what the IK did
    /// into `c`; returns the flags it sets on h(n).
    fn follow(
        &mut self,
        position: [f64; 3],
        rotation: Option<[f64; 4]>,
        released: bool,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> Flags;

    /// One period of `dt` s: a real robot's `measured` joints are the arm's (its own controller
    /// follows the reference); without, the simulated joints move under the servo,
    /// pushed back by what the tool `touch`es. Returns the joint efforts clamped to
    /// their limits this period.
    fn advance(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> u32;

    /// One period with no input: simulated, the arm holds where it was when the input
    /// went silent; a real robot (`measured`) is commanded the reference it had then.
    /// Counted into `c`.
    fn hold(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> HoldStep;

    /// Input is back: the next silence holds where the arm is then.
    fn end_hold(&mut self);

    /// The tool, m in the master's frame: as the HSD's FK computes it (the paper's
    /// arithmetic) and as it is (f64), which the environment sees.
    fn tool(&self) -> ([f64; 3], [f64; 3]);

    /// The tool frame in the arm's own frame (the paper's arm: the paper's frame, the
    /// true tool, no orientation; a URDF arm: its base frame), which is a physics
    /// world's frame: the world is built around the arm.
    fn tool_frame(&self) -> tactile_world::Pose {
        tactile_world::Pose {
            position: self.tool().1,
            ..tactile_world::Pose::default()
        }
    }

    /// A point of the arm's frame in the master's, m (the paper's arm: the same).
    fn point_to_master(&self, p: [f64; 3]) -> [f64; 3] {
        p
    }

    /// Where the operator's clutch puts the tool relative to the master's handle, m in
    /// the master's frame (zero for an arm without a clutch): MMT's model is rendered
    /// against the handle, so it is sent shifted back by this.
    fn clutch_shift(&self) -> [f64; 3] {
        [0.0; 3]
    }

    /// FBF: the force of a contact at `surface` of `stiffness` (N/m per axis) on the
    /// tool at `tool`,
    /// as the operator is to feel it.
    fn contact_force(&self, surface: [f64; 3], tool: [f64; 3], stiffness: [f64; 3]) -> [f64; 3];

    /// A force-torque sensor's force or torque (the paper's robot's in the paper's
    /// frame, a URDF arm's in its base's axes) as the operator is to feel it.
    fn felt(&self, f: [f64; 3]) -> [f64; 3];

    /// The joint references a real robot is commanded.
    fn reference(&self) -> Joints;

    /// `c` with what the arm counts itself (the hardware's clocks, failed dynamics).
    fn counters(&self, c: SlaveCounters) -> SlaveCounters;

    /// The arm's state for the record after a step, whichever arm (the paper's: its
    /// three angles, their reference and FCS's torques): `torque` is h(n)'s, `master`
    /// the orientation followed. Inline, as every sample makes one.
    fn joints(&self, torque: [f64; 3], master: Option<[f64; 4]>) -> ArmJoints;

    /// The live view's sample of the step `view`.
    fn live(&self, view: SlaveView) -> SampleView;
}
