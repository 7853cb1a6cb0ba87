//! The message types, each with its ROS 2 type name, schema and CDR encoding (fields
//! in their definition's order, [`crate::schema`]). Vectors are `[x, y, z]`,
//! quaternions `[x, y, z, w]`.

use crate::cdr::{CdrError, CdrReader, CdrWriter};

/// A message Tactile publishes or records.
pub trait Message {
    /// The ROS 2 type, `pkg/msg/Type`.
    const TYPE: &'static str;
    /// Appends the fields (the writer holds the encapsulation header).
    fn encode(&self, w: &mut CdrWriter);
    /// The whole message in CDR.
    fn to_cdr(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.encode(&mut w);
        w.bytes().to_vec()
    }
}

/// A message Tactile takes in from a device or robot: decoded field by field, every
/// read checked, nothing left over (a peer's bytes are never trusted).
pub trait Decode: Sized {
    /// Reads the fields after the encapsulation header.
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;
    /// The whole message from CDR bytes; trailing bytes beyond alignment padding are
    /// an error.
    fn from_cdr(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let m = Self::decode(&mut r)?;
        r.finish()?;
        Ok(m)
    }
}

/// `builtin_interfaces/Time` (and `Duration`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `< 1e9`.
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds (saturating at i32 seconds, year 2038).
    pub fn from_ns(ns: u64) -> Time {
        Time {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    fn encode(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
}

impl Time {
    /// Nanoseconds (0 for a negative time).
    pub fn ns(&self) -> u64 {
        u64::try_from(self.sec).unwrap_or(0) * 1_000_000_000 + u64::from(self.nanosec)
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Time, CdrError> {
        Ok(Time {
            sec: r.i32()?,
            nanosec: r.u32()?,
        })
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Header {
    /// When the data holds.
    pub stamp: Time,
    /// The frame the data is expressed in.
    pub frame_id: String,
}

impl Header {
    /// A header at `ns` in `frame`.
    pub fn at(ns: u64, frame: &str) -> Header {
        Header {
            stamp: Time::from_ns(ns),
            frame_id: frame.to_string(),
        }
    }

    pub(crate) fn encode(&self, w: &mut CdrWriter) {
        self.stamp.encode(w);
        w.string(&self.frame_id);
    }

    pub(crate) fn decode(r: &mut CdrReader<'_>) -> Result<Header, CdrError> {
        Ok(Header {
            stamp: Time::decode(r)?,
            frame_id: r.string()?,
        })
    }
}

pub(crate) fn vec3(w: &mut CdrWriter, v: &[f64; 3]) {
    v.iter().for_each(|x| w.f64(*x));
}

pub(crate) fn read_vec3(r: &mut CdrReader<'_>) -> Result<[f64; 3], CdrError> {
    Ok([r.f64()?, r.f64()?, r.f64()?])
}

pub(crate) fn read_f64s(r: &mut CdrReader<'_>) -> Result<Vec<f64>, CdrError> {
    let n = r.seq_len()?;
    (0..n).map(|_| r.f64()).collect()
}

pub(crate) fn quat(w: &mut CdrWriter, q: &[f64; 4]) {
    q.iter().for_each(|x| w.f64(*x));
}

pub(crate) fn f64s(w: &mut CdrWriter, v: &[f64]) {
    w.seq_len(v.len());
    v.iter().for_each(|x| w.f64(*x));
}

/// The identity rotation.
pub const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

/// `std_msgs/msg/String`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StringMsg {
    /// The text.
    pub data: String,
}

impl Message for StringMsg {
    const TYPE: &'static str = "std_msgs/msg/String";
    fn encode(&self, w: &mut CdrWriter) {
        w.string(&self.data);
    }
}

/// `sensor_msgs/msg/JointState`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointState {
    /// Stamp and frame.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Angles, rad.
    pub position: Vec<f64>,
    /// Angular velocities, rad/s.
    pub velocity: Vec<f64>,
    /// Torques, N m.
    pub effort: Vec<f64>,
}

impl Message for JointState {
    const TYPE: &'static str = "sensor_msgs/msg/JointState";
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.seq_len(self.name.len());
        self.name.iter().for_each(|n| w.string(n));
        f64s(w, &self.position);
        f64s(w, &self.velocity);
        f64s(w, &self.effort);
    }
}

impl Decode for JointState {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let header = Header::decode(r)?;
        let n = r.seq_len()?;
        let name = (0..n).map(|_| r.string()).collect::<Result<_, _>>()?;
        Ok(JointState {
            header,
            name,
            position: read_f64s(r)?,
            velocity: read_f64s(r)?,
            effort: read_f64s(r)?,
        })
    }
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// Position, m.
    pub position: [f64; 3],
    /// Orientation.
    pub orientation: [f64; 4],
}

impl Message for PoseStamped {
    const TYPE: &'static str = "geometry_msgs/msg/PoseStamped";
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        vec3(w, &self.position);
        quat(w, &self.orientation);
    }
}

