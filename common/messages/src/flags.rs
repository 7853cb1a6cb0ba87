//! The bits a sample carries in [`Signal::flags`](crate::samples::Signal::flags), as a
//! type. They fall in three groups, each bit in exactly one:
//!
//! - the run's control messages (probe, end, waiting, dropped), made and read
//!   through [`Control`]: their bits have no public name;
//! - the payload's: what a sample carries or how the network treated it
//!   ([`Flags::PAYLOAD`]: substituted, unsent, corrupted, pose, released);
//! - notes of what the node that set them did, for the trace ([`Flags::NOTES`]: IK
//!   clamped, rejected, rotation rejected, contact, held, peer lost, clamped, guess
//!   refused). No receiver acts on them.
//!
//! On the wire and in records a `Flags` is its `u32` (`repr(C)` over one `u32`, serde
//! transparent), so the layout and the bytes are those of the bare number.

use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{BitAnd, BitOr, BitOrAssign};

/// A set of flags.
#[repr(C)]
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default, ZeroCopySend, Serialize, Deserialize)]
#[serde(transparent)]
#[type_name("tactile::Flags/1")]
pub struct Flags(u32);

/// Each named flag with its bit, in bit order, for [`Flags`]' `Debug`.
const NAMES: [(&str, Flags); 17] = [
    ("SUBSTITUTED", Flags::SUBSTITUTED),
    ("IK_CLAMPED", Flags::IK_CLAMPED),
    ("REJECTED", Flags::REJECTED),
    ("CONTACT", Flags::CONTACT),
    ("PROBE", Flags::PROBE),
    ("END", Flags::END),
    ("HELD", Flags::HELD),
    ("PEER_LOST", Flags::PEER_LOST),
    ("CORRUPTED", Flags::CORRUPTED),
    ("CLAMPED", Flags::CLAMPED),
    ("UNSENT", Flags::UNSENT),
    ("WAITING", Flags::WAITING),
    ("DROPPED", Flags::DROPPED),
    ("POSE", Flags::POSE),
    ("RELEASED", Flags::RELEASED),
    ("ROTATION_REJECTED", Flags::ROTATION_REJECTED),
    ("GUESS_REFUSED", Flags::GUESS_REFUSED),
];

impl Flags {
    /// No flag.
    pub const NONE: Flags = Flags(0);

