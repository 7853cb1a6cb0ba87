//! The samples that cross process boundaries, laid out for zero-copy shared memory.
//!
//! Every type is `#[repr(C)]`, holds only plain numbers, and carries an explicit
//! iceoryx2 type name, so separately built binaries agree on the layout. A sample
//! carries, for each of its three values, the master sample it originates from, that
//! sample's timestamp and the delay injected on purpose, so the master can measure the
//! round trip on its own clock and subtract the injected delay. Each sample also
//! carries a timestamp per stage it passed.

use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

pub use crate::flags::{Control, Flags};

/// Stages a sample passes, in order; indices into `stamps`.
pub mod stage {
    /// Sample n's instant: its scheduled tick in realtime (so a late wake-up counts as
    /// overhead), the moment it starts in lockstep.
    pub const MASTER_TICK: usize = 0;
    /// Master publishes c(n) (after MD model and FK-HMD).
    pub const MASTER_SEND: usize = 1;
    /// Emulator takes c(n).
    pub const EMU_FWD_RECV: usize = 2;
    /// Emulator publishes v(n).
    pub const EMU_FWD_SEND: usize = 3;
    /// Slave takes v(n).
    pub const SLAVE_RECV: usize = 4;
    /// Slave publishes h(n) (after IK, controller, dynamics, FK, ENV, FBF).
    pub const SLAVE_SEND: usize = 5;
    /// Emulator takes h(n).
    pub const EMU_BWD_RECV: usize = 6;
    /// Emulator publishes q(n).
    pub const EMU_BWD_SEND: usize = 7;
    /// Master takes q(n).
    pub const MASTER_RECV: usize = 8;
    /// Master has the torques p(n) (after KFF-HMD).
    pub const MASTER_DONE: usize = 9;
    /// Number of stages.
    pub const COUNT: usize = 10;
    /// Names for reports, in index order.
    pub const NAMES: [&str; COUNT] = [
        "master_tick",
        "master_send",
        "emu_fwd_recv",
        "emu_fwd_send",
        "slave_recv",
        "slave_send",
        "emu_bwd_recv",
        "emu_bwd_send",
        "master_recv",
        "master_done",
    ];
}

/// A sample that carries a per-hop publish counter.
pub trait Sequenced {
    /// Sets the publish counter of the hop about to be crossed.
    fn set_hop_seq(&mut self, n: u64);
    /// The publish counter of the last hop crossed.
    fn hop_seq(&self) -> u64;
}

impl Sequenced for Forward {
    fn set_hop_seq(&mut self, n: u64) {
        self.hop_seq = n;
    }
    fn hop_seq(&self) -> u64 {
        self.hop_seq
    }
}

impl Sequenced for Backward {
    fn set_hop_seq(&mut self, n: u64) {
        self.hop_seq = n;
    }
    fn hop_seq(&self) -> u64 {
        self.hop_seq
    }
}

/// Three signal values with their provenance.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("tactile::Signal/4")]
pub struct Signal {
    /// Values: what crosses the network. Position in metres (forward) and force in
    /// newtons (backward); with `control.kind = "wave"`, the wave variables.
    pub value: [f64; 3],
    /// The sender's input energy into the channel so far, per axis, J (the passivity
    /// observers' exchange); delayed with the value, never noised.
    pub energy: [f64; 3],
    /// The sender's sample number when it produced each value (the master's n
    /// forward, the slave's step backward), so a receiver's value can be compared
    /// with what the sender had then.
    pub sent_seq: [u64; 3],
    /// Master sample each value originates from.
    pub origin_seq: [u64; 3],
    /// Master timestamp of that sample (CLOCK_MONOTONIC, ns).
    pub origin_ns: [u64; 3],
    /// Delay injected on purpose along the path so far, samples.
    pub delay_samples: [u32; 3],
    /// What the payload is, how the network treated it, a control message or a
    /// node's notes ([`Flags`]).
    pub flags: Flags,
}

/// Forward stream: c(n) from the master, v(n) from the emulator. Carries only what the
/// loop needs; what each node did with it is in that node's own record.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("tactile::Forward/4")]
pub struct Forward {
    /// Sample number n on this stream.
    pub seq: u64,
    /// Publish counter of the hop this sample last crossed (set by the link's outbox);
    /// a gap at the receiver is a sample overwritten in its buffer.
    pub hop_seq: u64,
    /// The run this sample belongs to (chosen by the master at start; 0 = unknown).
    /// A node drops and counts samples of another run.
    pub run: u64,
    /// Tool position.
    pub signal: Signal,
    /// With [`Flags::POSE`]: the tool's orientation relative to the operator's home, in the
    /// master's frame, as a unit quaternion `[x, y, z, w]` (ROS order). It crosses the
    /// network in the position's packet (delayed with it, never noised).
    pub rotation: [f64; 4],
    /// Timestamps per stage (`stage::*`), ns; zero where not passed yet.
    pub stamps: [u64; stage::COUNT],
}

