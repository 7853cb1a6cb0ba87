//! Command-line parsing and dispatch for `tactile`.

use crate::cmd::bench::{BenchArgs, EchoArgs};
use crate::cmd::check::CheckArgs;
use crate::cmd::export::ExportArgs;
use crate::cmd::hdl::HdlArgs;
use crate::cmd::kernels::KernelsArgs;
use crate::cmd::paper::PaperArgs;
use crate::cmd::report::ReportArgs;
use crate::cmd::run::RunArgs;
use crate::cmd::sweep::SweepArgs;
use clap::{Parser, Subcommand};
use std::io::Write;
use std::process::ExitCode;
use tactile_launch::error::Error;
use tactile_runtime::exit::EXIT_BAD_INPUT;

/// Tactile: runtime and testbed for bilateral tactile-internet teleoperation.
#[derive(Debug, Parser)]
#[command(name = "tactile", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Evaluate one kernel over CSV rows from stdin, writing CSV to stdout.
    Kernels(KernelsArgs),
    /// Reproduce the paper's MSE table (hybrid against f32 on its validation run).
    Paper(PaperArgs),
    /// Run a scenario: start the master, emulator and slave programs, and report.
    Run(RunArgs),
    /// Check a scenario without running it: print it resolved (defaults filled in,
    /// --set applied), its duration, the size of what it writes, its warnings.
    Check(CheckArgs),
    /// Measure the loop's own overhead at 1 and 10 kHz beside UDP and a bare iceoryx2
    /// hop, and the lockstep throughput.
    Bench(BenchArgs),
    /// Join the nodes' records (one folder, or one folder per node) into the run's
    /// report: summary, trace, histograms, plots.
    Report(ReportArgs),
    /// Run a scenario for every combination of values (--set KEY=V1,V2,...), and
    /// tabulate and plot the runs' metrics.
    Sweep(SweepArgs),
    /// Write runs and sweeps in another tool's format: `export lerobot` a LeRobot
    /// v3.0 dataset for robot learning.
    Export(ExportArgs),
    /// The paper's trigonometric block as RTL: Verilog, test vectors from the model,
    /// co-simulation (Icarus Verilog) and synthesis (Yosys, Virtex-6).
    Hdl(HdlArgs),
    /// Drive every decoder of outside bytes (records, CDR, wire samples, attachments,
    /// scenario TOML, trajectory CSV, kernels input) with mutated inputs; exit 1 on a
    /// panic, the input kept.
    Fuzz(crate::cmd::fuzz::FuzzArgs),
    /// The echo side of `tactile bench`'s bare iceoryx2 hop (started by the bench).
    #[command(hide = true)]
    BenchEcho(EchoArgs),
}

/// Parses the command line, runs it, and maps the outcome to an exit status with one
/// readable line on stderr.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { EXIT_BAD_INPUT } else { 0 });
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of stdout has gone (`| head`): it has all it wanted.
        Err(Error::Io { source, .. }) if tactile_launch::say::closed_pipe(&source) => {
            ExitCode::SUCCESS
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "tactile: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// Runs a parsed command line against the process's stdin and stdout.
pub fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Kernels(args) => {
            tactile_launch::stop::watch()?;
            let stdin =
                std::io::BufReader::with_capacity(1 << 16, tactile_launch::stop::Input::stdin());
            crate::cmd::kernels::run(&args, stdin, &mut tactile_launch::stop::Output::stdout())
        }
        Command::Paper(args) => {
            let mut stdout = std::io::stdout().lock();
            crate::cmd::paper::run(&args, &mut stdout)
        }
        Command::Run(args) => crate::cmd::run::main(&args),
        Command::Hdl(args) => crate::cmd::hdl::main(&args),
        Command::Check(args) => crate::cmd::check::main(&args),
        Command::Bench(args) => crate::cmd::bench::main(&args),
        Command::Report(args) => crate::cmd::report::main(&args),
        Command::Sweep(args) => crate::cmd::sweep::main(&args),
        Command::Export(args) => crate::cmd::export::main(&args),
        Command::Fuzz(args) => crate::cmd::fuzz::main(&args),
        Command::BenchEcho(args) => {
            crate::cmd::bench::echo(&args.prefix, std::time::Duration::from_micros(args.spin_us))
                .map_err(|e| Error::Failed(e.to_string()))
        }
    }
}
