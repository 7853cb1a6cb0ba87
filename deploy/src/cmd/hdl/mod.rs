//! `tactile hdl`: the TFB as RTL. Writes the Verilog with a format's parameters,
//! the model's test vectors, runs the co-simulation (Icarus Verilog) and the
//! synthesis (Yosys, Virtex-6) that hold the RTL against the model, and the modules'
//! timing from a real place and route (Yosys and nextpnr, ECP5)
//! (docs/09-the-hardware.md).

mod kin;
mod params;
mod sim;
mod synth;
mod timing;
mod units;
mod vectors;

use super::datapath::DatapathArgs;
use crate::error::Error;
use clap::{Args, Subcommand, ValueEnum};
use std::io::Write;
use std::path::PathBuf;

pub use params::{latency, model, write_rtl};
pub use tactile_rtl::text::{params_vh, Pipeline, MODULES};
pub use vectors::vectors;

/// Arguments of `tactile hdl`.
#[derive(Debug, Args)]
pub struct HdlArgs {
    /// What to make or run.
    #[command(subcommand)]
    pub command: HdlCommand,
}

/// The `tactile hdl` subcommands.
#[derive(Debug, Subcommand)]
pub enum HdlCommand {
    /// Write the TFB's Verilog and the format's tfb_params.vh into a folder.
    Rtl {
        /// Folder to write (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Which stage registers the modules keep.
        #[arg(long, value_enum, default_value = "sample")]
        pipeline: PipelineArg,
        /// Fixed-point format and the arm's geometry (the modules' constants).
        #[command(flatten)]
        datapath: DatapathArgs,
    },
    /// Write test vectors from the hybrid model (stdout, or --out).
    Vectors {
        /// Which block: a TFB function, an f32 unit or a module.
        #[arg(long, value_enum)]
        function: Function,
        /// Samples beyond the edge cases: half an even sweep of the input range, half
        /// random from the seed (1 to 10^7).
        #[arg(long, default_value_t = 20_000, value_parser = sim::count_parser())]
        count: usize,
        /// Seed of the random inputs.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// File to write instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Fixed-point format and the arm's geometry (the modules' constants).
        #[command(flatten)]
        datapath: DatapathArgs,
    },
    /// Run the RTL over the model's vectors in Icarus Verilog, bit for bit.
    Cosim(sim::CosimArgs),
    /// Synthesize each function with Yosys for Virtex-6 and print its resources.
    Synth(synth::SynthArgs),
    /// Place and route each of the paper's modules on an ECP5 (Yosys, nextpnr-ecp5):
    /// its clock rate, its latency in ns, its cells, beside the paper's Virtex-6.
    Timing(timing::TimingArgs),
}

/// `--pipeline`: which of the stage registers the modules keep
/// ([`tactile_rtl::text::Pipeline`]). The bits are the same in every configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PipelineArg {
    /// Every stage a register: one sample a clock, the most clocks a sample (FK 35).
    Sample,
    /// One register at each unit's output: an f32 operation or a TFB function a clock.
    Unit,
    /// The paper's architecture: each module's datapath between its inputs and one
    /// output register, one clock a sample, the least latency.
    Module,
}

impl From<PipelineArg> for Pipeline {
    fn from(p: PipelineArg) -> Pipeline {
        match p {
            PipelineArg::Sample => Pipeline::Sample,
            PipelineArg::Unit => Pipeline::Unit,
            PipelineArg::Module => Pipeline::Module,
        }
    }
}

