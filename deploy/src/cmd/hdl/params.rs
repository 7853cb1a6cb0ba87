//! The RTL's sources and the one generated file, `tfb_params.vh`: every constant of
//! a format, taken from the hybrid model so the hardware and the model share them.

use crate::error::Error;
use std::fmt::Write as _;
use std::path::Path;
use tactile_math::cordic::hdl::{RtlConstants, REDUCE_GUARD};
use tactile_math::cordic::{Cordic, CordicConfig, Rounding};

/// The hand-written, parameterized RTL (deploy/hdl), carried in the binary so that
/// `tactile hdl` works from any folder.
pub const SOURCES: [(&str, &str); 10] = [
    ("tfb_fp.vh", include_str!("../../../hdl/tfb_fp.vh")),
    ("tfb_delay.v", include_str!("../../../hdl/tfb_delay.v")),
    ("tfb_stage.v", include_str!("../../../hdl/tfb_stage.v")),
    ("tfb_sincos.v", include_str!("../../../hdl/tfb_sincos.v")),
    ("tfb_vector.v", include_str!("../../../hdl/tfb_vector.v")),
    ("tfb_atan2.v", include_str!("../../../hdl/tfb_atan2.v")),
    ("tfb_sqrt1m.v", include_str!("../../../hdl/tfb_sqrt1m.v")),
    ("tfb_acos.v", include_str!("../../../hdl/tfb_acos.v")),
    ("tfb_top.v", include_str!("../../../hdl/tfb_top.v")),
    ("tb_tfb.v", include_str!("../../../hdl/tb_tfb.v")),
];

/// The modules of the TFB, in compile order (the testbench and the synthesis tops
/// come on top of these).
pub const MODULES: [&str; 7] = [
    "tfb_delay.v",
    "tfb_stage.v",
    "tfb_sincos.v",
    "tfb_vector.v",
    "tfb_atan2.v",
    "tfb_sqrt1m.v",
    "tfb_acos.v",
];

/// Clocks from input to output of each function (the RTL's LATENCY localparams).
pub fn latency(function: super::Function, cfg: &CordicConfig) -> u32 {
    match function {
        super::Function::Sincos => cfg.iterations + 5,
        super::Function::Atan2 => cfg.iterations + 4,
        super::Function::Acos => 33 + cfg.iterations + 4,
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

/// The text of `tfb_params.vh` for one format.
pub fn params_vh(c: &RtlConstants) -> String {
    let cfg = &c.config;
    let nearest = cfg.rounding == Rounding::Nearest;
    let word = |v: i64| format!("32'h{:08x}", v as u32);
    let mut atan = String::new();
    for i in (0..32).rev() {
        let v = c.atan.get(i).copied().unwrap_or(0);
        let sep = if i == 0 { "" } else { "," };
        let _ = write!(atan, "\n    {}{sep}", word(v));
    }
    format!(
        "// tfb_params.vh: the TFB's parameters for [s{w}.{f}], {n} iterations, {r}.\n\
         // Written by `tactile hdl rtl` from the hybrid model (tactile-math,\n\
         // cordic::hdl): regenerate it, do not edit it.\n\
         localparam integer WORD = {w};\n\
         localparam integer FRAC = {f};\n\
         localparam integer ITER = {n};\n\
         localparam integer NEAREST = {near};\n\
         localparam integer GUARD = {g};\n\
         // Q(2^(FRAC+1) / K_n), Q(pi 2^FRAC), Q(pi/2 2^FRAC), floor(pi 2^FRAC)\n\
         localparam [31:0] GAIN = {gain};\n\
         localparam [31:0] PI_Q = {pi};\n\
         localparam [31:0] HALF_PI_Q = {half_pi};\n\
         localparam [31:0] PI_FLOOR = {pi_floor};\n\
         // Q(atan(2^-i) 2^FRAC), entry i at bits [32 i +: 32]\n\
         localparam [1023:0] ATAN = {{{atan}\n}};\n\
         // 2 pi 2^(FRAC+GUARD), rounded\n\
         localparam [127:0] TWO_PI = 128'h{two_pi:032x};\n\
         // f32 bits of the first angles reduced by 2 pi and by 4 pi\n\
         localparam [31:0] PI_UP = 32'h{pi_up:08x};\n\
         localparam [31:0] THREE_PI_UP = 32'h{three:08x};\n",
        w = cfg.word,
        f = cfg.frac,
        n = cfg.iterations,
        r = if nearest { "nearest" } else { "truncate" },
        near = u8::from(nearest),
        g = REDUCE_GUARD,
        gain = word(c.gain),
        pi = word(c.pi),
        half_pi = word(c.half_pi),
        pi_floor = word(c.pi_floor),
        two_pi = c.two_pi,
        pi_up = c.pi_up,
        three = c.three_pi_up,
    )
}

/// Writes the sources and `tfb_params.vh` into `dir` (created if missing).
pub fn write_rtl(dir: &Path, c: &RtlConstants) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(Error::io(format!("creating {}", dir.display())))?;
    let params = params_vh(c);
    let files = SOURCES
        .iter()
        .map(|(n, t)| (*n, *t))
        .chain([("tfb_params.vh", params.as_str())]);
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(Error::io(format!("writing {}", path.display())))?;
    }
    Ok(())
}
