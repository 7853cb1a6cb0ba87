//! Command-line parsing and dispatch for `tactile`.

use crate::error::{Error, EXIT_BAD_INPUT};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use tactile_math::arith::ArithKind;
use tactile_math::cordic::{CordicConfig, Rounding};
use tactile_math::geometry::Geometry;

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
    /// Measure the loop's own overhead at 1 and 10 kHz beside UDP and a bare iceoryx2
    /// hop, and the lockstep throughput.
    Bench(BenchArgs),
    /// Join the nodes' records (one folder, or one folder per node) into the run's
    /// report: summary, trace, histograms, plots.
    Report(ReportArgs),
    /// Run a scenario for every combination of values (--set KEY=V1,V2,...), and
    /// tabulate and plot the runs' metrics.
    Sweep(SweepArgs),
    /// The echo side of `tactile bench`'s bare iceoryx2 hop (started by the bench).
    #[command(hide = true)]
    BenchEcho(EchoArgs),
}

/// Arguments of `tactile sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Scenario file (TOML) every run starts from.
    pub scenario: PathBuf,
    /// A swept key and its values, KEY=V1,V2,... (commas inside brackets or quotes
    /// belong to the value: network.forward.delay=[0,0,0],[5,5,5]). Repeatable: every
    /// combination runs. The first key is the plots' x axis, the second their lines.
    #[arg(long, value_name = "KEY=V1,V2,...", required = true)]
    pub set: Vec<String>,
    /// Folder for sweep.csv, the plots, and one folder per run (run-0000, ...).
    #[arg(long, default_value = "sweep-out")]
    pub out: PathBuf,
    /// Start the three node programs for every run (in realtime, each run then takes
    /// its real time) instead of running them in-process.
    #[arg(long)]
    pub processes: bool,
    /// Write each run's trace.csv too (about 1 kB per sample).
    #[arg(long)]
    pub trace: bool,
}

/// Arguments of `tactile report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Folders holding the nodes' records (master.rec, emulator.rec, slave.rec).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Folder for the report (default: the master's folder).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write no trace.csv (a long run's trace is about 1 kB per sample).
    #[arg(long)]
    pub no_trace: bool,
}

/// Arguments of `tactile bench-echo`.
#[derive(Debug, Args)]
pub struct EchoArgs {
    /// iceoryx2 prefix of the hop.
    #[arg(long)]
    pub prefix: String,
    /// Busy-poll budget, microseconds.
    #[arg(long, default_value_t = 0)]
    pub spin_us: u64,
}

/// Arguments of `tactile bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Samples per run (each rate, each transport).
    #[arg(long, default_value_t = 60_000)]
    pub samples: u64,
    /// Rates to measure, Hz.
    #[arg(long, value_delimiter = ',', default_values_t = [1000.0, 10000.0])]
    pub rates: Vec<f64>,
    /// Seconds to probe the machine's own stalls after the loops: a SCHED_FIFO 99
    /// thread per CPU that reads the clock, 900 ms of every second (0: no probe; at
    /// most 600).
    #[arg(long, default_value_t = 20.0)]
    pub probe_s: f64,
    /// Samples of the lockstep throughput run.
    #[arg(long, default_value_t = 20_000)]
    pub lockstep_samples: u64,
    /// Output folder (bench.json and each run's report).
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Poll budget of every node, microseconds (default: the nodes' own).
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: microseconds before a sample is due that each node stops sleeping
    /// and polls (default 200, at most 40 % of a period).
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Scheduling of every loop's nodes (the same for every transport).
    #[arg(long, value_enum, default_value_t = tactile_node::sched::Policy::Fifo)]
    pub sched: tactile_node::sched::Policy,
    /// What each node's CPU does while the node sleeps, under SCHED_FIFO: halt (the
    /// kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so a
    /// halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: README "What the CPUs do while the nodes
    /// sleep").
    #[arg(long, value_enum, default_value_t = tactile_node::sched::IdleMode::Halt)]
    pub idle: tactile_node::sched::IdleMode,
    /// Do not pin the iceoryx2 processes to CPUs.
    #[arg(long)]
    pub no_pin: bool,
    /// iceoryx2 prefix of the bench's runs (default: one per invocation).
    #[arg(long)]
    pub prefix: Option<String>,
    /// Also run the Zenoh and UDP loops across two hosts: two network namespaces
    /// joined by a veth pair (made and removed by the bench; needs root).
    #[arg(long)]
    pub hosts: bool,
}

