//! The slave's record: one schema for what it received, computed and commanded. The
//! report joins it with the master's and the emulator's records by sample number.

use serde::{Deserialize, Serialize};
use tactile_math::hardware::Clocks;
use tactile_math::joints::Joints;
use tactile_messages::samples::{Flags, Model, Signal};
use tactile_messages::stream::{InboxStats, OutboxStats};

/// What the slave counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SlaveCounters {
    /// Steps taken.
    pub steps: u64,
    /// Targets outside the workspace: IK clamped.
    pub ik_clamped: u64,
    /// Samples not physically possible (not finite, too large, too fast, out of
    /// order), rejected and filled by the predictor; or outside the workspace (IK);
    /// or whose orientation is no rotation. A sample counts once.
    pub rejected: u64,
    /// Joint torque clamps (one per joint per step).
    pub torque_clamps: u64,
    /// Steps in contact with an object.
    pub contact_steps: u64,
    /// Steps taken holding position because the input went silent.
    pub held_steps: u64,
    /// Times the input went silent and the slave started holding.
    pub holds: u64,
    /// Largest distance the tool moved while holding, m.
    pub hold_drift_max_m: f64,
    /// Backward samples the codec put on the network (the others went as clock only).
    pub packets_sent: u64,
    /// `control.kind = "mmt"`: environment models sent (each a changed estimate; every
    /// sample carries the last one).
    pub models_sent: u64,
    /// A URDF arm (`[slave.arm]`): IK calls a joint limit clamped.
    pub ik_joint_limited: u64,
    /// A URDF arm: IK calls the joints' velocity limits shortened.
    pub ik_velocity_limited: u64,
    /// A URDF arm: IK calls that damped near a singularity.
    pub ik_damped: u64,
    /// Targets outside the arm's workspace box, clamped onto it.
    pub workspace_clamped: u64,
    /// A URDF arm: periods whose dynamics step failed (not finite, a singular mass
    /// matrix); the arm stood still in each, so a report must say so.
    pub dynamics_failed: u64,
    /// `arithmetic = "rtl"`: the clocks IK-HSD, FK-HSD and FBF-HSD spent (zero
    /// otherwise).
    pub rtl: Clocks,
}

/// One step on a received v(n).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Step {
    /// Sample number of v(n).
    pub n: u64,
    /// v(n) as received (values, provenance, injected delay, flags).
    pub received: Signal,
    /// The control's Cartesian reference (the received position itself without
    /// control), m.
    pub reference: [f64; 3],
    /// FK-HSD tool position l(n), m.
    pub tool: [f64; 3],
    /// Nearest surface point s^OBJ(n), m (zero without contact).
    pub surface: [f64; 3],
    /// h(n) before the backward channel, N.
    pub force: [f64; 3],
    /// The slave's passivity observer per axis after this step, J.
    pub observer: [f64; 3],
    /// Energy the slave's port has put into the channel minus what it took out, all
    /// axes, J (its share of the channel's energy).
    pub port_net_j: f64,
    /// Energy the control dissipated this step, J.
    pub dissipated_j: f64,
    /// Torque clamps this step.
    pub clamps: u32,
    /// Object index in contact, or u32::MAX.
    pub contact_object: u32,
    /// The flags of h(n): the slave's notes on its step, and h(n)'s payload's.
    pub flags: Flags,
    /// `control.kind = "mmt"`: the model h(n) carried (the last sent; `seq` 0: none).
    pub model: Model,
}

/// One step of holding position while the input is silent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HoldStep {
    /// Held steps so far in the run.
    pub step: u64,
    /// Tool position (true device), m.
    pub tool: [f64; 3],
}

/// The arm after a step, whichever arm it is: its joints in their order (the paper's
/// arm's three angles theta, their reference theta_ref from IK-HSD and FCS's torques
/// u; a URDF arm's chain), and for a URDF arm its tool's targets and clutch. One arm
/// state for every arm: the step's record has no paper-only fields. Inline (its joints
/// are [`Joints`], at most [`tactile_math::joints::MAX_JOINTS`], which the arm's
/// loader refuses beyond): making one allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ArmJoints {
    /// The IK's joint references, rad or m (the paper's arm: theta_ref).
    pub q_ref: Joints,
    /// Joint values, rad or m (the paper's arm: theta^SD).
    pub q: Joints,
    /// Efforts the servo applied, N m or N (the paper's arm: FCS's torques u).
    pub tau: Joints,
    /// h(n)'s torque about the tool in the base's axes (a real arm's sensor's; zero
    /// for the simulated point contact), N m.
    pub torque: [f64; 3],
    /// The tool's orientation reference relative to its home, about the base's axes,
    /// `[x, y, z, w]` (a 6-DoF master's rotation, moved by the clutch's offsets; the
    /// identity for a 3-DoF master).
    pub target_rotation: [f64; 4],
    /// The tool's orientation (FK of the joints) relative to its home, `[x, y, z, w]`.
    pub tool_rotation: [f64; 4],
    /// The tool's position target in the arm's base frame, m: the master's position
    /// through the map, moved by the clutch's offset and clamped into the workspace
    /// box; while released, the reference the robot holds. What the report's
    /// task-space tracking error measures the tool against (the step's `reference`
    /// is v(n) in the master's frame, which knows neither offsets nor box).
    pub target_position: [f64; 3],
    /// The tool's position (FK of the joints) in the arm's base frame, m.
    pub tool_position: [f64; 3],
    /// The 6-DoF master's orientation the arm follows (relative to the operator's
    /// home, about the master base's axes), as last accepted; the identity for a 3-DoF
    /// master.
    pub master_rotation: [f64; 4],
    /// The clutch's position offset captured at the last engage, m in the base frame:
    /// where the master's mapped position met the robot's held reference (zero before
    /// the first release).
    pub offset: [f64; 3],
    /// The clutch's orientation offset captured then, `[x, y, z, w]` (applied on the
    /// right of the mapped orientation).
    pub offset_rotation: [f64; 4],
    /// The operator's clutch was released: the references held.
    pub released: bool,
}