/// `geometry_msgs/msg/WrenchStamped`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WrenchStamped {
    /// Stamp and frame.
    pub header: Header,
    /// Force, N.
    pub force: [f64; 3],
    /// Torque, N m.
    pub torque: [f64; 3],
}

impl Message for WrenchStamped {
    const TYPE: &'static str = "geometry_msgs/msg/WrenchStamped";
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        vec3(w, &self.force);
        vec3(w, &self.torque);
    }
}

impl Decode for WrenchStamped {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(WrenchStamped {
            header: Header::decode(r)?,
            force: read_vec3(r)?,
            torque: read_vec3(r)?,
        })
    }
}

/// `std_msgs/msg/Float64MultiArray` with an empty layout (a flat array, as
/// ros2_control's forward command controllers take it).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Float64MultiArray {
    /// The values.
    pub data: Vec<f64>,
}

impl Message for Float64MultiArray {
    const TYPE: &'static str = "std_msgs/msg/Float64MultiArray";
    fn encode(&self, w: &mut CdrWriter) {
        w.seq_len(0); // layout.dim
        w.u32(0); // layout.data_offset
        f64s(w, &self.data);
    }
}

impl Decode for Float64MultiArray {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        for _ in 0..r.seq_len()? {
            r.string()?;
            r.u32()?;
            r.u32()?;
        }
        r.u32()?;
        Ok(Float64MultiArray {
            data: read_f64s(r)?,
        })
    }
}

/// `trajectory_msgs/msg/JointTrajectory` of one point, as a joint_trajectory_controller
/// takes a streamed reference: the joints by name, where they should be and how fast
/// they should move `time_from_start` after the header's stamp (zero: on receipt).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointTrajectory {
    /// Stamp (zero: start at once) and frame (empty).
    pub header: Header,
    /// The joints the point's values belong to, in their order.
    pub joint_names: Vec<String>,
    /// Positions, rad or m.
    pub positions: Vec<f64>,
    /// Velocities, rad/s or m/s (empty: none given).
    pub velocities: Vec<f64>,
    /// When the point is to be reached, after the stamp.
    pub time_from_start: Time,
}

impl Message for JointTrajectory {
    const TYPE: &'static str = "trajectory_msgs/msg/JointTrajectory";
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.seq_len(self.joint_names.len());
        self.joint_names.iter().for_each(|n| w.string(n));
        w.seq_len(1); // points
        f64s(w, &self.positions);
        f64s(w, &self.velocities);
        f64s(w, &[]); // accelerations
        f64s(w, &[]); // effort
        self.time_from_start.encode(w);
    }
}

impl Decode for JointTrajectory {
    /// The first point (a trajectory of none reads as no positions).
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let header = Header::decode(r)?;
        let n = r.seq_len()?;
        let joint_names = (0..n).map(|_| r.string()).collect::<Result<_, _>>()?;
        let mut t = JointTrajectory {
            header,
            joint_names,
            ..JointTrajectory::default()
        };
        for k in 0..r.seq_len()? {
            let (p, v) = (read_f64s(r)?, read_f64s(r)?);
            read_f64s(r)?;
            read_f64s(r)?;
            let at = Time::decode(r)?;
            if k == 0 {
                (t.positions, t.velocities, t.time_from_start) = (p, v, at);
            }
        }
        Ok(t)
    }
}