/// Arguments of `tactile run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML); without one, the built-in paper scenario
    /// (deploy/scenarios/paper.toml).
    pub scenario: Option<PathBuf>,
    /// Folder for summary.json, trace.csv, histograms and plots.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Change the scenario: KEY is a dotted path (network.forward.delay,
    /// environment.objects[0].stiffness), VALUE a TOML value ([5, 5, 5], 1000.0; a bare
    /// word is a string). Repeatable; checked like the file.
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// iceoryx2 prefix isolating this run's shared memory (default: one per launcher).
    #[arg(long)]
    pub prefix: Option<String>,
    /// Microseconds each process polls (yielding the core between polls) before it
    /// blocks on its wake-up event. Default: twice the wake-up margin (each node
    /// sleeps until 200 us before a sample is due, at most 40 % of a period), two
    /// periods in lockstep (chosen by measurement, see README "Waiting").
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: microseconds before a sample is due that each node stops sleeping
    /// and polls (default 200, at most 40 % of a period).
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Run master, emulator and slave in this process, without shared memory.
    #[arg(long)]
    pub in_process: bool,
    /// No progress line.
    #[arg(long, short)]
    pub quiet: bool,
    /// Times the emulator or the slave is restarted if it dies mid-run.
    #[arg(long, default_value_t = 3)]
    pub max_restarts: u32,
    /// What carries the samples between the nodes on this host: iceoryx2 (shared
    /// memory), udp (loopback datagrams, the reference) or zenoh (loopback TCP; across
    /// hosts, start the nodes by hand, see the README's "Across hosts").
    #[arg(long, value_enum, default_value_t = tactile_node::runtime::LinkKind::Iceoryx2)]
    pub link: tactile_node::runtime::LinkKind,
    /// Shorthand for --link udp.
    #[arg(long, conflicts_with = "link")]
    pub udp: bool,
    /// Do not pin the processes (by default the master runs on CPU 0 and the emulator
    /// and slave on CPU 1, where the machine has two CPUs).
    #[arg(long)]
    pub no_pin: bool,
    /// Scheduling the nodes set on themselves: fifo (SCHED_FIFO at priority 70 with
    /// memory locked, where permitted; otherwise SCHED_OTHER, said in the report) or
    /// other.
    #[arg(long, value_enum, default_value_t = tactile_node::sched::Policy::Fifo)]
    pub sched: tactile_node::sched::Policy,
    /// What each node's CPU does while the node sleeps, under SCHED_FIFO: halt (the
    /// kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so a
    /// halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: README "What the CPUs do while the nodes
    /// sleep").
    #[arg(long, value_enum, default_value_t = tactile_node::sched::IdleMode::Halt)]
    pub idle: tactile_node::sched::IdleMode,
    /// Write no trace.csv (a long run's trace is about 1 kB per sample); everything
    /// else is reported.
    #[arg(long)]
    pub no_trace: bool,
}

/// The kernel a `kernels` run evaluates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Module {
    /// Forward kinematics: theta1,theta2,theta3 -> x,y,z.
    Fk,
    /// Inverse kinematics: x,y,z -> theta1,theta2,theta3,reachable.
    Ik,
    /// Kinesthetic feedback force: theta1..3,fx,fy,fz -> tau1,tau2,tau3.
    Kff,
    /// Feedback force: x_obj..z_obj,x_env..z_env,hx,hy,hz -> fx,fy,fz.
    Fbf,
}