    /// Payload: a value stood in for one the channel did not have (start-up of a
    /// delay, a gap).
    pub const SUBSTITUTED: Flags = Flags(1);
    /// Note: the slave's IK target was outside the workspace (clamped).
    pub const IK_CLAMPED: Flags = Flags(2);
    /// Note: the node that set it rejected a position or force it received (not
    /// finite, a jump its predictor finds implausible; at the slave, also a target its
    /// IK refuses) and went on from its estimate;
    /// the slave sets it on its step and h(n), the master on its effect. Never on v(n)
    /// as received; on q(n) as received it is the slave's note about the v(n) it
    /// stepped on, not about q(n). An orientation rejected is
    /// [`Flags::ROTATION_REJECTED`].
    pub const REJECTED: Flags = Flags(4);
    /// Note: the tool is in contact with an object.
    pub const CONTACT: Flags = Flags(8);
    /// Control: a start-up probe ([`Control::Probe`]).
    pub(crate) const PROBE: Flags = Flags(16);
    /// Control: the run is over ([`Control::End`]).
    pub(crate) const END: Flags = Flags(32);
    /// Note (trace): no answer this sample; the master held its last torque.
    pub const HELD: Flags = Flags(64);
    /// Note (trace): the loop is broken (a peer is silent past the timeout); zero
    /// torque.
    pub const PEER_LOST: Flags = Flags(128);
    /// Payload: a value was corrupted to NaN on purpose by the emulator (fault
    /// injection).
    pub const CORRUPTED: Flags = Flags(256);
    /// Note: a force or torque was clamped to the device's limit.
    pub const CLAMPED: Flags = Flags(512);
    /// Payload: the sender's codec did not send this sample (deadband): it crosses the
    /// processes as the loop's clock only, no packet crosses the network for it, and
    /// the receiver fills it with its predictor. The emulator clears it on the way
    /// (the receiver sees [`Flags::SUBSTITUTED`]), so no trace row carries it.
    pub const UNSENT: Flags = Flags(1024);
    /// Control: a probe's echo from a node that still waits for its robot
    /// ([`Control::Waiting`]).
    pub(crate) const WAITING: Flags = Flags(2048);
    /// Control: lockstep only, the emulator dropped sample `seq` on purpose
    /// ([`Control::Dropped`]).
    pub(crate) const DROPPED: Flags = Flags(4096);
    /// Payload, set by the master (and copied by the slave onto h(n)): a 6-DoF
    /// sample. Forward, c(n) carries an orientation in
    /// [`Forward::rotation`](crate::samples::Forward::rotation); backward, h(n) carries a torque in
    /// [`Backward::torque`](crate::samples::Backward::torque). Never set in the paper's 3-DoF runs, whose samples carry
    /// positions and forces only.
    pub const POSE: Flags = Flags(8192);
    /// Payload (forward), set by the master: the operator has released the clutch; the robot holds where
    /// it is and, at the next engaged sample, takes the master's pose from there (its
    /// offsets captured again), so it never jumps.
    pub const RELEASED: Flags = Flags(16384);
    /// Note: the slave rejected a 6-DoF sample's orientation (not finite, not of norm
    /// one) and held the last one it took; the position may still have been followed,
    /// so the position's tracking errors keep the step.
    pub const ROTATION_REJECTED: Flags = Flags(32768);
    /// Note: the node's predictor refused a guess from outside the scenario (a Python
    /// function) that a received value would have been refused for (not finite, too
    /// large, too fast) and held the last value instead.
    pub const GUESS_REFUSED: Flags = Flags(65536);

    /// The flags that make a sample a control message.
    pub(crate) const CONTROL: Flags = Flags(16 | 32 | 2048 | 4096);
    /// What a sample's payload is or how the network treated it: part of what it
    /// carries.
    pub const PAYLOAD: Flags = Flags(1 | 256 | 1024 | 8192 | 16384);
    /// Notes of what the node that set them did with the sample, for the trace.
    pub const NOTES: Flags = Flags(2 | 4 | 8 | 64 | 128 | 512 | 32768 | 65536);

    /// The flags as the number on the wire, in records and in the trace's columns.
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The flags a number carries, every bit kept (a record's or a peer's number reads
    /// back as it was written).
    pub const fn from_bits(bits: u32) -> Flags {
        Flags(bits)
    }

    /// True if every flag of `other` is set.
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }

    /// True if any flag of `other` is set.
    pub const fn intersects(self, other: Flags) -> bool {
        self.0 & other.0 != 0
    }

    /// True if no flag is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Clears the flags of `other`.
    pub fn remove(&mut self, other: Flags) {
        self.0 &= !other.0;
    }

    /// These flags without those of `other`.
    pub const fn without(self, other: Flags) -> Flags {
        Flags(self.0 & !other.0)
    }
}

impl BitOr for Flags {
    type Output = Flags;
    fn bitor(self, other: Flags) -> Flags {
        Flags(self.0 | other.0)
    }
}

impl BitOrAssign for Flags {
    fn bitor_assign(&mut self, other: Flags) {
        self.0 |= other.0;
    }
}

impl BitAnd for Flags {
    type Output = Flags;
    fn bitand(self, other: Flags) -> Flags {
        Flags(self.0 & other.0)
    }
}

