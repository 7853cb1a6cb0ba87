//! The RTL's text: the hand-written Verilog (`hdl/`, beside this crate's sources: it
//! packages with the crate that compiles it) and the three generated
//! parameter files, `tfb_params.vh` (a format's CORDIC constants), `kin_params.vh`
//! (the modules' constants for a geometry), both computed by the model
//! (`tactile-math`) so the hardware and the model share every number, and `pipe.vh`
//! (which stage registers are registers: [`Pipeline`]).
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

/// How deep the modules are pipelined: which of the registers between the stages of
/// every unit (f32 adder, multiplier, divider, square root; the TFB's functions) are
/// registers and which are wires. Written into `pipe.vh`; the bits never change, only
/// the clocks a sample takes and how long a clock must be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Pipeline {
    /// Every stage a register: one new sample a clock, the shortest clock, the most
    /// clocks a sample (FK 35, IK 175).
    #[default]
    Sample,
    /// One register a unit, at its output: each f32 operation and each TFB function
    /// takes one clock (FK 5, IK 14), its whole datapath inside that clock.
    Unit,
    /// The paper's architecture: the whole datapath of a module between its input
    /// and one output register, so a sample takes one clock (as long as the longest
    /// path through the module): the least latency.
    Module,
}

impl Pipeline {
    /// Every configuration, deepest first.
    pub const ALL: [Pipeline; 3] = [Pipeline::Sample, Pipeline::Unit, Pipeline::Module];

    /// The name in `pipe.vh`, the CLI and the reports.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::Sample => "sample",
            Pipeline::Unit => "unit",
            Pipeline::Module => "module",
        }
    }

    /// The configuration called `name`, if any.
    pub fn from_name(name: &str) -> Option<Pipeline> {
        Pipeline::ALL.into_iter().find(|p| p.name() == name)
    }

    /// 1 where a unit's inner stages are registers (`PIPE_S`).
    pub fn stage(self) -> u32 {
        u32::from(self == Pipeline::Sample)
    }

    /// 1 where a unit's output is a register (`PIPE_U`).
    pub fn unit(self) -> u32 {
        u32::from(self != Pipeline::Module)
    }

    /// 1 where a module's outputs are registered on their own (`PIPE_M`): when no
    /// unit holds a register, so a sample still takes one clock.
    pub fn module(self) -> u32 {
        u32::from(self == Pipeline::Module)
    }

    /// Clocks through a unit of `inner` inner stages (f32_lat.vh's formulas).
    fn through(self, inner: u32) -> u32 {
        inner * self.stage() + self.unit()
    }

    /// Clocks from a block's input to its output with a TFB of `iterations`: the
    /// RTL's LATENCY localparams (f32_lat.vh, kin_*.v), which the co-simulation
    /// measures and holds to these.
    pub fn latency(self, block: Block, iterations: u32) -> u32 {
        let vector = self.through(iterations + 3);
        let unit = |b| self.latency(b, iterations);
        match block {
            Block::Sincos => self.through(iterations + 4),
            Block::Atan2 => vector,
            Block::Acos => self.through(32) + vector,
            Block::Add | Block::Sub | Block::Mul => self.through(3),
            Block::Div | Block::Sqrt => self.through(27),
            Block::Fk => {
                unit(Block::Sincos) + 2 * unit(Block::Mul) + 2 * unit(Block::Add) + self.module()
            }
            Block::Kff => {
                unit(Block::Sincos) + 3 * unit(Block::Mul) + 3 * unit(Block::Add) + self.module()
            }
            Block::Fbf => unit(Block::Add) + unit(Block::Mul) + self.module(),
            // The acos's argument, then acos, then the three additions of theta3; 4
            // stages of comparisons and muxes on the way.
            Block::Ik => {
                6 * unit(Block::Add)
                    + 3 * unit(Block::Mul)
                    + 2 * unit(Block::Div)
                    + unit(Block::Sqrt)
                    + unit(Block::Acos)
                    + 4 * self.stage()
                    + self.module()
            }
        }
    }
}