/// Backward stream: h(n) from the slave, q(n) from the emulator.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("tactile::Backward/5")]
pub struct Backward {
    /// Sample number n on this stream (the forward sample that triggered it).
    pub seq: u64,
    /// Publish counter of the last hop, as in [`Forward::hop_seq`].
    pub hop_seq: u64,
    /// The run this sample belongs to, copied from the forward sample.
    pub run: u64,
    /// Contact force.
    pub signal: Signal,
    /// The contact torque about the tool, in the master's frame, N m: what a real
    /// arm's wrench sensor measured, zero for a point contact; flagged [`Flags::POSE`] in
    /// a 6-DoF run. It crosses the network in the force's packet.
    pub torque: [f64; 3],
    /// With `control.kind = "mmt"`: the last environment model the slave sent. It is
    /// state, so every sample carries it (a lost packet costs one sample's delay, not
    /// the model); `seq` says when it is new. It crosses the network in the force's
    /// packet, never noised.
    pub model: Model,
    /// Stamps of the triggering forward sample, then the backward stages.
    pub stamps: [u64; stage::COUNT],
}

/// A plane wall as model-mediated teleoperation sends it: contact where `normal . x <
/// offset`, force `stiffness (offset - normal . x) normal` there, in the master's frame.
/// A receiver checks it before believing it (`tactile_control::mmt::PlaneModel::is_valid`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("tactile::Model/1")]
pub struct Model {
    /// Outward unit normal.
    pub normal: [f64; 3],
    /// The surface's position along the normal, m.
    pub offset: f64,
    /// N/m.
    pub stiffness: f64,
    /// The model's number: 0 for none yet, then one more each time the slave sends a
    /// changed model.
    pub seq: u64,
}

/// A sample that belongs to a run.
pub trait OfRun {
    /// The run token carried.
    fn run(&self) -> u64;
}

impl OfRun for Forward {
    fn run(&self) -> u64 {
        self.run
    }
}

impl OfRun for Backward {
    fn run(&self) -> u64 {
        self.run
    }
}

/// How many samples back an answer may still be matched to the sample it answers. The
/// master keeps this window of samples awaiting answers, and the report joins records
/// within it; an answer older than this counts as unexpected. Bounded, so memory does
/// not grow with the run's length.
pub const LATE_WINDOW: u64 = 1024;

impl Forward {
    /// The control message `kind` of run `run`, numbered `seq` (a probe's count).
    pub fn control(kind: Control, run: u64, seq: u64) -> Forward {
        let mut f = Forward {
            seq,
            run,
            ..Forward::default()
        };
        f.signal.flags = kind.flags();
        f
    }

    /// What control message this is, if it is one.
    pub fn control_kind(&self) -> Option<Control> {
        Control::of(self.signal.flags)
    }
}

impl Backward {
    /// The control message `kind` of run `run`, about sample `seq` (a probe's echo,
    /// a dropped sample's notice).
    pub fn control(kind: Control, run: u64, seq: u64) -> Backward {
        let mut b = Backward {
            seq,
            run,
            ..Backward::default()
        };
        b.signal.flags = kind.flags();
        b
    }

    /// What control message this is, if it is one.
    pub fn control_kind(&self) -> Option<Control> {
        Control::of(self.signal.flags)
    }
}

#[cfg(test)]
mod control_tests {
    use super::*;

    #[test]
    fn each_control_reads_back_as_itself_and_data_as_none() {
        for k in [
            Control::Probe,
            Control::Waiting,
            Control::End,
            Control::Dropped,
        ] {
            assert_eq!(Forward::control(k, 7, 3).control_kind(), Some(k));
            let b = Backward::control(k, 7, 3);
            assert_eq!((b.control_kind(), b.run, b.seq), (Some(k), 7, 3));
            assert!(k.flags().without(Flags::CONTROL).is_empty());
        }
        let mut data = Forward::default();
        data.signal.flags = Flags::from_bits(!0).without(Flags::CONTROL);
        assert_eq!(data.control_kind(), None);
        assert!(Control::Waiting.is_probe() && !Control::End.is_probe());
    }
}