/// `Flags(POSE | RELEASED)`; bits no flag names show as a number.
impl fmt::Debug for Flags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut names: Vec<String> = NAMES
            .iter()
            .filter(|(_, b)| self.contains(*b))
            .map(|(n, _)| (*n).to_string())
            .collect();
        let known = NAMES.iter().fold(Flags::NONE, |a, (_, b)| a | *b);
        let rest = self.without(known);
        if !rest.is_empty() {
            names.push(format!("{:#x}", rest.0));
        }
        write!(f, "Flags({})", names.join(" | "))
    }
}

/// The run's control messages, as a kind: what a sample is when it carries no data.
/// On the wire each is its control bits in [`Signal::flags`](crate::samples::Signal::flags)
/// (the layout is unchanged); a program makes and reads them only through this type
/// (`Forward::control`, `Backward::control`, `Forward::control_kind`,
/// `Backward::control_kind` in [`crate::samples`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// A start-up probe: passes every process untouched and comes back to the master.
    Probe,
    /// A probe's echo from the end of the chain, which is there but still waits for
    /// its robot, so the master can say what it waits for.
    Waiting,
    /// The run is over: each process passes it on and exits.
    End,
    /// Lockstep, backward: the emulator dropped sample `seq` on purpose (the loss
    /// model), no answer comes, so the master counts the miss at once, as the
    /// in-process run does, instead of waiting out a timeout whose firing would depend
    /// on the machine's load.
    Dropped,
}

impl Control {
    /// Its bits on the wire.
    pub fn flags(self) -> Flags {
        match self {
            Control::Probe => Flags::PROBE,
            Control::Waiting => Flags::PROBE | Flags::WAITING,
            Control::End => Flags::END,
            Control::Dropped => Flags::DROPPED,
        }
    }

    /// The control message that `flags` make, if any: the end first (a run that
    /// ends, ends), then a waiting echo, a probe, a drop.
    pub fn of(flags: Flags) -> Option<Control> {
        if !flags.intersects(Flags::CONTROL) {
            None
        } else if flags.intersects(Flags::END) {
            Some(Control::End)
        } else if flags.intersects(Flags::WAITING) {
            Some(Control::Waiting)
        } else if flags.intersects(Flags::PROBE) {
            Some(Control::Probe)
        } else if flags.intersects(Flags::DROPPED) {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_flag_is_in_exactly_one_group() {
        let groups = [Flags::CONTROL, Flags::PAYLOAD, Flags::NOTES];
        let all = NAMES.iter().fold(Flags::NONE, |a, (_, b)| a | *b);
        assert_eq!(groups.iter().fold(Flags::NONE, |a, g| a | *g), all);
        let counted: u32 = groups.iter().map(|g| g.bits().count_ones()).sum();
        assert_eq!(counted, NAMES.len() as u32);
        for (name, bit) in NAMES {
            assert_eq!(bit.bits().count_ones(), 1, "{name} is one bit");
        }
    }

    #[test]
    fn flags_are_their_number_on_the_wire_and_in_records() {
        let f = Flags::POSE | Flags::RELEASED;
        assert_eq!(f.bits(), 8192 | 16384);
        assert_eq!(std::mem::size_of::<Flags>(), 4);
        let config = bincode::config::standard();
        let (a, b) = (
            bincode::serde::encode_to_vec(f, config).expect("encodes"),
            bincode::serde::encode_to_vec(f.bits(), config).expect("encodes"),
        );
        assert_eq!(a, b);
        let (back, _): (Flags, usize) =
            bincode::serde::decode_from_slice(&a, config).expect("decodes");
        assert_eq!(back, f);
    }

    #[test]
    fn debug_names_each_flag_and_shows_unnamed_bits() {
        let f = Flags::POSE | Flags::RELEASED | Flags::from_bits(1 << 20);
        assert_eq!(format!("{f:?}"), "Flags(POSE | RELEASED | 0x100000)");
        let mut g = Flags::NONE;
        g |= Flags::REJECTED | Flags::CONTACT;
        g.remove(Flags::CONTACT);
        assert!(g.contains(Flags::REJECTED) && !g.intersects(Flags::CONTACT));
    }
}
