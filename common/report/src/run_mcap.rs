//! `run.mcap`: the run as ROS 2 messages (tactile-ros's topics) in an MCAP file,
//! streamed sample by sample from the joined records, so Foxglove, Rerun and
//! `ros2 bag` open it. Log time is the sample's time on the master's clock (its tick
//! stamp); in lockstep, where samples run as fast as the machine goes, it is the
//! sample's nominal time on that clock (`n t_s` after the first tick), so a viewer
//! plays the run at the speed it simulates. Publish time the stamp of the stage that produced the message (the slave's
//! send for its messages, the master's receive for q(n)), or the log time where that
//! stage was not passed. Header stamps are the log time.

use crate::arm_scene::ArmScene;
use crate::body_scene::BodyScene;
use crate::join::Joined;
use crate::mcap::McapWriter;
use crate::trace::TraceRow;
use std::io::{self, Write};
use tactile_math::geometry::Geometry;
use tactile_messages::samples::stage;
use tactile_records::slave::ArmJoints;
use tactile_ros::msg::{
    Header, Marker, MarkerArray, SampleTiming, StringMsg, TfMessage, TransformStamped, IDENTITY,
};
use tactile_ros::topics::TOPICS;
use tactile_ros::view::{self, ArmView, At, MasterView, SampleView, SlaveView, Typed};
use tactile_ros::{arm, schema, urdf, CdrWriter, Message};
use tactile_scenario::Object;
use tactile_scenario::{Mode, Scenario};

/// A URDF arm's joint values at a sample.
type Joints = (u64, Vec<f64>);

/// The recording's file name in a report folder.
pub const FILE: &str = "run.mcap";

/// Writes a run's messages to an MCAP file.
#[derive(Debug)]
pub struct Recording<W: Write> {
    mcap: McapWriter<W>,
    channels: Vec<u16>,
    geometry: Geometry,
    objects: Vec<Object>,
    /// The slave as a URDF arm, with its joints' last values and the sample they
    /// came from (the velocities' previous values); None for the paper's arm.
    arm: Option<(ArmScene, Vec<f64>, Option<Joints>)>,
    /// A physics world's bodies (`engine = "physics"`).
    bodies: Option<BodyScene>,
    rate_hz: u64,
    t_s_ns: f64,
    /// Lockstep: log times are nominal, `n t_s` after the first sample's tick.
    nominal: Option<Option<u64>>,
    /// The previous sample: n and both arms' angles (for the velocities).
    prev: Option<(u64, [f64; 3], [f64; 3])>,
    sequence: u32,
    cdr: CdrWriter,
}

impl<W: Write> Recording<W> {
    /// Compresses the chunks from here on with `c`.
    pub fn compress_with(&mut self, c: crate::mcap::Compression) {
        self.mcap.compress_with(c);
    }

    /// Starts the file with a channel per topic; `arm` draws a URDF slave, `bodies`
    /// a physics world (in the frame the arm is drawn in: [`Recording::frame`]).
    pub fn new(
        out: W,
        scenario: &Scenario,
        arm: Option<ArmScene>,
        bodies: Option<BodyScene>,
    ) -> io::Result<Self> {
        let geometry = scenario.device.geometry().map_err(io::Error::other)?;
        let library = concat!("tactile ", env!("CARGO_PKG_VERSION"));
        let mut mcap = McapWriter::new(out, "ros2", library)?;
        let mut schemas: Vec<(&str, u16)> = Vec::new();
        let mut channels = Vec::new();
        for t in TOPICS {
            let id = match schemas.iter().find(|(ty, _)| *ty == t.ty) {
                Some((_, id)) => *id,
                None => {
                    let text = schema::ros2msg(t.ty).unwrap_or_default();
                    let id = mcap.schema(t.ty, "ros2msg", text.as_bytes())?;
                    schemas.push((t.ty, id));
                    id
                }
            };
            channels.push(mcap.channel(t.name, id, "cdr")?);
        }
        Ok(Recording {
            mcap,
            channels,
            geometry,
            objects: scenario.environment.objects.clone(),
            arm: arm.map(|a| {
                let home = scenario
                    .slave
                    .arm
                    .as_ref()
                    .map_or_else(Vec::new, |c| c.home.clone());
                (a, home, None)
            }),
            bodies,
            rate_hz: (scenario.rate_hz.round() as u64).max(1),
            t_s_ns: scenario.t_s() * 1e9,
            nominal: (scenario.mode == Mode::Lockstep).then_some(None),
            prev: None,
            sequence: 0,
            cdr: CdrWriter::new(),
        })
    }

