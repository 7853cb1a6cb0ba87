//! Every node's record, described once: what the master, the emulator and the slave
//! write for each sample ([`master`], [`emulator`], [`slave`]) and what they count, the
//! entries every record shares ([`entry`]: start, run, events, counters, stop), the
//! checked frames they are stored in ([`frames`]), samples in blocks of columns
//! ([`block`], [`file`]), and the writer a node records
//! through ([`recorder`]). The report reads records with these types alone, so it
//! needs none of the node crates; a node writes with the same ones.

mod ahead;
pub mod block;
pub mod device;
pub mod emulator;
pub mod entry;
pub mod file;
pub mod frames;
pub mod master;
pub mod recorder;
pub mod slave;

pub use entry::{AnyRecord, Event, Record, SampleBlock, Sched, Start, Stop, Totals};
pub use file::{body_len, fits, rows_in, RecordReader, RecordWriter, TooLong};
pub use frames::{Damage, RecordError, MAGIC, MAX_FRAME};
pub use recorder::{record_path, Events, Recorder, WriteError};