/// A block of the hardware: a TFB function, an f32 unit, one of the paper's modules.
/// The one list of them: their latencies ([`Pipeline::latency`]), their names on the
/// command line and in the reports (`tactile hdl --function`), the placed figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Block {
    /// TFB, rotation mode.
    Sincos,
    /// TFB, vectoring mode.
    Atan2,
    /// TFB: the root, then vectoring.
    Acos,
    /// f32 adder.
    Add,
    /// f32 subtractor (the adder with b negated).
    Sub,
    /// f32 multiplier.
    Mul,
    /// f32 divider.
    Div,
    /// f32 square root.
    Sqrt,
    /// FK-HMD / FK-HSD.
    Fk,
    /// KFF-HMD.
    Kff,
    /// FBF-HSD.
    Fbf,
    /// IK-HSD.
    Ik,
}

impl Block {
    /// Every block, in the order the reports list them.
    pub const ALL: [Block; 12] = [
        Block::Sincos,
        Block::Atan2,
        Block::Acos,
        Block::Add,
        Block::Sub,
        Block::Mul,
        Block::Div,
        Block::Sqrt,
        Block::Fk,
        Block::Kff,
        Block::Fbf,
        Block::Ik,
    ];

    /// The TFB's three functions.
    pub const TFB: [Block; 3] = [Block::Sincos, Block::Atan2, Block::Acos];

    /// The name on the command line and in the reports.
    pub fn name(self) -> &'static str {
        match self {
            Block::Sincos => "sincos",
            Block::Atan2 => "atan2",
            Block::Acos => "acos",
            Block::Add => "add",
            Block::Sub => "sub",
            Block::Mul => "mul",
            Block::Div => "div",
            Block::Sqrt => "sqrt",
            Block::Fk => "fk",
            Block::Kff => "kff",
            Block::Fbf => "fbf",
            Block::Ik => "ik",
        }
    }

    /// What it computes, in a line (the command line's help).
    pub fn what(self) -> &'static str {
        match self {
            Block::Sincos => "TFB, rotation mode: sin and cos of an angle",
            Block::Atan2 => "TFB, vectoring mode: the angle of (x, y)",
            Block::Acos => "TFB: acos(a) = atan2(sqrt((1 - a)(1 + a)), a), the root in f32",
            Block::Add => "f32 unit: a + b",
            Block::Sub => "f32 unit: a - b (the adder with b negated)",
            Block::Mul => "f32 unit: a * b",
            Block::Div => "f32 unit: a / b",
            Block::Sqrt => "f32 unit: sqrt(a)",
            Block::Fk => "Module FK-HMD / FK-HSD: forward kinematics",
            Block::Kff => "Module KFF-HMD: joint torques J^T F",
            Block::Fbf => "Module FBF-HSD: the feedback force h (obj - env)",
            Block::Ik => "Module IK-HSD: inverse kinematics",
        }
    }
}

/// A name that is no block's. (Display and Error by hand: the build script compiles
/// this file too, without the crate's dependencies.)
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownBlock(pub String);