    fn put<M: Message>(
        &mut self,
        topic: Typed<M>,
        m: &M,
        log: u64,
        publish: u64,
    ) -> io::Result<()> {
        self.cdr.reset();
        m.encode(&mut self.cdr);
        self.sequence = self.sequence.wrapping_add(1);
        self.mcap.message(
            self.channels[topic.index()],
            self.sequence,
            log,
            publish,
            self.cdr.bytes(),
        )
    }

    /// Adds one sample's messages; `joints` are a URDF arm's (a row without them
    /// draws the arm where it last was).
    pub fn add(&mut self, row: &TraceRow, joined: &Joined) -> io::Result<()> {
        let (joints, rotation) = (joined.joints, joined.rotation);
        let log = self.log_time(row);
        if self.prev.is_none() {
            self.first(log)?;
        }
        if row.n.is_multiple_of(self.rate_hz) || self.prev.is_none() {
            self.environment(log)?;
        }
        if let (Some(scene), Some(w)) = (self.bodies.as_mut(), joined.world) {
            let markers = scene.moving(w, log);
            self.put(view::SLAVE_BODIES, &MarkerArray { markers }, log, log)?;
        }
        let (vm, vs) = self.velocities(row);
        let arm_velocity = self.arm_velocity(row.n, joints);
        self.put(view::TF, &self.transforms(row, log), log, log)?;
        let sample = SampleView {
            master: Some(MasterView {
                theta: row.theta_md,
                velocity: Some(vm),
                tau: row.tau,
                target: row.target,
                handle: row.handle,
                rotation: rotation.unwrap_or(tactile_ros::msg::IDENTITY),
                q: row.q,
                felt: row.felt,
            }),
            slave: self.arm.is_none().then_some(SlaveView {
                theta: row.theta_sd,
                velocity: Some(vs),
                torque: row.u,
                tool: row.tool,
                force: row.h,
            }),
            // A URDF arm's part is emitted below, borrowed (no copy of its joints).
            arm: None,
            timing: Some(timing(row)),
        };
        let arm = self.arm.take();
        let mut sink = Stamped {
            rec: self,
            log,
            stamps: row.stamps.0,
        };
        let done = sample.emit(log, &mut sink).and_then(|()| match &arm {
            Some((scene, q, _)) => ArmView {
                base: &scene.base,
                names: &scene.names,
                q,
                velocity: Some(&arm_velocity),
                effort: joints.map_or(&[][..], |j| &j.tau[..]),
                tool: scene.to_robot(row.tool),
                force: row.h,
            }
            .emit(log, &mut sink),
            None => Ok(()),
        });
        self.arm = arm;
        done
    }

    /// A URDF arm's joints taken from the row (kept where it has none) and their
    /// backward differences, rad/s (0 at the first sample and after a gap of joints).
    fn arm_velocity(&mut self, n: u64, joints: Option<&ArmJoints>) -> Vec<f64> {
        let t_s = self.t_s_ns * 1e-9;
        let Some((_, q, prev)) = &mut self.arm else {
            return Vec::new();
        };
        let Some(j) = joints.filter(|j| j.q.len() == q.len()) else {
            return vec![0.0; q.len()];
        };
        q.copy_from_slice(&j.q);
        let v = match prev.as_ref() {
            Some((m, before)) if n > *m => {
                let dt = (n - m) as f64 * t_s;
                q.iter().zip(before).map(|(a, b)| (a - b) / dt).collect()
            }
            _ => vec![0.0; q.len()],
        };
        *prev = Some((n, q.clone()));
        v
    }

    /// The sample's log time: its tick on the master's clock, or in lockstep its
    /// nominal time after the first tick.
    fn log_time(&mut self, row: &TraceRow) -> u64 {
        let tick = row.stamps[stage::MASTER_TICK];
        let nominal = (row.n as f64 * self.t_s_ns) as u64;
        match &mut self.nominal {
            // The origin is the first sample's tick less its own nominal time.
            Some(origin) => *origin.get_or_insert(tick.saturating_sub(nominal)) + nominal,
            None if tick > 0 => tick,
            None => nominal,
        }
    }