/// `geometry_msgs/TransformStamped`: `child_frame_id` in `header.frame_id`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// The frame this transform places.
    pub child_frame_id: String,
    /// Its origin in the parent, m.
    pub translation: [f64; 3],
    /// Its rotation in the parent.
    pub rotation: [f64; 4],
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

impl Message for TfMessage {
    const TYPE: &'static str = "tf2_msgs/msg/TFMessage";
    fn encode(&self, w: &mut CdrWriter) {
        w.seq_len(self.transforms.len());
        for t in &self.transforms {
            t.header.encode(w);
            w.string(&t.child_frame_id);
            vec3(w, &t.translation);
            quat(w, &t.rotation);
        }
    }
}

/// `visualization_msgs/Marker`, the fields a shape needs (the rest empty).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Marker {
    /// Stamp and frame.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Shape: [`Marker::CUBE`], [`Marker::SPHERE`], ...
    pub kind: i32,
    /// Centre, m.
    pub position: [f64; 3],
    /// Orientation.
    pub orientation: [f64; 4],
    /// Size along the marker's axes, m.
    pub scale: [f64; 3],
    /// RGBA, 0 to 1.
    pub color: [f32; 4],
    /// A [`Marker::TRIANGLE_LIST`]'s corners, three a triangle, m in the marker's
    /// frame (empty for the other shapes).
    pub points: Vec<[f64; 3]>,
}

impl Marker {
    /// A box.
    pub const CUBE: i32 = 1;
    /// A sphere (an ellipsoid by `scale`).
    pub const SPHERE: i32 = 2;
    /// A cylinder along z (`scale`: diameters in x and y, length in z).
    pub const CYLINDER: i32 = 3;
    /// Triangles, `points` three a triangle (scaled by `scale`).
    pub const TRIANGLE_LIST: i32 = 11;

    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.string(&self.ns);
        w.i32(self.id);
        w.i32(self.kind);
        w.i32(0); // ADD
        vec3(w, &self.position);
        quat(w, &self.orientation);
        vec3(w, &self.scale);
        self.color.iter().for_each(|c| w.f32(*c));
        Time::default().encode(w); // lifetime 0: forever
        w.bool(false); // frame_locked
        w.seq_len(self.points.len());
        self.points.iter().for_each(|p| vec3(w, p));
        w.seq_len(0); // colors
        w.string(""); // texture_resource
        Header::default().encode(w); // texture: header, format, data
        w.string("");
        w.seq_len(0);
        w.seq_len(0); // uv_coordinates
        w.string(""); // text
        w.string(""); // mesh_resource
        w.string(""); // mesh_file: filename, data
        w.seq_len(0);
        w.bool(false); // mesh_use_embedded_materials
    }
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MarkerArray {
    /// The markers.
    pub markers: Vec<Marker>,
}

impl Message for MarkerArray {
    const TYPE: &'static str = "visualization_msgs/msg/MarkerArray";
    fn encode(&self, w: &mut CdrWriter) {
        w.seq_len(self.markers.len());
        self.markers.iter().for_each(|m| m.encode(w));
    }
}

/// `tactile_msgs/msg/SampleTiming`: one sample's timing and channel state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SampleTiming {
    /// Sample number n.
    pub sample: u64,
    /// Whether q(n) came back.
    pub answered: bool,
    /// Round trip, ns (0 without an answer).
    pub round_trip_ns: i64,
    /// Round trip minus the injected delay, ns.
    pub overhead_ns: i64,
    /// Delay injected into v(n) per axis, samples.
    pub delay_forward: [u32; 3],
    /// Delay injected into q(n) per axis, samples.
    pub delay_backward: [u32; 3],
    /// Flags of v(n) as the slave received it (1: substituted, the channel held a
    /// value: a gap, a deadband, a delay's start-up).
    pub flags_forward: u32,
    /// Flags of q(n) as the master received it.
    pub flags_backward: u32,
    /// The master's own flags.
    pub flags_master: u32,
    /// The master's passivity observer per axis, J.
    pub observer_master: [f64; 3],
    /// The slave's passivity observer per axis, J.
    pub observer_slave: [f64; 3],
}

