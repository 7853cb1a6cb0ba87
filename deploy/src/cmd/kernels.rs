//! `tactile kernels`: one kernel over CSV rows.
//!
//! A public interface users script against. Input: a header naming the module's
//! columns, then one row of numbers per sample. Output: a header, then one row per
//! input row. The whole output is built in memory and written only when every row
//! parsed, so a bad row leaves stdout empty rather than half written.

use super::datapath::{ArithArg, DatapathArgs, Module};
use clap::Args;
use std::io::{BufRead, Read, Write};
use tactile_launch::error::Error;
use tactile_math::arith::ArithKind;
use tactile_math::engine::Engine;
use tactile_math::kernels::IkStatus;
use tactile_scenario::csv;

/// Arguments of `tactile kernels`.
#[derive(Debug, Args)]
pub struct KernelsArgs {
    /// Which kernel to evaluate.
    #[arg(value_enum)]
    pub module: Module,
    /// Arithmetic to evaluate in.
    #[arg(long, value_enum, default_value_t = ArithArg::F64)]
    pub arith: ArithArg,
    /// Datapath format and device.
    #[command(flatten)]
    pub datapath: DatapathArgs,
}

impl Module {
    /// Input column names, in order.
    pub fn input_columns(self) -> &'static [&'static str] {
        match self {
            Module::Fk => &["theta1", "theta2", "theta3"],
            Module::Ik => &["x", "y", "z"],
            Module::Kff => &["theta1", "theta2", "theta3", "fx", "fy", "fz"],
            Module::Fbf => &[
                "x_obj", "y_obj", "z_obj", "x_env", "y_env", "z_env", "hx", "hy", "hz",
            ],
        }
    }

    /// Output column names, in order.
    pub fn output_columns(self) -> &'static [&'static str] {
        match self {
            Module::Fk => &["x", "y", "z"],
            Module::Ik => &["theta1", "theta2", "theta3", "reachable"],
            Module::Kff => &["tau1", "tau2", "tau3"],
            Module::Fbf => &["fx", "fy", "fz"],
        }
    }
}

/// Formats a kernel output so it reads back to the same value: shortest round-trip
/// form of the arithmetic's own precision (an f32 result prints as an f32).
fn push_float(out: &mut String, v: f64, kind: ArithKind) {
    use std::fmt::Write as _;
    // Writing into a String cannot fail.
    let _ = match kind {
        ArithKind::F64 => write!(out, "{v:?}"),
        ArithKind::F32 | ArithKind::Hybrid | ArithKind::Rtl => write!(out, "{:?}", v as f32),
    };
}

/// Longest input line read, bytes: a kernel row is a few numbers, so a longer line is
/// not a row (and is refused before it fills memory).
pub const MAX_LINE: usize = 4096;

/// Reads lines of at most [`MAX_LINE`] bytes, numbering them from 1.
struct Lines<R> {
    input: R,
    n: usize,
    buf: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    /// The next line (without its end), `None` at the end of the input.
    fn next_line(&mut self) -> Result<Option<(usize, String)>, Error> {
        self.n += 1;
        let n = self.n;
        self.buf.clear();
        let limit = (MAX_LINE + 1) as u64;
        let got = (&mut self.input)
            .take(limit)
            .read_until(b'\n', &mut self.buf)
            .map_err(tactile_launch::stop::or_io(
                format!("reading line {n} of stdin"),
                "nothing written to stdout",
            ))?;
        if got == 0 {
            return Ok(None);
        }
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
        } else if got as u64 == limit {
            return Err(Error::BadInput(format!(
                "line {n}: longer than {MAX_LINE} bytes: not a row of numbers"
            )));
        }
        let text = String::from_utf8(std::mem::take(&mut self.buf))
            .map_err(|_| Error::BadInput(format!("line {n}: not UTF-8 text")))?;
        Ok(Some((n, text.trim_end_matches('\r').to_string())))
    }
}

/// The first line that is not blank, checked as the module's header.
fn header<R: BufRead>(lines: &mut Lines<R>, in_cols: &[&str]) -> Result<(), Error> {
    while let Some((n, line)) = lines.next_line()? {
        if !line.trim().is_empty() {
            return csv::check_header(n, &line, in_cols)
                .map_err(|e| Error::BadInput(e.to_string()));
        }
    }
    Err(Error::BadInput(
        csv::CsvError::Empty {
            expected: in_cols.join(","),
        }
        .to_string(),
    ))
}

/// One row through the module: its three values, and for IK whether the target was
/// reachable.
fn evaluate(engine: &Engine, module: Module, v: &[f64]) -> ([f64; 3], Option<bool>) {
    match module {
        Module::Fk => (engine.fk([v[0], v[1], v[2]]), None),
        Module::Ik => {
            let s = engine.ik([v[0], v[1], v[2]]);
            (s.theta, Some(s.status == IkStatus::Reachable))
        }
        Module::Kff => (engine.kff([v[0], v[1], v[2]], [v[3], v[4], v[5]]), None),
        Module::Fbf => (
            engine.fbf([v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]),
            None,
        ),
    }
}

/// Evaluates `args.module` over the CSV on `input`, writing CSV to `output`. The
/// command reads and writes through [`tactile_launch::stop::Input`] and
/// [`tactile_launch::stop::Output`], so a stop request (SIGINT, SIGTERM) ends it within a
/// second however its input comes (a FIFO that gives nothing, an endless stream).
pub fn run(args: &KernelsArgs, input: impl BufRead, output: &mut impl Write) -> Result<(), Error> {
    let kind = ArithKind::from(args.arith);
    let engine = Engine::new(kind, args.datapath.geometry()?, args.datapath.cordic()?)
        .map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))?;
    let module = args.module;
    let in_cols = module.input_columns();
    let mut lines = Lines {
        input,
        n: 0,
        buf: Vec::new(),
    };
    header(&mut lines, in_cols)?;
    let mut out = String::with_capacity(4096);
    out.push_str(&module.output_columns().join(","));
    out.push('\n');
    let mut v = Vec::with_capacity(in_cols.len());
    while let Some((lineno, line)) = lines.next_line()? {
        if line.trim().is_empty() {
            continue;
        }
        csv::parse_row(lineno, &line, in_cols, &mut v)
            .map_err(|e| Error::BadInput(e.to_string()))?;
        let (values, reachable) = evaluate(&engine, module, &v);
        if let Some(k) = values.iter().position(|x| !x.is_finite()) {
            let name = module.output_columns()[k];
            return Err(Error::BadInput(format!(
                "line {lineno}: {name} overflows ({}): the inputs are beyond what the kernel can compute",
                values[k]
            )));
        }
        for (k, x) in values.iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            push_float(&mut out, *x, kind);
        }
        if let Some(r) = reachable {
            out.push_str(if r { ",1" } else { ",0" });
        }
        out.push('\n');
    }
    output
        .write_all(out.as_bytes())
        .and_then(|()| output.flush())
        .map_err(tactile_launch::stop::or_io(
            "writing stdout",
            "stdout holds part of the output",
        ))
}