    /// Both arms' link transforms at the row's angles (a URDF arm's at its joints).
    fn transforms(&self, row: &TraceRow, log: u64) -> TfMessage {
        let mut links = arm::links(&self.geometry, "master", row.theta_md).to_vec();
        match &self.arm {
            Some((scene, q, _)) => links.extend(scene.links(q)),
            None => links.extend(arm::links(&self.geometry, "slave", row.theta_sd)),
        }
        TfMessage {
            transforms: links.into_iter().map(|l| stamped(l, log)).collect(),
        }
    }

    /// Backward differences of both arms' angles, rad/s (0 at the first sample).
    fn velocities(&mut self, row: &TraceRow) -> ([f64; 3], [f64; 3]) {
        let v = match self.prev {
            Some((n, m, s)) if row.n > n => {
                let dt = (row.n - n) as f64 * self.t_s_ns * 1e-9;
                (
                    [0, 1, 2].map(|k| (row.theta_md[k] - m[k]) / dt),
                    [0, 1, 2].map(|k| (row.theta_sd[k] - s[k]) / dt),
                )
            }
            _ => ([0.0; 3], [0.0; 3]),
        };
        self.prev = Some((row.n, row.theta_md, row.theta_sd));
        v
    }

    /// The messages sent once: the URDF and the transforms that never move.
    fn first(&mut self, log: u64) -> io::Result<()> {
        let (data, fixed) = match &self.arm {
            Some((scene, _, _)) => {
                let mut fixed = arm::fixed_of(&self.geometry, &["master"]);
                fixed.extend(scene.fixed());
                (scene.description().to_string(), fixed)
            }
            None => (urdf::urdf(&self.geometry), arm::fixed(&self.geometry)),
        };
        self.put(view::ROBOT_DESCRIPTION, &StringMsg { data }, log, log)?;
        let transforms = fixed.into_iter().map(|l| stamped(l, log)).collect();
        self.put(view::TF_STATIC, &TfMessage { transforms }, log, log)
    }

    /// The objects, in the paper slave's base frame or a URDF arm's (where the map
    /// from the loop puts them).
    fn environment(&mut self, log: u64) -> io::Result<()> {
        let mut markers: Vec<Marker> = self
            .objects
            .iter()
            .enumerate()
            .map(|(k, o)| match &self.arm {
                Some((scene, _, _)) => marker(&scene.object(o), &scene.base, k as i32, log),
                None => marker(o, view::SLAVE_BASE, k as i32, log),
            })
            .collect();
        if let Some(b) = &self.bodies {
            markers.extend(b.fixed(log));
        }
        self.put(view::SLAVE_ENVIRONMENT, &MarkerArray { markers }, log, log)
    }

    /// Writes the summary and the footer.
    pub fn finish(self) -> io::Result<W> {
        self.mcap.finish()
    }
}

/// A row's timing as the recording shows it.
fn timing(row: &TraceRow) -> SampleTiming {
    SampleTiming {
        sample: row.n,
        answered: row.received,
        round_trip_ns: i64::try_from(row.round_trip_ns).unwrap_or(i64::MAX),
        overhead_ns: row.overhead_ns,
        delay_forward: row.delay_f,
        delay_backward: row.delay_b,
        flags_forward: row.flags_f.bits(),
        flags_backward: row.flags_b.bits(),
        flags_master: row.flags_m.bits(),
        observer_master: row.observer_m,
        observer_slave: row.observer_s,
    }
}

/// A sample's messages into the recording, each published at its stage's stamp (or
/// the log time where that stage was not passed).
struct Stamped<'a, W: Write> {
    rec: &'a mut Recording<W>,
    log: u64,
    stamps: [u64; stage::COUNT],
}

impl<W: Write> view::Sink for Stamped<'_, W> {
    type Error = io::Error;
    fn put<M: Message>(&mut self, topic: Typed<M>, at: At, m: &M) -> io::Result<()> {
        let s = match at {
            At::MasterTick => stage::MASTER_TICK,
            At::SlaveSend => stage::SLAVE_SEND,
            At::MasterRecv => stage::MASTER_RECV,
            At::MasterDone => stage::MASTER_DONE,
        };
        let publish = match self.stamps[s] {
            0 => self.log,
            t => t,
        };
        self.rec.put(topic, m, self.log, publish)
    }
}

