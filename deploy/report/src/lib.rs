//! The report of a run as a library: the trace row and its columns.

pub mod trace;
