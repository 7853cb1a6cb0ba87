//! The RTL's text: the hand-written Verilog (`hdl/`, beside this crate's sources: it
//! packages with the crate that compiles it) and the two generated
//! parameter files, `tfb_params.vh` (a format's CORDIC constants) and `kin_params.vh`
//! (the modules' constants for a geometry), both computed by the model
//! (`tactile-math`) so the hardware and the model share every number.
//!
//! Pure: no I/O. `tactile hdl` writes these into a folder; this crate's build script
//! (feature `verilator`) includes this file to build the RTL it simulates.

use std::fmt::Write as _;
use tactile_math::cordic::hdl::{RtlConstants, REDUCE_GUARD};
use tactile_math::cordic::Rounding;
use tactile_math::geometry::{Geometry, Lengths};
use tactile_math::kernels::IkConstants;

/// The hand-written, parameterized RTL (`common/rtl/hdl/`), carried in the binary so that
/// `tactile hdl` works from any folder.
pub const SOURCES: [(&str, &str); 25] = [
    ("tfb_fp.vh", include_str!("../hdl/tfb_fp.vh")),
    ("tfb_delay.v", include_str!("../hdl/tfb_delay.v")),
    ("tfb_stage.v", include_str!("../hdl/tfb_stage.v")),
    ("tfb_sincos.v", include_str!("../hdl/tfb_sincos.v")),
    ("tfb_vector.v", include_str!("../hdl/tfb_vector.v")),
    ("tfb_atan2.v", include_str!("../hdl/tfb_atan2.v")),
    ("tfb_sqrt1m.v", include_str!("../hdl/tfb_sqrt1m.v")),
    ("tfb_acos.v", include_str!("../hdl/tfb_acos.v")),
    ("tfb_top.v", include_str!("../hdl/tfb_top.v")),
    ("tb_tfb.v", include_str!("../hdl/tb_tfb.v")),
    ("f32_lat.vh", include_str!("../hdl/f32_lat.vh")),
    ("f32_fn.vh", include_str!("../hdl/f32_fn.vh")),
    ("f32_round.vh", include_str!("../hdl/f32_round.vh")),
    ("f32_add.v", include_str!("../hdl/f32_add.v")),
    ("f32_mul.v", include_str!("../hdl/f32_mul.v")),
    ("f32_div.v", include_str!("../hdl/f32_div.v")),
    ("f32_sqrt.v", include_str!("../hdl/f32_sqrt.v")),
    ("tb_f32.v", include_str!("../hdl/tb_f32.v")),
    ("kin_sincos3.v", include_str!("../hdl/kin_sincos3.v")),
    ("kin_fk.v", include_str!("../hdl/kin_fk.v")),
    ("kin_kff.v", include_str!("../hdl/kin_kff.v")),
    ("kin_fbf.v", include_str!("../hdl/kin_fbf.v")),
    ("kin_ik.v", include_str!("../hdl/kin_ik.v")),
    ("kin_top.v", include_str!("../hdl/kin_top.v")),
    ("tb_kin.v", include_str!("../hdl/tb_kin.v")),
];

/// The modules of the hardware, in compile order: the TFB's, the f32 units, the
/// paper's modules (the testbenches and the synthesis tops come on top of these).
pub const MODULES: [&str; 16] = [
    "tfb_delay.v",
    "tfb_stage.v",
    "tfb_sincos.v",
    "tfb_vector.v",
    "tfb_atan2.v",
    "tfb_sqrt1m.v",
    "tfb_acos.v",
    "f32_add.v",
    "f32_mul.v",
    "f32_div.v",
    "f32_sqrt.v",
    "kin_sincos3.v",
    "kin_fk.v",
    "kin_kff.v",
    "kin_fbf.v",
    "kin_ik.v",
];

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

/// The text of `kin_params.vh`: the geometry's lengths and IK's constants as f32 bits.
pub fn kin_params_vh(geometry: &Geometry) -> String {
    let g: Lengths<f32> = geometry.lengths();
    let k = IkConstants::of(&g);
    let rows = [
        ("L1", g.l1, "upper arm"),
        ("L2", g.l2, "forearm"),
        ("L3", g.l3, "shoulder height"),
        ("L4", g.l4, "L1 + a"),
        ("C_GAMMA", k.c_gamma, "L1 L1 - L2 L2"),
        ("TWO_L1", k.two_l1, "2 L1"),
        ("C_ALPHA", k.c_alpha, "L1 L1 + L2 L2"),
        ("D_ALPHA", k.d_alpha, "2 L1 L2"),
        ("REACH2", k.reach2, "2 (L1 + L2)"),
        ("REACH4", k.reach4, "4 (L1 + L2)"),
        ("ONE_TOL", k.one_tol, "1 + 16 eps"),
        ("HALF_PI", std::f32::consts::FRAC_PI_2, "pi / 2"),
    ];
    let mut s = String::from(
        "// kin_params.vh: the modules' constants as f32 bits, each computed in f32 by the\n\
         // model's kernels (tactile-math, kernels::IkConstants). Written by\n\
         // `tactile hdl rtl`: regenerate it, do not edit it.\n",
    );
    for (name, v, what) in rows {
        let _ = writeln!(
            s,
            "localparam [31:0] {name:<7} = 32'h{:08x}; // {what}: {v:e}",
            v.to_bits()
        );
    }
    let _ = writeln!(
        s,
        "localparam integer L1_NE_L2 = {}; // r = 0 is outside the workspace",
        u8::from(g.l1 != g.l2)
    );
    s
}

/// Every file of the RTL for a format and a geometry: the sources, then
/// `tfb_params.vh` and `kin_params.vh`.
pub fn files(c: &RtlConstants, geometry: &Geometry) -> Vec<(&'static str, String)> {
    SOURCES
        .iter()
        .map(|(n, t)| (*n, (*t).to_string()))
        .chain([
            ("tfb_params.vh", params_vh(c)),
            ("kin_params.vh", kin_params_vh(geometry)),
        ])
        .collect()
}