/// A recording being written to `dir/run.mcap.partial`, renamed to `run.mcap` when
/// it is whole, so a report that fails half-way leaves no truncated recording.
pub type FileRecording = Recording<std::io::BufWriter<std::fs::File>>;

/// Starts `dir/run.mcap.partial`; a URDF slave is drawn from its file. A URDF that
/// cannot be read (the records moved without their inputs) leaves the arm undrawn
/// rather than the run unreported: the second value says why, for the summary.
pub fn create(
    dir: &std::path::Path,
    scenario: &Scenario,
    compression: crate::mcap::Compression,
) -> io::Result<(FileRecording, Option<String>)> {
    let (arm, mut warning) = match ArmScene::of_scenario(scenario) {
        Ok(arm) => (arm, None),
        Err(e) => (
            None,
            Some(format!("run.mcap: the slave arm is not drawn: {e}")),
        ),
    };
    let frame = frame(arm.as_ref());
    let bodies = BodyScene::of(scenario, frame).unwrap_or_else(|e| {
        warning.get_or_insert(format!("run.mcap: the world's bodies are not drawn: {e}"));
        None
    });
    let f = std::fs::File::create(dir.join(format!("{FILE}.partial")))?;
    let w = std::io::BufWriter::with_capacity(1 << 16, f);
    let mut rec = Recording::new(w, scenario, arm, bodies)?;
    rec.compress_with(compression);
    Ok((rec, warning))
}

/// The frame a physics world's bodies are drawn in: the arm's base (the world's
/// frame is the arm's): the paper slave's `slave_base`, or a URDF arm's base link.
pub fn frame(arm: Option<&ArmScene>) -> &str {
    arm.map_or(view::SLAVE_BASE, |a| a.base.as_str())
}

/// A transform as `/tf` carries it.
fn stamped((parent, child, translation, rotation): arm::Link, log: u64) -> TransformStamped {
    TransformStamped {
        header: Header::at(log, &parent),
        child_frame_id: child,
        translation,
        rotation,
    }
}

/// Finishes a recording from [`create`] and gives it its name.
pub fn commit(rec: FileRecording, dir: &std::path::Path) -> io::Result<()> {
    let w = rec.finish()?;
    w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
    std::fs::rename(dir.join(format!("{FILE}.partial")), dir.join(FILE))
}

/// Removes a recording [`create`] started, after a failure.
pub fn discard(dir: &std::path::Path) {
    let _ = std::fs::remove_file(dir.join(format!("{FILE}.partial")));
}

/// An object as a marker in `frame`: a sphere, a box, or a plane as a thin 0.3 m
/// square.
fn marker(o: &Object, frame: &str, id: i32, log: u64) -> Marker {
    let (kind, position, orientation, scale) = match o {
        Object::Sphere { center, radius, .. } => {
            (Marker::SPHERE, *center, IDENTITY, [2.0 * radius; 3])
        }
        Object::Box {
            center,
            half_extents,
            ..
        } => (
            Marker::CUBE,
            *center,
            IDENTITY,
            half_extents.map(|h| 2.0 * h),
        ),
        Object::Plane { point, normal, .. } => {
            (Marker::CUBE, *point, z_to(*normal), [0.3, 0.3, 0.002])
        }
    };
    Marker {
        header: Header::at(log, frame),
        ns: "environment".into(),
        id,
        kind,
        position,
        orientation,
        scale,
        color: [0.6, 0.6, 0.65, 0.5],
        points: Vec::new(),
    }
}

/// The rotation taking z to the unit vector along `n`.
fn z_to(n: [f64; 3]) -> [f64; 4] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len == 0.0 || !len.is_finite() {
        return IDENTITY;
    }
    let [x, y, z] = n.map(|v| v / len);
    // Half-way quaternion between z and n: axis z x n, angle acos(z . n).
    let w = 1.0 + z;
    if w < 1e-12 {
        return [1.0, 0.0, 0.0, 0.0]; // n = -z: half a turn about x
    }
    let q = [-y, x, 0.0, w];
    let norm = (q[0] * q[0] + q[1] * q[1] + w * w).sqrt();
    q.map(|v| v / norm)
}
