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
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Subcommand, ValueEnum};
use std::io::Write;
use std::path::PathBuf;
use tactile_launch::error::Error;

pub use params::{latency, model, write_rtl};
pub use tactile_rtl::text::{params_vh, Block, Pipeline, MODULES};
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
        #[arg(long, value_parser = block_parser())]
        function: Block,
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

/// `--function`: a block by its name ([`Block::name`]), its help [`Block::what`].
pub fn block_parser() -> impl TypedValueParser<Value = Block> {
    PossibleValuesParser::new(Block::ALL.map(|b| PossibleValue::new(b.name()).help(b.what())))
        .try_map(|s| s.parse::<Block>())
}

/// What kind of block a [`Block`] is: each kind has its own testbench.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// A TFB function (`tb_tfb.v`).
    Tfb,
    /// An f32 unit (`tb_f32.v`).
    Unit(units::Unit),
    /// One of the paper's modules (`tb_kin.v`).
    Module(kin::Module),
}

/// What `tactile hdl` knows of a block beyond the RTL's list ([`Block`]): its
/// family, its testbench and its vectors' fields.
pub trait Bench {
    /// Which kind of block it is.
    fn family(self) -> Family;
    /// The vector file's fields, in order.
    fn fields(self) -> &'static str;
    /// The testbench's define (the synthesis top is `top_<name>`).
    fn define(self) -> String;
    /// The testbench and the prefix of its result line.
    fn testbench(self) -> (&'static str, &'static str);
}

impl Bench for Block {
    fn family(self) -> Family {
        use kin::Module;
        use units::Unit;
        match self {
            Block::Sincos | Block::Atan2 | Block::Acos => Family::Tfb,
            Block::Add => Family::Unit(Unit::Add),
            Block::Sub => Family::Unit(Unit::Sub),
            Block::Mul => Family::Unit(Unit::Mul),
            Block::Div => Family::Unit(Unit::Div),
            Block::Sqrt => Family::Unit(Unit::Sqrt),
            Block::Fk => Family::Module(Module::Fk),
            Block::Kff => Family::Module(Module::Kff),
            Block::Fbf => Family::Module(Module::Fbf),
            Block::Ik => Family::Module(Module::Ik),
        }
    }

    fn fields(self) -> &'static str {
        match self {
            Block::Sincos => "angle range_err code folded flip sin_code cos_code sin cos",
            Block::Atan2 => "y x stages x_code y_code z_code angle",
            Block::Acos => "a stages root x_code y_code z_code angle",
            Block::Add | Block::Sub | Block::Mul | Block::Div => "a b r",
            Block::Sqrt => "a r",
            Block::Fk => "t1 t2 t3 err s1 c1 s2 c2 s3 c3 x y z",
            Block::Kff => {
                "t1 t2 t3 f1 f2 f3 err s1 c1 s2 c2 s3 c3 j11 j12 j13 j21 j22 j23 j31 j32 j33 \
                 tau1 tau2 tau3"
            }
            Block::Fbf => "o1 o2 o3 e1 e2 e3 h1 h2 h3 d1 d2 d3 f1 f2 f3",
            Block::Ik => {
                "x y z status xs ys zs atan rr2 big_r r2 r cg gamma beta ca alpha t1 t2 t3"
            }
        }
    }

    fn define(self) -> String {
        let prefix = match self.family() {
            Family::Tfb => "FUNC",
            Family::Unit(_) => "OP",
            Family::Module(_) => "MOD",
        };
        format!("{prefix}_{}", self.name().to_uppercase())
    }

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
    (f, count, seed): (Block, usize, u64),
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
    (function, count, seed): (Block, usize, u64),
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
                Box::new(tactile_launch::stop::Checked(file)),
                path.display().to_string(),
            )
        }
        None => (
            Box::new(tactile_launch::stop::Output::stdout()),
            "stdout".to_string(),
        ),
    };
    let mut buf = std::io::BufWriter::with_capacity(1 << 16, &mut sink);
    block_vectors(&cordic, &k, &geometry, (function, count, seed), &mut buf)
        .and_then(|_| buf.flush())
        .map_err(tactile_launch::stop::or_io(
            format!("writing {shown}"),
            "the vectors written so far are incomplete",
        ))
}

/// Runs `tactile hdl`. Everything but `rtl` can run long: a stop request (SIGINT,
/// SIGTERM) ends it within a second, its tools killed and its work folder removed.
pub fn main(args: &HdlArgs) -> Result<(), Error> {
    if !matches!(args.command, HdlCommand::Rtl { .. }) {
        tactile_launch::stop::watch()?;
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
            tactile_launch::outln!(
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