/// CLI spelling of [`ArithKind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ArithArg {
    /// f64 reference.
    F64,
    /// f32 software model.
    F32,
    /// f32 with CORDIC in fixed point (the FPGA datapath).
    Hybrid,
}

impl From<ArithArg> for ArithKind {
    fn from(a: ArithArg) -> Self {
        match a {
            ArithArg::F64 => ArithKind::F64,
            ArithArg::F32 => ArithKind::F32,
            ArithArg::Hybrid => ArithKind::Hybrid,
        }
    }
}

/// CLI spelling of [`Rounding`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RoundingArg {
    /// Floor, what a plain arithmetic shift does.
    Truncate,
    /// Round half up.
    Nearest,
}

impl From<RoundingArg> for Rounding {
    fn from(r: RoundingArg) -> Self {
        match r {
            RoundingArg::Truncate => Rounding::Truncate,
            RoundingArg::Nearest => Rounding::Nearest,
        }
    }
}

/// Fixed-point format of the CORDIC block and the device geometry.
#[derive(Debug, Clone, Args)]
pub struct DatapathArgs {
    /// Word length V of the signed fixed-point format [sV.N].
    #[arg(long, default_value_t = CordicConfig::S16_13.word)]
    pub word: u32,
    /// Fractional bits N of [sV.N].
    #[arg(long, default_value_t = CordicConfig::S16_13.frac)]
    pub frac: u32,
    /// CORDIC iterations (default derived from --frac).
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Rounding in the float-to-fixed conversion and every shift.
    #[arg(long, value_enum)]
    pub rounding: Option<RoundingArg>,
    /// Device geometry: `paper`, `omni`, or a TOML file with l1, l2, l3, a (metres).
    #[arg(long, default_value = "paper")]
    pub device: String,
}

impl DatapathArgs {
    /// The validated CORDIC configuration.
    pub fn cordic(&self) -> Result<CordicConfig, Error> {
        let rounding = self
            .rounding
            .map(Rounding::from)
            .unwrap_or(CordicConfig::S16_13.rounding);
        CordicConfig::new(self.word, self.frac, self.iterations, rounding)
            .map_err(|e| Error::BadInput(format!("bad fixed-point format: {e}")))
    }

    /// The device geometry: a preset or a validated file.
    pub fn geometry(&self) -> Result<Geometry, Error> {
        if let Some(g) = Geometry::preset(&self.device) {
            return Ok(g);
        }
        let path = PathBuf::from(&self.device);
        let text = tactile_node::files::read_text(
            &path,
            "device file",
            tactile_node::files::MAX_DEVICE_BYTES,
        )
        .map_err(|e| {
            Error::BadInput(format!(
                "--device {}: not a preset (paper, omni); {e}",
                self.device
            ))
        })?;
        tactile_scenario::geometry_from_toml(&text)
            .map_err(|e| Error::BadInput(format!("{}: {e}", path.display())))
    }
}

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

/// Arguments of `tactile paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Datapath format and device.
    #[command(flatten)]
    pub datapath: DatapathArgs,
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
            let stdin = std::io::stdin().lock();
            let mut stdout = std::io::stdout().lock();
            crate::kernels_cmd::run(&args, stdin, &mut stdout)
        }
        Command::Paper(args) => {
            let mut stdout = std::io::stdout().lock();
            crate::paper_cmd::run(&args, &mut stdout)
        }
        Command::Run(args) => crate::run_cmd::main(&args),
        Command::Bench(args) => crate::bench_cmd::main(&args),
        Command::Report(args) => crate::report_cmd::main(&args),
        Command::Sweep(args) => crate::sweep_cmd::main(&args),
        Command::BenchEcho(args) => crate::bench_cmd::echo(
            &args.prefix,
            tactile_node::ipc::WaitPolicy {
                spin: std::time::Duration::from_micros(args.spin_us),
            },
        )
        .map_err(|e| Error::Failed(e.to_string())),
    }
}
