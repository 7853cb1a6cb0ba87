//! One row of `trace.csv` per master sample: every signal of the loop and every stamp.
//!
//! The columns are described once, in [`trace_row!`]'s invocation below: the struct's
//! fields in CSV order, from which the header and the writer follow, so a column
//! cannot be added to one and missed in the other. A three-valued field `x` gives
//! columns `x_1,x_2,x_3`; the stamps give `t_<stage>` (relative to the first sample's
//! tick). Signal columns come first and timing columns last, so a comparison of two
//! runs' signals (the determinism test, lockstep against the in-process simulation)
//! can cut the timing columns off by name. Floats are written in shortest round-trip
//! form, so equal values give equal text and the file reads back exactly.

use crate::columns::{Columns, Kind};
use std::fmt::Write;
use tactile_messages::samples::{stage, Flags};

/// Name of the first timing column; everything from here on is wall-clock dependent.
pub const FIRST_TIMING_COLUMN: &str = "round_trip_ns";

/// How a field's type becomes columns: their names and the cells of one row.
trait Cells {
    /// Appends `,name` for each column of field `field`.
    fn names(field: &str, h: &mut String);
    /// Appends `,value` for each column; `t0` is subtracted from stamps.
    fn cells(&self, line: &mut String, t0: u64);
    /// Appends each column's name and kind (the columnar files' schema).
    fn kinds(field: &str, k: &mut Vec<(String, Kind)>);
    /// Pushes each column's value; `t0` is subtracted from stamps.
    fn push(&self, cols: &mut Columns, t0: u64);
}

/// Integers as they print; in columns, as their bits in the signed type of their width.
macro_rules! integer_cells {
    ($($t:ty => $kind:ident, $col:ident, $bits:ty);*) => {$(
        impl Cells for $t {
            fn names(field: &str, h: &mut String) {
                let _ = write!(h, ",{field}");
            }
            fn cells(&self, line: &mut String, _: u64) {
                let _ = write!(line, ",{self}");
            }
            fn kinds(field: &str, k: &mut Vec<(String, Kind)>) {
                k.push((field.to_string(), Kind::$kind));
            }
            fn push(&self, cols: &mut Columns, _: u64) {
                cols.$col(*self as $bits);
            }
        }
    )*};
}

integer_cells!(u64 => U64, i64, i64; u32 => U32, i32, i32; i64 => I64, i64, i64);

/// Flags as their number.
impl Cells for Flags {
    fn names(field: &str, h: &mut String) {
        u32::names(field, h);
    }
    fn cells(&self, line: &mut String, t0: u64) {
        self.bits().cells(line, t0);
    }
    fn kinds(field: &str, k: &mut Vec<(String, Kind)>) {
        u32::kinds(field, k);
    }
    fn push(&self, cols: &mut Columns, t0: u64) {
        self.bits().push(cols, t0);
    }
}

impl Cells for bool {
    fn names(field: &str, h: &mut String) {
        let _ = write!(h, ",{field}");
    }
    fn cells(&self, line: &mut String, _: u64) {
        let _ = write!(line, ",{}", u8::from(*self));
    }
    fn kinds(field: &str, k: &mut Vec<(String, Kind)>) {
        k.push((field.to_string(), Kind::Bool));
    }
    fn push(&self, cols: &mut Columns, _: u64) {
        cols.bool(*self);
    }
}

impl Cells for f64 {
    fn names(field: &str, h: &mut String) {
        let _ = write!(h, ",{field}");
    }
    fn cells(&self, line: &mut String, _: u64) {
        let _ = write!(line, ",{self:?}");
    }
    fn kinds(field: &str, k: &mut Vec<(String, Kind)>) {
        k.push((field.to_string(), Kind::F64));
    }
    fn push(&self, cols: &mut Columns, _: u64) {
        cols.f64(*self);
    }
}

