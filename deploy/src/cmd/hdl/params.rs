//! The RTL in a folder: its sources and generated parameters (`tactile_rtl::text`),
//! each block's latency, and the model a format's RTL is checked against.

use crate::error::Error;
use std::path::Path;
use tactile_math::cordic::hdl::{RtlConstants, REDUCE_GUARD};
use tactile_math::cordic::{Cordic, CordicConfig};
use tactile_math::geometry::Geometry;
use tactile_rtl::text::{files, SOURCES};

/// Clocks from input to output of each function (the RTL's LATENCY localparams).
pub fn latency(function: super::Function, cfg: &CordicConfig) -> u32 {
    use super::Function as F;
    match function {
        F::Sincos => cfg.iterations + 5,
        F::Atan2 => cfg.iterations + 4,
        F::Acos => 33 + cfg.iterations + 4,
        F::Add | F::Sub => unit_latency("F32_ADD_LAT"),
        F::Mul => unit_latency("F32_MUL_LAT"),
        F::Div => unit_latency("F32_DIV_LAT"),
        F::Sqrt => unit_latency("F32_SQRT_LAT"),
        F::Fk | F::Kff | F::Fbf | F::Ik => module_latency(function, cfg),
    }
}

/// A unit's latency, read from `f32_lat.vh` (the one place it is written).
fn unit_latency(name: &str) -> u32 {
    let text = SOURCES
        .iter()
        .find(|(n, _)| *n == "f32_lat.vh")
        .map_or("", |(_, t)| *t);
    text.lines()
        .filter_map(|l| l.split_once(name)?.1.trim_start().strip_prefix('='))
        .find_map(|v| v.trim().trim_end_matches(';').trim().parse().ok())
        .unwrap_or(0)
}

/// A module's latency: the formula of its LATENCY localparam (kin_*.v), which the
/// co-simulation checks against the clocks it measures.
fn module_latency(function: super::Function, cfg: &CordicConfig) -> u32 {
    use super::Function as F;
    let (add, mul) = (unit_latency("F32_ADD_LAT"), unit_latency("F32_MUL_LAT"));
    let (div, sqrt) = (unit_latency("F32_DIV_LAT"), unit_latency("F32_SQRT_LAT"));
    let sincos = latency(F::Sincos, cfg);
    match function {
        F::Fk => sincos + 2 * mul + 2 * add,
        F::Kff => sincos + 3 * mul + 3 * add,
        F::Fbf => add + mul,
        // The acos's argument, then acos, then the three additions of theta3; 4 clocks
        // of comparisons and muxes on the way.
        _ => 6 * add + 3 * mul + 2 * div + sqrt + latency(F::Acos, cfg) + 4,
    }
}

/// The model for `cfg`, refused (with the model's error) where the model refuses it,
/// and where the RTL's integer range reduction would not give the model's codes.
pub fn model(cfg: CordicConfig) -> Result<(Cordic, RtlConstants), Error> {
    let cordic =
        Cordic::new(cfg).map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))?;
    let constants = cordic.rtl_constants();
    if let Some(a) = cordic.rtl_reduction_mismatch(&constants) {
        return Err(Error::BadInput(format!(
            "no RTL for this format: its range reduction in {REDUCE_GUARD} guard bits \
             differs from the model's at angle {a:e}"
        )));
    }
    Ok((cordic, constants))
}

/// Writes the sources, `tfb_params.vh` and `kin_params.vh` (the modules' constants
/// for `geometry`) into `dir` (created if missing).
pub fn write_rtl(dir: &Path, c: &RtlConstants, geometry: &Geometry) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(Error::io(format!("creating {}", dir.display())))?;
    for (name, text) in files(c, geometry) {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(Error::io(format!("writing {}", path.display())))?;
    }
    Ok(())
}
