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

// The flags fall in three groups, each bit in one ([`Control::FLAGS`],
// [`PAYLOAD_FLAGS`], [`NOTE_FLAGS`]): the run's control messages (probe, end, waiting,
// dropped; made and read through [`Control`] only); what the payload is or how the
// network treated it (substituted, unsent, corrupted, pose, released); and notes of what the node that set them did, for the trace (IK clamped,
// rejected, contact, held, peer lost, clamped).

/// What a sample's payload is (unsent, a pose, the clutch released) or how the
/// network treated it (substituted, corrupted): part of what it carries.
pub const PAYLOAD_FLAGS: u32 =
    FLAG_SUBSTITUTED | FLAG_UNSENT | FLAG_CORRUPTED | FLAG_POSE | FLAG_RELEASED;

/// Notes of what the node that set them did with the sample, for the trace: no
/// receiver acts on them.
pub const NOTE_FLAGS: u32 =
    FLAG_IK_CLAMPED | FLAG_REJECTED | FLAG_CONTACT | FLAG_HELD | FLAG_PEER_LOST | FLAG_CLAMPED;

/// Flag: a value stood in for one the channel did not have (start-up of a delay, gap).
pub const FLAG_SUBSTITUTED: u32 = 1;
/// Flag: the slave's IK target was outside the workspace (clamped).
pub const FLAG_IK_CLAMPED: u32 = 2;
/// Flag (note): the node that set it rejected a value it received (not finite, a jump
/// its predictor finds implausible, a rotation not of norm one) and went on from its
/// estimate; the slave sets it on its step and h(n), the master on its effect. Never
/// on v(n) as received; on q(n) as received it is the slave's note about the v(n) it
/// stepped on, not about q(n).
pub const FLAG_REJECTED: u32 = 4;
/// Flag: the tool is in contact with an object.
pub const FLAG_CONTACT: u32 = 8;
/// Flag: a start-up probe; passes every process untouched and comes back to the master.
pub const FLAG_PROBE: u32 = 16;
/// Flag: the run is over; each process passes it on and exits.
pub const FLAG_END: u32 = 32;
/// Flag (trace): no answer this sample; the master held its last torque.
pub const FLAG_HELD: u32 = 64;
/// Flag (trace): the loop is broken (a peer is silent past the timeout); zero torque.
pub const FLAG_PEER_LOST: u32 = 128;
/// Flag: a value was corrupted to NaN on purpose by the emulator (fault injection).
pub const FLAG_CORRUPTED: u32 = 256;
/// Flag: a force or torque was clamped to the device's limit.
pub const FLAG_CLAMPED: u32 = 512;
/// Flag: the sender's codec did not send this sample (deadband): it crosses the
/// processes as the loop's clock only, no packet crosses the network for it, and the
/// receiver fills it with its predictor.
pub const FLAG_UNSENT: u32 = 1024;
/// Flag: on a probe's echo, the node at the end of the chain is there but still
/// waits for its robot, so the master can say what it waits for.
pub const FLAG_WAITING: u32 = 2048;
/// Flag: lockstep only, a notice from the emulator to the master that sample `seq`
/// was dropped on purpose (the loss model): no answer to it comes, so the master
/// counts the miss at once, as the in-process run does, instead of waiting out a
/// timeout whose firing would depend on the machine's load.
pub const FLAG_DROPPED: u32 = 4096;
/// Flag: a 6-DoF sample. Forward, c(n) carries an orientation in
/// [`Forward::rotation`]; backward, h(n) carries a torque in [`Backward::torque`].
/// Never set in the paper's 3-DoF runs, whose samples carry positions and forces only.
pub const FLAG_POSE: u32 = 8192;
/// Flag (forward): the operator has released the clutch; the robot holds where it is
/// and, at the next engaged sample, takes the master's pose from there (its offsets
/// captured again), so it never jumps.
pub const FLAG_RELEASED: u32 = 16384;

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
    /// `FLAG_*` bits.
    pub flags: u32,
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
    /// With `FLAG_POSE`: the tool's orientation relative to the operator's home, in the
    /// master's frame, as a unit quaternion `[x, y, z, w]` (ROS order). It crosses the
    /// network in the position's packet (delayed with it, never noised).
    pub rotation: [f64; 4],
    /// Timestamps per stage (`stage::*`), ns; zero where not passed yet.
    pub stamps: [u64; stage::COUNT],
}

/// Backward stream: h(n) from the slave, q(n) from the emulator.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("tactile::Backward/4")]
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
    /// arm's wrench sensor measured, zero for a point contact; flagged `FLAG_POSE` in
    /// a 6-DoF run. It crosses the network in the force's packet.
    pub torque: [f64; 3],
    /// Stamps of the triggering forward sample, then the backward stages.
    pub stamps: [u64; stage::COUNT],
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

/// The run's control messages, as a kind: what a sample is when it carries no data.
/// On the wire each is its `FLAG_*` bits in [`Signal::flags`] (the layout is
/// unchanged); a program makes and reads them only through this type
/// ([`Forward::control`], [`Backward::control`], [`Forward::control_kind`],
/// [`Backward::control_kind`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// A start-up probe: passes every process untouched and comes back to the master
    /// ([`FLAG_PROBE`]).
    Probe,
    /// A probe's echo from the end of the chain, which is there but still waits for
    /// its robot ([`FLAG_PROBE`] and [`FLAG_WAITING`]).
    Waiting,
    /// The run is over: each process passes it on and exits ([`FLAG_END`]).
    End,
    /// Lockstep, backward: the emulator dropped sample `seq` on purpose, no answer
    /// comes ([`FLAG_DROPPED`]).
    Dropped,
}

impl Control {
    /// The flags that make a sample a control message.
    pub const FLAGS: u32 = FLAG_PROBE | FLAG_WAITING | FLAG_END | FLAG_DROPPED;

    /// Its bits on the wire.
    pub fn flags(self) -> u32 {
        match self {
            Control::Probe => FLAG_PROBE,
            Control::Waiting => FLAG_PROBE | FLAG_WAITING,
            Control::End => FLAG_END,
            Control::Dropped => FLAG_DROPPED,
        }
    }

    /// The control message that `flags` make, if any: the end first (a run that
    /// ends, ends), then a waiting echo, a probe, a drop.
    pub fn of(flags: u32) -> Option<Control> {
        if flags & FLAG_END != 0 {
            Some(Control::End)
        } else if flags & FLAG_WAITING != 0 {
            Some(Control::Waiting)
        } else if flags & FLAG_PROBE != 0 {
            Some(Control::Probe)
        } else if flags & FLAG_DROPPED != 0 {
            Some(Control::Dropped)
        } else {
            None
        }
    }

    /// True for a probe or its echo, which the chain passes on untouched.
    pub fn is_probe(self) -> bool {
        matches!(self, Control::Probe | Control::Waiting)
    }
}

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
            assert_eq!(k.flags() & !Control::FLAGS, 0);
        }
        let mut data = Forward::default();
        data.signal.flags = !Control::FLAGS;
        assert_eq!(data.control_kind(), None);
        assert!(Control::Waiting.is_probe() && !Control::End.is_probe());
    }

    #[test]
    fn every_flag_is_in_exactly_one_group() {
        let groups = [Control::FLAGS, PAYLOAD_FLAGS, NOTE_FLAGS];
        assert_eq!(groups.iter().fold(0, |a, g| a | g), (1 << 15) - 1);
        assert_eq!(groups.iter().map(|g| g.count_ones()).sum::<u32>(), 15);
    }
}