/// Three values per axis: `field_1`, `field_2`, `field_3`.
impl<T: Cells> Cells for [T; 3] {
    fn names(field: &str, h: &mut String) {
        for axis in ["1", "2", "3"] {
            T::names(&format!("{field}_{axis}"), h);
        }
    }
    fn cells(&self, line: &mut String, t0: u64) {
        for x in self {
            x.cells(line, t0);
        }
    }
    fn kinds(field: &str, k: &mut Vec<(String, Kind)>) {
        for axis in ["1", "2", "3"] {
            T::kinds(&format!("{field}_{axis}"), k);
        }
    }
    fn push(&self, cols: &mut Columns, t0: u64) {
        for x in self {
            x.push(cols, t0);
        }
    }
}

/// A timestamp per stage, ns from the first sample's tick (zero where not passed).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stamps(pub [u64; stage::COUNT]);

impl std::ops::Deref for Stamps {
    type Target = [u64; stage::COUNT];
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl std::ops::DerefMut for Stamps {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.0
    }
}

impl Cells for Stamps {
    fn names(_: &str, h: &mut String) {
        for name in stage::NAMES {
            let _ = write!(h, ",t_{name}");
        }
    }
    fn cells(&self, line: &mut String, t0: u64) {
        for t in self.0 {
            let _ = write!(line, ",{}", t.saturating_sub(t0));
        }
    }
    fn kinds(_: &str, k: &mut Vec<(String, Kind)>) {
        for name in stage::NAMES {
            k.push((format!("t_{name}"), Kind::U64));
        }
    }
    fn push(&self, cols: &mut Columns, t0: u64) {
        for t in self.0 {
            cols.i64(t.saturating_sub(t0) as i64);
        }
    }
}

