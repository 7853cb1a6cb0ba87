//! `tactile hdl`: the TFB as RTL. Writes the Verilog with a format's parameters,
//! the model's test vectors, runs the co-simulation (Icarus Verilog) and the
//! synthesis (Yosys, Virtex-6) that hold the RTL against the model
//! (docs/09-the-hardware.md).

mod params;
mod sim;
mod vectors;

use super::datapath::FormatArgs;
use crate::error::Error;
use clap::{Args, Subcommand, ValueEnum};
use std::io::Write;
use std::path::PathBuf;

pub use params::{latency, model, params_vh, write_rtl, MODULES};
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
        /// Fixed-point format.
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Write test vectors from the hybrid model (stdout, or --out).
    Vectors {
        /// Which function.
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
        /// Fixed-point format.
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Run the RTL over the model's vectors in Icarus Verilog, bit for bit.
    Cosim(sim::CosimArgs),
    /// Synthesize each function with Yosys for Virtex-6 and print its resources.
    Synth(sim::SynthArgs),
}

/// A function of the TFB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Function {
    /// Rotation mode: sin and cos of an angle.
    Sincos,
    /// Vectoring mode: the angle of (x, y).
    Atan2,
    /// acos(a) = atan2(sqrt((1 - a)(1 + a)), a), the root in f32.
    Acos,
}

impl Function {
    /// Every function, in the order the reports list them.
    pub const ALL: [Function; 3] = [Function::Sincos, Function::Atan2, Function::Acos];

    /// The CLI and report name.
    pub fn name(self) -> &'static str {
        match self {
            Function::Sincos => "sincos",
            Function::Atan2 => "atan2",
            Function::Acos => "acos",
        }
    }

    /// The vector file's fields, in order.
    pub fn fields(self) -> &'static str {
        match self {
            Function::Sincos => "angle range_err code folded flip sin_code cos_code sin cos",
            Function::Atan2 => "y x stages x_code y_code z_code angle",
            Function::Acos => "a stages root x_code y_code z_code angle",
        }
    }

    /// The testbench's define and the synthesis top.
    fn define(self) -> &'static str {
        match self {
            Function::Sincos => "FUNC_SINCOS",
            Function::Atan2 => "FUNC_ATAN2",
            Function::Acos => "FUNC_ACOS",
        }
    }
}

/// Runs `tactile hdl`.
pub fn main(args: &HdlArgs) -> Result<(), Error> {
    match &args.command {
        HdlCommand::Rtl { out, format } => {
            let (_, k) = model(format.cordic()?)?;
            write_rtl(out, &k)?;
            crate::outln!("wrote the TFB's RTL for this format into {}", out.display());
            Ok(())
        }
        HdlCommand::Vectors {
            function,
            count,
            seed,
            out,
            format,
        } => {
            let (cordic, k) = model(format.cordic()?)?;
            let (text, _) = vectors(&cordic, &k, *function, *count, *seed);
            match out {
                Some(path) => std::fs::write(path, text)
                    .map_err(Error::io(format!("writing {}", path.display()))),
                None => std::io::stdout()
                    .lock()
                    .write_all(text.as_bytes())
                    .map_err(Error::io("writing stdout")),
            }
        }
        HdlCommand::Cosim(a) => sim::cosim_main(a),
        HdlCommand::Synth(a) => sim::synth_main(a),
    }
}