/// A block of the hardware: a TFB function, an f32 unit or one of the paper's modules.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Function {
    /// TFB, rotation mode: sin and cos of an angle.
    Sincos,
    /// TFB, vectoring mode: the angle of (x, y).
    Atan2,
    /// TFB: acos(a) = atan2(sqrt((1 - a)(1 + a)), a), the root in f32.
    Acos,
    /// f32 unit: a + b.
    Add,
    /// f32 unit: a - b (the adder with b negated).
    Sub,
    /// f32 unit: a * b.
    Mul,
    /// f32 unit: a / b.
    Div,
    /// f32 unit: sqrt(a).
    Sqrt,
    /// Module FK-HMD / FK-HSD: forward kinematics.
    Fk,
    /// Module KFF-HMD: joint torques J^T F.
    Kff,
    /// Module FBF-HSD: the feedback force h (obj - env).
    Fbf,
    /// Module IK-HSD: inverse kinematics.
    Ik,
}

/// What kind of block a [`Function`] is: each kind has its own testbench.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// A TFB function (`tb_tfb.v`).
    Tfb,
    /// An f32 unit (`tb_f32.v`).
    Unit(units::Unit),
    /// One of the paper's modules (`tb_kin.v`).
    Module(kin::Module),
}

impl Function {
    /// Every block, in the order the reports list them.
    pub const ALL: [Function; 12] = [
        Function::Sincos,
        Function::Atan2,
        Function::Acos,
        Function::Add,
        Function::Sub,
        Function::Mul,
        Function::Div,
        Function::Sqrt,
        Function::Fk,
        Function::Kff,
        Function::Fbf,
        Function::Ik,
    ];

    /// The TFB's three functions.
    pub const TFB: [Function; 3] = [Function::Sincos, Function::Atan2, Function::Acos];

    /// The CLI and report name.
    pub fn name(self) -> &'static str {
        match self {
            Function::Sincos => "sincos",
            Function::Atan2 => "atan2",
            Function::Acos => "acos",
            Function::Add => "add",
            Function::Sub => "sub",
            Function::Mul => "mul",
            Function::Div => "div",
            Function::Sqrt => "sqrt",
            Function::Fk => "fk",
            Function::Kff => "kff",
            Function::Fbf => "fbf",
            Function::Ik => "ik",
        }
    }

    /// Which kind of block it is.
    pub fn family(self) -> Family {
        use kin::Module;
        use units::Unit;
        match self {
            Function::Sincos | Function::Atan2 | Function::Acos => Family::Tfb,
            Function::Add => Family::Unit(Unit::Add),
            Function::Sub => Family::Unit(Unit::Sub),
            Function::Mul => Family::Unit(Unit::Mul),
            Function::Div => Family::Unit(Unit::Div),
            Function::Sqrt => Family::Unit(Unit::Sqrt),
            Function::Fk => Family::Module(Module::Fk),
            Function::Kff => Family::Module(Module::Kff),
            Function::Fbf => Family::Module(Module::Fbf),
            Function::Ik => Family::Module(Module::Ik),
        }
    }

    /// The vector file's fields, in order.
    pub fn fields(self) -> &'static str {
        match self {
            Function::Sincos => "angle range_err code folded flip sin_code cos_code sin cos",
            Function::Atan2 => "y x stages x_code y_code z_code angle",
            Function::Acos => "a stages root x_code y_code z_code angle",
            Function::Add | Function::Sub | Function::Mul | Function::Div => "a b r",
            Function::Sqrt => "a r",
            Function::Fk => "t1 t2 t3 err s1 c1 s2 c2 s3 c3 x y z",
            Function::Kff => {
                "t1 t2 t3 f1 f2 f3 err s1 c1 s2 c2 s3 c3 j11 j12 j13 j21 j22 j23 j31 j32 j33 \
                 tau1 tau2 tau3"
            }
            Function::Fbf => "o1 o2 o3 e1 e2 e3 h1 h2 h3 d1 d2 d3 f1 f2 f3",
            Function::Ik => {
                "x y z status xs ys zs atan rr2 big_r r2 r cg gamma beta ca alpha t1 t2 t3"
            }
        }
    }

    /// The testbench's define (the synthesis top is `top_<name>`).
    fn define(self) -> String {
        let prefix = match self.family() {
            Family::Tfb => "FUNC",
            Family::Unit(_) => "OP",
            Family::Module(_) => "MOD",
        };
        format!("{prefix}_{}", self.name().to_uppercase())
    }

    /// The testbench and the prefix of its result line.
    fn testbench(self) -> (&'static str, &'static str) {
        match self.family() {
            Family::Tfb => ("tb_tfb.v", "tfb-cosim"),
            Family::Unit(_) => ("tb_f32.v", "f32-cosim"),
            Family::Module(_) => ("tb_kin.v", "kin-cosim"),
        }
    }
}

