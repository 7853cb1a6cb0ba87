//! The four streams of the loop and who is at each end. Every transport names its
//! services, keys and addresses after these, so each is written once.

use tactile_messages::Role;

/// Which way a stream's samples go, and so which sample type it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Positions, operator to environment: `Forward` samples.
    Forward = 0,
    /// Forces, environment to operator: `Backward` samples.
    Backward = 1,
}

/// A stream of the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// c(n): master to emulator.
    C,
    /// v(n): emulator (or a master without emulator) to slave.
    V,
    /// h(n): slave to emulator (or to a master without emulator).
    H,
    /// q(n): emulator to master.
    Q,
}

impl Stream {
    /// The stream's short name, the last part of its key.
    pub const fn name(self) -> &'static str {
        match self {
            Stream::C => "c",
            Stream::V => "v",
            Stream::H => "h",
            Stream::Q => "q",
        }
    }

    /// Forward or backward.
    pub const fn kind(self) -> Kind {
        match self {
            Stream::C | Stream::V => Kind::Forward,
            Stream::H | Stream::Q => Kind::Backward,
        }
    }

    /// The node that takes this stream in a run with an emulator.
    pub const fn receiver(self) -> Role {
        match self {
            Stream::C | Stream::H => Role::Emulator,
            Stream::V => Role::Slave,
            Stream::Q => Role::Master,
        }
    }

    /// The iceoryx2 service of the stream.
    pub const fn service(self) -> &'static str {
        match self {
            Stream::C => "forward/c",
            Stream::V => "forward/v",
            Stream::H => "backward/h",
            Stream::Q => "backward/q",
        }
    }
}

/// The Zenoh key of `stream` in run `prefix`.
pub fn key(prefix: &str, stream: Stream) -> String {
    format!("tactile/{prefix}/{}", stream.name())
}

/// Which end of a stream a node holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// It publishes the stream.
    Publish,
    /// It subscribes to it.
    Subscribe,
}

/// The streams `role` publishes and subscribes to; `direct`: no emulator, the master
/// publishes v(n) and takes h(n) straight from the slave.
pub fn ends(role: Role, direct: bool) -> &'static [(Stream, End)] {
    use End::{Publish, Subscribe};
    match (role, direct) {
        (Role::Master, false) => &[(Stream::C, Publish), (Stream::Q, Subscribe)],
        (Role::Master, true) => &[(Stream::V, Publish), (Stream::H, Subscribe)],
        (Role::Slave, _) => &[(Stream::V, Subscribe), (Stream::H, Publish)],
        (Role::Emulator, _) => &[
            (Stream::C, Subscribe),
            (Stream::Q, Publish),
            (Stream::V, Publish),
            (Stream::H, Subscribe),
        ],
    }
}

impl Stream {
    /// True for the streams between the master and the emulator (c and q): an
    /// emulator may carry them on another link than the two towards the slave.
    pub const fn touches_master(self) -> bool {
        matches!(self, Stream::C | Stream::Q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stream_is_published_by_one_node_and_taken_by_its_receiver() {
        let mut all: Vec<(Role, Stream, End)> = Vec::new();
        for role in Role::ALL {
            for &(s, e) in ends(role, false) {
                all.push((role, s, e));
            }
        }
        for s in [Stream::C, Stream::V, Stream::H, Stream::Q] {
            let pubs = all
                .iter()
                .filter(|x| x.1 == s && x.2 == End::Publish)
                .count();
            let subs: Vec<Role> = all
                .iter()
                .filter(|x| x.1 == s && x.2 == End::Subscribe)
                .map(|x| x.0)
                .collect();
            assert_eq!(pubs, 1, "{s:?}");
            assert_eq!(subs, vec![s.receiver()], "{s:?}");
        }
    }
}
