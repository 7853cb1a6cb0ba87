//! The links between Tactile's nodes: a publisher and a subscriber per transport
//! ([`ends`]), on iceoryx2 shared memory within a host ([`ipc`]), UDP ([`udp`]) or Zenoh
//! across hosts ([`zenoh_link`], behind the `zenoh` feature), and in memory for the
//! loop run in one process ([`memory`]); the loop's four streams ([`streams`]), the
//! wire format of the hops that leave the host ([`wire`]), the options that choose a
//! transport per stream ([`options`]) and a node's ends composed from them
//! ([`ports`]). What the nodes do with their samples is not here: the loop's driver in
//! `tactile-runtime` owns the waits, pacing and protocol.

pub mod ends;
pub mod ipc;
pub mod memory;
pub mod options;
pub mod pem_file;
pub mod ports;
pub mod streams;
#[cfg(feature = "zenoh")]
pub mod tls_files;
pub mod udp;
pub mod wire;
#[cfg(feature = "zenoh")]
mod zenoh_config;
#[cfg(feature = "zenoh")]
pub mod zenoh_link;

pub use ends::{LinkError, Publish, Subscribe, Wake};
pub use options::{BadOption, LinkArgs, LinkKind};
pub use ports::{PortStats, Ports};
pub use streams::{Kind, Stream};