/// Writes the vectors of any block to `out`, a line at a time; returns their number.
pub fn block_vectors(
    cordic: &tactile_math::cordic::Cordic,
    k: &tactile_math::cordic::hdl::RtlConstants,
    geometry: &tactile_math::geometry::Geometry,
    (f, count, seed): (Function, usize, u64),
    out: &mut dyn Write,
) -> std::io::Result<usize> {
    match f.family() {
        Family::Tfb => vectors(cordic, k, f, count, seed, out),
        Family::Unit(u) => units::unit_vectors(u, f.name(), count, seed, out),
        Family::Module(m) => {
            writeln!(out, "// fields: {}", f.fields())?;
            let top = k.three_pi_up;
            kin::kin_vectors(m, f.name(), cordic, top, geometry, count, seed, out)
        }
    }
}

/// `tactile hdl vectors`: to a file or stdout, through a buffer, never held whole;
/// a stop request (SIGINT, SIGTERM) ends it at the next write.
fn write_vectors(
    (function, count, seed): (Function, usize, u64),
    out: Option<&std::path::Path>,
    datapath: &DatapathArgs,
) -> Result<(), Error> {
    let (cordic, k) = model(datapath.cordic()?)?;
    let geometry = datapath.geometry()?;
    let (mut sink, shown): (Box<dyn Write>, String) = match out {
        Some(path) => {
            let file = std::fs::File::create(path)
                .map_err(Error::io(format!("writing {}", path.display())))?;
            (
                Box::new(crate::stop::Checked(file)),
                path.display().to_string(),
            )
        }
        None => (
            Box::new(crate::stop::Output::stdout()),
            "stdout".to_string(),
        ),
    };
    let mut buf = std::io::BufWriter::with_capacity(1 << 16, &mut sink);
    block_vectors(&cordic, &k, &geometry, (function, count, seed), &mut buf)
        .and_then(|_| buf.flush())
        .map_err(crate::stop::or_io(
            format!("writing {shown}"),
            "the vectors written so far are incomplete",
        ))
}

/// Runs `tactile hdl`. Everything but `rtl` can run long: a stop request (SIGINT,
/// SIGTERM) ends it within a second, its tools killed and its work folder removed.
pub fn main(args: &HdlArgs) -> Result<(), Error> {
    if !matches!(args.command, HdlCommand::Rtl { .. }) {
        crate::stop::watch()?;
    }
    match &args.command {
        HdlCommand::Rtl {
            out,
            pipeline,
            datapath,
        } => {
            let (_, k) = model(datapath.cordic()?)?;
            let pipeline = Pipeline::from(*pipeline);
            write_rtl(out, &k, &datapath.geometry()?, pipeline)?;
            crate::outln!(
                "wrote the RTL (TFB, f32 units, modules) for this format and geometry, \
                 pipeline {}, into {}",
                pipeline.name(),
                out.display()
            );
            Ok(())
        }
        HdlCommand::Vectors {
            function,
            count,
            seed,
            out,
            datapath,
        } => write_vectors((*function, *count, *seed), out.as_deref(), datapath),
        HdlCommand::Cosim(a) => sim::cosim_main(a),
        HdlCommand::Synth(a) => synth::synth_main(a),
        HdlCommand::Timing(a) => timing::timing_main(a),
    }
}