/// Declares [`TraceRow`] from its columns in CSV order, with the header and the
/// writer that follow from them.
macro_rules! trace_row {
    ($($(#[doc = $doc:literal])* $field:ident: $ty:ty,)*) => {
        /// Sample n as the report joins it from the nodes' records: the master's part
        /// (target, encoders, c, q, torques, round trip), the emulator's (noise
        /// injected) and the slave's (what it received and did). A part whose node
        /// recorded nothing for n stays zero, and `received` says whether the answer
        /// came back.
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct TraceRow {
            $($(#[doc = $doc])* pub $field: $ty,)*
            /// True if the slave recorded a step on v(n) (not a trace column: it says
            /// whether the slave's columns hold data).
            pub stepped: bool,
            /// The slave's note flags for its step (rejected, rotation rejected, contact,
            /// IK clamped); not a
            /// trace column: q(n)'s are `flags_b`, and h(n) may not come back.
            pub flags_s: Flags,
        }

        /// The header line (without newline).
        pub fn header() -> String {
            let mut h = String::new();
            $(<$ty as Cells>::names(stringify!($field), &mut h);)*
            h.split_off(1)
        }

        /// Every column's name and kind, in the header's order.
        pub fn kinds() -> Vec<(String, Kind)> {
            let mut k = Vec::new();
            $(<$ty as Cells>::kinds(stringify!($field), &mut k);)*
            k
        }

        impl TraceRow {
            /// Appends this row as one CSV line (with newline); `t0` is subtracted
            /// from stamps.
            pub fn write_csv(&self, line: &mut String, t0: u64) {
                let start = line.len();
                $(self.$field.cells(line, t0);)*
                line.remove(start);
                line.push('\n');
            }

            /// Pushes this row's values into `cols` (made from [`kinds`]); `t0` is
            /// subtracted from stamps.
            pub fn push(&self, cols: &mut Columns, t0: u64) {
                $(self.$field.push(cols, t0);)*
            }
        }
    };
}

trace_row! {
    /// Sample number.
    n: u64,
    /// True if q(n) came back to the master.
    received: bool,
    /// The operator's target a(n), m.
    target: [f64; 3],
    /// Master joint angles b(n), rad.
    theta_md: [f64; 3],
    /// c(n) as sent, m.
    c: [f64; 3],
    /// v(n) as the slave received it, m.
    v: [f64; 3],
    /// Noise the emulator added to v(n).
    noise_f: [f64; 3],
    /// Delay injected into v(n), samples.
    delay_f: [u32; 3],
    /// IK-HSD reference angles, rad.
    theta_ref: [f64; 3],
    /// Slave joint angles after the step, rad.
    theta_sd: [f64; 3],
    /// Slave controller torques, N m.
    u: [f64; 3],
    /// FK-HSD tool position l(n), m.
    tool: [f64; 3],
    /// Nearest surface point, m (zero without contact).
    surface: [f64; 3],
    /// h(n), N.
    h: [f64; 3],
    /// q(n) as the master received it, N.
    q: [f64; 3],
    /// Noise the emulator added to q(n).
    noise_b: [f64; 3],
    /// Delay injected into q(n), samples.
    delay_b: [u32; 3],
    /// KFF-HMD torques p(n), N m.
    tau: [f64; 3],
    /// The force the operator feels, N.
    felt: [f64; 3],
    /// The handle's true position, m.
    handle: [f64; 3],
    /// The impedance hand's force on the handle, N.
    hand_force: [f64; 3],
    /// The slave's Cartesian reference from the channel's control, m.
    reference: [f64; 3],
    /// The master's passivity observer per axis, J.
    observer_m: [f64; 3],
    /// The slave's passivity observer per axis, J.
    observer_s: [f64; 3],
    /// The slave step each value of q(n) was produced at.
    q_from: [u64; 3],
    /// The master sample each value of q(n) started from: n minus the oldest is the
    /// round trip in samples.
    q_origin: [u64; 3],
    /// Flags of v(n) as received.
    flags_f: Flags,
    /// Flags of q(n) as received.
    flags_b: Flags,
    /// The master's flags for this sample (held, peer lost, clamped, rejected).
    flags_m: Flags,
    /// Object in contact, or -1.
    contact_object: i64,
    /// Energy the master's control dissipated this sample, J.
    dissipated_m: f64,
    /// Energy the slave's control dissipated this step, J.
    dissipated_s: f64,
    /// The master port's net energy into the channel so far, J.
    port_net_m: f64,
    /// The slave port's net energy into the channel so far, J.
    port_net_s: f64,
    /// `control.kind = "mmt"`: the number of the model h(n) carried (0: none yet).
    model_seq: u64,
    /// That model's outward normal.
    model_normal: [f64; 3],
    /// That model's surface along its normal, m.
    model_offset: f64,
    /// That model's stiffness, N/m.
    model_k: f64,
    /// Energy the master's rendered model changes have added at the handle so far, J.
    model_injected_m: f64,
    /// Round trip, ns (0 if no answer).
    round_trip_ns: u64,
    /// Round trip minus injected delay, ns.
    overhead_ns: i64,
    /// Stamps per stage, ns (zero where not passed).
    stamps: Stamps,
}

/// Keeps only the columns before [`FIRST_TIMING_COLUMN`] of a trace's text.
pub fn signal_columns(trace: &str) -> String {
    let Some(header) = trace.lines().next() else {
        return String::new();
    };
    let keep = header
        .split(',')
        .position(|c| c == FIRST_TIMING_COLUMN)
        .unwrap_or(usize::MAX);
    trace
        .lines()
        .map(|l| l.split(',').take(keep).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_row_have_the_same_columns_in_order() {
        let h = header();
        let names: Vec<&str> = h.split(',').collect();
        assert_eq!(names[..3], ["n", "received", "target_1"]);
        assert_eq!(names.last().copied(), Some("t_master_done"));
        let first_timing = names.iter().position(|c| *c == FIRST_TIMING_COLUMN);
        assert_eq!(first_timing, Some(names.len() - stage::COUNT - 2));
        let mut line = String::new();
        let row = TraceRow {
            n: 7,
            received: true,
            contact_object: -1,
            ..TraceRow::default()
        };
        row.write_csv(&mut line, 0);
        let cells: Vec<&str> = line.trim_end().split(',').collect();
        assert_eq!(cells.len(), names.len());
        assert_eq!(cells[..2], ["7", "1"]);
        let k = names
            .iter()
            .position(|c| *c == "contact_object")
            .expect("column");
        assert_eq!(cells[k], "-1");
    }
}