impl Message for SampleTiming {
    const TYPE: &'static str = "tactile_msgs/msg/SampleTiming";
    fn encode(&self, w: &mut CdrWriter) {
        w.u64(self.sample);
        w.bool(self.answered);
        w.i64(self.round_trip_ns);
        w.i64(self.overhead_ns);
        self.delay_forward.iter().for_each(|d| w.u32(*d));
        self.delay_backward.iter().for_each(|d| w.u32(*d));
        w.u32(self.flags_forward);
        w.u32(self.flags_backward);
        w.u32(self.flags_master);
        vec3(w, &self.observer_master);
        vec3(w, &self.observer_slave);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::CdrReader;

    #[test]
    fn a_joint_state_reads_back_field_by_field() {
        let js = JointState {
            header: Header::at(1_500_000_001, "base"),
            name: vec!["j1".into()],
            position: vec![0.25],
            velocity: vec![],
            effort: vec![-1.0],
        };
        let b = js.to_cdr();
        let mut r = CdrReader::new(&b).expect("header");
        assert_eq!((r.i32(), r.u32()), (Ok(1), Ok(500_000_001)));
        assert_eq!(r.string().as_deref(), Ok("base"));
        assert_eq!(r.seq_len(), Ok(1));
        assert_eq!(r.string().as_deref(), Ok("j1"));
        assert_eq!((r.seq_len(), r.f64()), (Ok(1), Ok(0.25)));
        assert_eq!(r.seq_len(), Ok(0));
        assert_eq!((r.seq_len(), r.f64()), (Ok(1), Ok(-1.0)));
        assert!(r.u8().is_err(), "nothing after the last field");
    }

    #[test]
    fn decoding_reads_back_what_encoding_wrote_and_refuses_the_rest() {
        let js = JointState {
            header: Header::at(7_000_000_123, "base"),
            name: vec!["waist".into(), "shoulder".into()],
            position: vec![0.5, -1.25],
            velocity: vec![],
            effort: vec![0.1, 0.2],
        };
        let b = js.to_cdr();
        assert_eq!(JointState::from_cdr(&b), Ok(js));
        let w = WrenchStamped {
            header: Header::at(1, "base"),
            force: [1.0, -2.0, 3.5],
            torque: [0.0; 3],
        };
        assert_eq!(WrenchStamped::from_cdr(&w.to_cdr()), Ok(w));
        let a = Float64MultiArray {
            data: vec![0.1, 0.2, 0.3],
        };
        assert_eq!(Float64MultiArray::from_cdr(&a.to_cdr()), Ok(a));
        let t = JointTrajectory {
            header: Header::at(0, ""),
            joint_names: vec!["a".into(), "b".into()],
            positions: vec![0.5, -1.0],
            velocities: vec![0.1, 0.2],
            time_from_start: Time::from_ns(1_000_000),
        };
        assert_eq!(JointTrajectory::from_cdr(&t.to_cdr()), Ok(t));
        for cut in 0..b.len() {
            assert!(JointState::from_cdr(&b[..cut]).is_err(), "cut at {cut}");
        }
        let mut long = b.clone();
        long.extend_from_slice(&[0; 16]);
        assert!(JointState::from_cdr(&long).is_err(), "trailing bytes");
    }

    #[test]
    fn every_type_has_a_schema() {
        for t in [
            StringMsg::TYPE,
            JointState::TYPE,
            PoseStamped::TYPE,
            WrenchStamped::TYPE,
            TfMessage::TYPE,
            MarkerArray::TYPE,
            SampleTiming::TYPE,
            Float64MultiArray::TYPE,
        ] {
            assert!(crate::schema::ros2msg(t).is_some(), "{t}");
        }
    }
}