/// Moving bodies' poses one sample's record holds at most: a world of more moving
/// bodies records them in turns (`ceil(n / BODIES_PER_SAMPLE)` samples for all), so a
/// record's row keeps one bounded, inline size whatever the scene.
pub const BODIES_PER_SAMPLE: usize = 16;

/// Joints' positions one sample's record holds at most (in turns beyond, as bodies).
pub const JOINTS_PER_SAMPLE: usize = 8;

/// A body's pose in the world's frame (the arm's base frame; the paper's arm: the
/// paper's frame): its centre, m, and orientation `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyPose {
    /// Centre, m.
    pub position: [f64; 3],
    /// Orientation, `[x, y, z, w]`.
    pub rotation: [f64; 4],
}

impl Default for BodyPose {
    fn default() -> Self {
        BodyPose {
            position: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

/// The task's state after a sample (`[task]`): what `TaskMonitor` measured.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TaskSample {
    /// Distance to the goal (m; rad or m for a joint), 0 or less when met.
    pub distance: f64,
    /// Whether the goal is met in this sample.
    pub met: bool,
    /// Whether the task has succeeded (met and held) by this sample.
    pub success: bool,
}

/// A physics world after a sample (`engine = "physics"`): the tool body's pose, the
/// moving (dynamic and kinematic) bodies' poses in the order of
/// `[[environment.bodies]]` with the static ones left out (they never move: the
/// scenario places them), the joints' positions, and the task's state. Inline and
/// bounded ([`BODIES_PER_SAMPLE`], [`JOINTS_PER_SAMPLE`]): making one allocates
/// nothing. Rows that hold no world (the analytic scene) carry none.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WorldSample {
    /// The tool body's pose (where the coupling pulled it, not the arm's tool frame).
    pub tool: BodyPose,
    /// Index among the moving bodies of `poses[0]`.
    pub first_body: u32,
    /// How many of `poses` hold a body.
    pub bodies: u32,
    /// The moving bodies' poses from `first_body` on.
    pub poses: [BodyPose; BODIES_PER_SAMPLE],
    /// Index among `[[environment.joints]]` of `joint_positions[0]`.
    pub first_joint: u32,
    /// How many of `joint_positions` hold a joint.
    pub joints: u32,
    /// The joints' positions from the start (rad or m).
    pub joint_positions: [f64; JOINTS_PER_SAMPLE],
    /// The task's state, if the scenario has a `[task]`.
    pub task: Option<TaskSample>,
}

impl WorldSample {
    /// The moving bodies this sample holds: (index among the moving bodies, pose).
    pub fn poses(&self) -> impl Iterator<Item = (usize, &BodyPose)> {
        let n = (self.bodies as usize).min(BODIES_PER_SAMPLE);
        let first = self.first_body as usize;
        self.poses[..n]
            .iter()
            .enumerate()
            .map(move |(k, p)| (first + k, p))
    }

    /// The joints this sample holds: (index among the joints, position).
    pub fn joint_positions(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        let n = (self.joints as usize).min(JOINTS_PER_SAMPLE);
        let first = self.first_joint as usize;
        self.joint_positions[..n]
            .iter()
            .enumerate()
            .map(move |(k, q)| (first + k, *q))
    }
}

/// One entry per step the slave took, with the arm's state after it. A sample lives
/// for one write or one read, and is made on every step: nothing in it is boxed, so
/// making one allocates nothing (a hold is as large as a step: the arm's state is
/// most of either, and a copy of a kilobyte is well under a microsecond).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum SlaveSample {
    /// A step on v(n), with a physics world's state after it.
    Step(Step, ArmJoints, Option<WorldSample>),
    /// A step holding position (a physics world steps on while the input is silent).
    Hold(HoldStep, ArmJoints, Option<WorldSample>),
}

impl SlaveSample {
    /// The step on v(n), if this is one.
    pub fn step(&self) -> Option<&Step> {
        match self {
            SlaveSample::Step(s, ..) => Some(s),
            SlaveSample::Hold(..) => None,
        }
    }