impl std::fmt::Display for UnknownBlock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = Block::ALL.iter().map(|b| b.name()).collect();
        write!(f, "{:?} is not a block ({})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownBlock {}

impl std::str::FromStr for Block {
    type Err = UnknownBlock;
    fn from_str(s: &str) -> Result<Block, UnknownBlock> {
        Block::ALL
            .into_iter()
            .find(|b| b.name() == s)
            .ok_or_else(|| UnknownBlock(s.to_string()))
    }
}

/// The text of `pipe.vh`: the pipeline configuration as the RTL reads it, a macro for
/// each kind of stage register (`STAGE_REG`, a unit's inner stage; `UNIT_REG`, its
/// output), clocked or combinational, and the numbers the latencies are computed from.
pub fn pipe_vh(p: Pipeline) -> String {
    let block = |on: u32| {
        if on == 1 {
            "always @(posedge clk)"
        } else {
            "always @*"
        }
    };
    format!(
        "// pipe.vh: the pipeline configuration \"{name}\". Written by `tactile hdl rtl`\n\
         // (tactile_rtl::text::Pipeline): regenerate it, do not edit it.\n\
         // A stage written `STAGE_REG or `UNIT_REG is a register, or (always @*) a wire:\n\
         // its non-blocking assignments then settle within the clock in the order\n\
         // written (Verilator makes them blocking), so a stage must assign a value\n\
         // before a later statement of its block reads it.\n\
         `ifndef TACTILE_PIPE_VH\n\
         `define TACTILE_PIPE_VH\n\
         `define STAGE_REG {stage_block}\n\
         `define UNIT_REG {unit_block}\n\
         `endif\n\
         localparam integer PIPE_S = {s};  // a unit's inner stages are registers\n\
         localparam integer PIPE_U = {u};  // a unit's output is a register\n\
         localparam integer PIPE_M = {m};  // a module's outputs are registered on their own\n",
        name = p.name(),
        stage_block = block(p.stage()),
        unit_block = block(p.unit()),
        s = p.stage(),
        u = p.unit(),
        m = p.module(),
    )
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

/// Every file of the RTL for a format, a geometry and a pipeline: the sources, then
/// `tfb_params.vh`, `kin_params.vh` and `pipe.vh`.
pub fn files(
    c: &RtlConstants,
    geometry: &Geometry,
    pipeline: Pipeline,
) -> Vec<(&'static str, String)> {
    SOURCES
        .iter()
        .map(|(n, t)| (*n, (*t).to_string()))
        .chain([
            ("tfb_params.vh", params_vh(c)),
            ("kin_params.vh", kin_params_vh(geometry)),
            ("pipe.vh", pipe_vh(pipeline)),
        ])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clocks docs/09 gives for each configuration at [s16.13] (14 iterations):
    /// checked here on any machine, and against the RTL's own clocks by `tactile hdl
    /// cosim` where Icarus is installed.
    #[test]
    fn every_block_is_found_by_its_name() {
        for b in Block::ALL {
            assert_eq!(b.name().parse::<Block>(), Ok(b));
        }
        assert!("tan".parse::<Block>().is_err());
    }

    #[test]
    fn each_pipeline_has_the_latencies_docs_09_gives() {
        let modules = [Block::Fk, Block::Kff, Block::Fbf, Block::Ik];
        let at = |p: Pipeline| modules.map(|b| p.latency(b, 14));
        assert_eq!(at(Pipeline::Sample), [35, 43, 8, 175]);
        assert_eq!(at(Pipeline::Unit), [5, 7, 2, 14]);
        assert_eq!(at(Pipeline::Module), [1, 1, 1, 1]);
        let units = [
            Block::Add,
            Block::Div,
            Block::Sincos,
            Block::Atan2,
            Block::Acos,
        ];
        let at = |p: Pipeline| units.map(|b| p.latency(b, 14));
        assert_eq!(at(Pipeline::Sample), [4, 28, 19, 18, 51]);
        assert_eq!(at(Pipeline::Unit), [1, 1, 1, 1, 2]);
        assert_eq!(at(Pipeline::Module), [0, 0, 0, 0, 0]);
        // A format of more iterations is deeper only where stages are registers.
        assert_eq!(Pipeline::Sample.latency(Block::Ik, 30), 175 + 16);
        assert_eq!(Pipeline::Unit.latency(Block::Ik, 30), 14);
    }

    #[test]
    fn pipe_vh_says_which_stages_are_registers() {
        for p in Pipeline::ALL {
            assert_eq!(Pipeline::from_name(p.name()), Some(p));
            let text = pipe_vh(p);
            let clocked = |m: &str| text.contains(&format!("`define {m} always @(posedge clk)"));
            assert_eq!(
                (clocked("STAGE_REG"), clocked("UNIT_REG")),
                (p == Pipeline::Sample, p != Pipeline::Module),
                "{text}"
            );
            assert!(text.contains(&format!("localparam integer PIPE_M = {};", p.module())));
        }
        assert_eq!(Pipeline::from_name("fast"), None);
    }
}