    /// The arm after the step, whichever it was.
    pub fn joints(&self) -> &ArmJoints {
        match self {
            SlaveSample::Step(_, j, _) | SlaveSample::Hold(_, j, _) => j,
        }
    }

    /// A physics world's state after the step, if the slave steps one.
    pub fn world(&self) -> Option<&WorldSample> {
        match self {
            SlaveSample::Step(.., w) | SlaveSample::Hold(.., w) => w.as_ref(),
        }
    }
}

/// The slave's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SlaveTotals {
    /// The state machine's counters.
    pub counters: SlaveCounters,
    /// v(n) as received.
    pub v_in: InboxStats,
    /// h(n) as published.
    pub h_out: OutboxStats,
    /// A real robot (`slave.backend = "ros2"`): what it delivered and how the loop
    /// judged it; all zero with the simulated arm.
    pub device: crate::device::DeviceCounters,
    /// A physics world (`[environment] engine = "physics"`): what went wrong in it and
    /// the task's outcome; all zero (and `physics` false) with the analytic scene.
    pub world: WorldCounters,
}

/// What a physics world counted over a run (docs/16): its faults, each also named in
/// the record's events, and the task's outcome.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WorldCounters {
    /// Whether the slave stepped a physics world at all.
    pub physics: bool,
    /// Dynamic bodies that left the world's bounds (taken out).
    pub left_bounds: u64,
    /// Episodes of energy rising without a source (explosions).
    pub energy_gains: u64,
    /// Bodies whose state became non-finite (taken out).
    pub non_finite: u64,
    /// Samples whose tool frame came in non-finite (the last good one held).
    pub bad_inputs: u64,
    /// Engine failures (at most one: the world froze).
    pub engine_failures: u64,
    /// Samples whose force to the operator was ramped down after a fault.
    pub ramped_steps: u64,
    /// The `[task]`'s outcome, if the scenario has one.
    pub task: Option<TaskResult>,
}

/// A `[task]`'s outcome over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TaskResult {
    /// Whether the goal was met and held for the task's `hold_s`.
    pub success: bool,
    /// Seconds from the start to the end of the first such hold.
    pub completion_s: Option<f64>,
    /// The distance to the goal at the last sample (m, or rad for a hinge).
    pub distance: f64,
    /// The closest the run came to the goal.
    pub closest: f64,
    /// Samples the task was evaluated on.
    pub steps: u64,
}

/// The slave's record type.
pub type SlaveRecord = crate::Record<SlaveSample, SlaveTotals>;

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_math::joints::Joints;

    /// The paper's arm's three angles are an arm state like any other: its joints of
    /// length 3 round-trip through the record's encodings.
    #[test]
    fn a_paper_arms_joints_round_trip_as_any_arms() {
        let j = ArmJoints {
            q_ref: Joints::from([0.1, -0.2, 0.3]),
            q: Joints::from([0.5, -1.25, 2.0]),
            tau: Joints::from([1e-300, -0.0, 0.45]),
            ..ArmJoints::default()
        };
        let step = Step {
            n: 123_456,
            clamps: 3,
            ..Step::default()
        };
        for sample in [
            SlaveSample::Step(step, j, None),
            SlaveSample::Hold(
                HoldStep {
                    step: 7,
                    tool: [0.1; 3],
                },
                j,
                None,
            ),
            SlaveSample::Step(step, j, Some(world())),
        ] {
            let config = bincode::config::standard();
            let bytes = bincode::serde::encode_to_vec(&sample, config).expect("encode");
            let (back, _): (SlaveSample, usize) =
                bincode::serde::decode_from_slice(&bytes, config).expect("decode");
            assert_eq!(back, sample);
            assert_eq!(back.joints().q.len(), 3);
        }
    }

    fn world() -> WorldSample {
        let mut w = WorldSample {
            first_body: 16,
            bodies: 2,
            first_joint: 0,
            joints: 1,
            task: Some(TaskSample {
                distance: 0.25,
                met: false,
                success: true,
            }),
            ..WorldSample::default()
        };
        w.poses[0].position = [0.1, -0.2, 0.3];
        w.poses[1].rotation = [0.0, 0.0, 0.6, 0.8];
        w.joint_positions[0] = -0.5;
        w
    }

    /// A world's row names its bodies by their index among the moving ones, from
    /// `first_body`, and only as many as it holds (a crafted count past the array is
    /// cut to it).
    #[test]
    fn a_world_sample_hands_out_the_bodies_it_holds() {
        let mut w = world();
        let held: Vec<usize> = w.poses().map(|(k, _)| k).collect();
        assert_eq!(held, [16, 17]);
        assert_eq!(w.poses().nth(1).map(|(_, p)| p.rotation[3]), Some(0.8));
        assert_eq!(w.joint_positions().collect::<Vec<_>>(), [(0, -0.5)]);
        w.bodies = u32::MAX;
        w.joints = u32::MAX;
        assert_eq!(w.poses().count(), BODIES_PER_SAMPLE);
        assert_eq!(w.joint_positions().count(), JOINTS_PER_SAMPLE);
    }
}
