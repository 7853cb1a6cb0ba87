//! What the three node programs share: their command line, their start-up checks, their
//! record and the mapping of their outcome to an exit status.
//!
//! A node's `main.rs` is one call into its crate; the crate parses [`NodeArgs`], calls
//! [`prepare`] (which checks everything a user controls before anything starts), runs
//! its loop against a link and a [`Recorder`], and returns a [`NodeError`] or the
//! reason it stopped. [`exit`] turns that into one line on stderr and the status.

use crate::lock::{self, Lock};
use crate::record::{peak_rss_kb, Event, Record, RecordWriter, Start, Stop, Totals};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;
use tactile_messages::clock::now_ns;
use tactile_messages::Role;
use tactile_scenario::Scenario;

pub use crate::exit::{EXIT_BAD_INPUT, EXIT_CODES_HELP, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK};

/// What carries the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LinkKind {
    /// iceoryx2 zero-copy shared memory (one host).
    Iceoryx2,
    /// UDP datagrams (the reference most stacks use); loopback unless --udp-hosts.
    Udp,
    /// Zenoh (across hosts): --listen and --connect name the endpoints.
    Zenoh,
}

impl LinkKind {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LinkKind::Iceoryx2 => "iceoryx2",
            LinkKind::Udp => "udp",
            LinkKind::Zenoh => "zenoh",
        }
    }
}

/// The command line every node takes.
#[derive(Debug, Clone, Args)]
pub struct NodeArgs {
    /// Scenario file (TOML); its relative paths are resolved against its own folder.
    #[arg(long)]
    pub scenario: PathBuf,
    /// Folder for this node's record (`ROLE.rec`) and log (`ROLE.log`).
    #[arg(long)]
    pub out: PathBuf,
    /// Name of the run: nodes with the same prefix find each other. 1 to 24 characters
    /// from A-Z a-z 0-9 _ -.
    #[arg(long, default_value = "tactile")]
    pub prefix: String,
    /// Transport between the nodes.
    #[arg(long, value_enum, default_value_t = LinkKind::Iceoryx2)]
    pub link: LinkKind,
    /// UDP ports of master, emulator and slave, as `m,e,s` (with --link udp).
    #[arg(long, default_value = "47501,47502,47503")]
    pub udp_ports: String,
    /// Addresses of the master's, emulator's and slave's hosts, as `a,b,c` (with --link
    /// udp).
    #[arg(long, default_value = "127.0.0.1,127.0.0.1,127.0.0.1")]
    pub udp_hosts: String,
    /// Zenoh endpoint to listen on, e.g. `tcp/198.18.0.1:7447` (repeatable).
    #[arg(long)]
    pub listen: Vec<String>,
    /// Zenoh endpoint of a peer to connect to, e.g. `tcp/198.18.0.1:7447` (repeatable).
    #[arg(long)]
    pub connect: Vec<String>,
    /// Let Zenoh find peers by multicast scouting too (off: only the endpoints given).
    #[arg(long)]
    pub scout: bool,
    /// Microseconds to poll (yielding the CPU) before blocking on the wake-up event.
    /// Default: twice --wake-early-us in realtime (the node wakes that long before a
    /// sample is due), two sampling periods in lockstep; 0 blocks at once.
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: stop sleeping this long before a sample is due, then poll. Default
    /// 200 us, at most 40 % of a sampling period (measured, README "Waiting").
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Scheduling: fifo (SCHED_FIFO with memory locked, where permitted; otherwise
    /// SCHED_OTHER, said in the log and the report) or other. Lockstep runs always
    /// SCHED_OTHER: its loop never sleeps.
    #[arg(long, value_enum, default_value_t = crate::sched::Policy::Fifo)]
    pub sched: crate::sched::Policy,
    /// What the node's CPU does while a realtime node under SCHED_FIFO sleeps: halt
    /// (the kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so
    /// a halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: README "What the CPUs do while the nodes
    /// sleep").
    #[arg(long, value_enum, default_value_t = crate::sched::IdleMode::Halt)]
    pub idle: crate::sched::IdleMode,
    /// SCHED_FIFO priority, 1 to 98.
    #[arg(long, default_value_t = crate::sched::DEFAULT_PRIORITY, value_parser = clap::value_parser!(u8).range(1..=98))]
    pub priority: u8,
    /// Pin this node to one CPU.
    #[arg(long)]
    pub cpu: Option<usize>,
    /// Continue this node's record in --out instead of starting it afresh (a node
    /// restarted into a run that is still going).
    #[arg(long)]
    pub append: bool,
    /// Started by `tactile run` (process id of the launcher): stop when it dies, log
    /// to the file only.
    #[arg(long, hide = true)]
    pub supervised: Option<u32>,
}

/// Why a node stopped without completing.
#[derive(Debug)]
pub enum NodeError {
    /// Bad input; nothing was started (exit 2).
    BadInput(String),
    /// A failure while running (exit 1).
    Failed(String),
}

impl NodeError {
    /// The exit status.
    pub fn code(&self) -> u8 {
        match self {
            NodeError::BadInput(_) => EXIT_BAD_INPUT,
            NodeError::Failed(_) => EXIT_FAILURE,
        }
    }
}

impl std::fmt::Display for NodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NodeError::BadInput(m) | NodeError::Failed(m) => f.write_str(m),
        }
    }
}

/// Maps a node's outcome to its exit status and one line on stderr.
pub fn exit(role: Role, outcome: Result<bool, NodeError>) -> ExitCode {
    match outcome {
        Ok(true) => ExitCode::from(EXIT_OK),
        Ok(false) => ExitCode::from(EXIT_INTERRUPTED),
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("tactile-{role}: {e}");
            ExitCode::from(e.code())
        }
    }
}

/// Everything a node has after its start-up checks.
#[derive(Debug)]
pub struct Prepared {
    /// The scenario.
    pub scenario: Scenario,
    /// Folder its relative paths are resolved against.
    pub base_dir: PathBuf,
    /// Poll budget before blocking.
    pub spin: Duration,
    /// Realtime: how long before a sample is due the node wakes (zero in lockstep).
    pub wake_early: Duration,
    /// The scheduling in force.
    pub sched: crate::sched::Sched,
    /// The threads keeping the node's CPUs awake, while the node lives.
    pub awake: Option<crate::sched::KeepAwake>,
    /// The run's lock for this role, held while the node lives.
    pub lock: Lock,
}

/// Checks the arguments, the scenario and the prefix, creates the output folder, takes
/// the role's lock, installs the logger and pins the CPU. Nothing is started when it
/// fails: the error is bad input (exit 2).
pub fn prepare(role: Role, args: &NodeArgs) -> Result<Prepared, NodeError> {
    let bad = NodeError::BadInput;
    lock::check_prefix(&args.prefix).map_err(bad)?;
    let (scenario, base_dir) = crate::files::load_scenario(&args.scenario).map_err(bad)?;
    check_link_args(args, &[args.link])?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| bad(format!("creating {}: {e}", args.out.display())))?;
    for file in [
        record_path(&args.out, role),
        args.out.join(format!("{role}.log")),
    ] {
        if crate::files::same_file(&file, &args.scenario) {
            return Err(bad(format!(
                "--out {}: writing {} would overwrite the scenario; choose another folder",
                args.out.display(),
                file.display()
            )));
        }
    }
    let holder = format!(
        "the {role} of pid {} (writing to {})",
        std::process::id(),
        args.out.display()
    );
    let lock = lock::take(&args.prefix, role.name(), &holder).map_err(bad)?;
    crate::logging::init(&args.out, role, args.supervised.is_none()).map_err(bad)?;
    if let Some(parent) = args.supervised {
        supervise(parent)?;
    }
    if let Some(cpu) = args.cpu {
        pin(cpu).map_err(bad)?;
    }
    let (wake_early, spin) = waiting(&scenario, args.wake_early_us, args.spin_us);
    check_waiting(args, &scenario, wake_early, spin)?;
    let (sched, awake) = schedule(args, &scenario, wake_early, spin);
    Ok(Prepared {
        scenario,
        base_dir,
        spin,
        wake_early,
        sched,
        awake,
        lock,
    })
}

/// The wake-up margin and the poll budget: as given, or the measured defaults
/// (README "Waiting"). Lockstep never sleeps: it polls two sampling periods, then
/// blocks.
pub fn waiting(
    scenario: &Scenario,
    wake_early_us: Option<u64>,
    spin_us: Option<u64>,
) -> (Duration, Duration) {
    let t_s = scenario.t_s_ns();
    if scenario.mode != tactile_scenario::Mode::Realtime {
        let spin = spin_us.map_or(Duration::from_nanos(2 * t_s), Duration::from_micros);
        return (Duration::ZERO, spin);
    }
    let early = wake_early_us.map_or_else(
        || Duration::from_nanos(crate::pace::default_wake_early_ns(t_s)),
        Duration::from_micros,
    );
    let spin = spin_us.map_or(2 * early, Duration::from_micros);
    (early, spin)
}

/// A realtime node must sleep in every period: a wake-up margin of a whole period
/// never sleeps, and under SCHED_FIFO neither does a poll budget of one (the kernel's
/// real-time throttle then stops the node for tens of milliseconds).
fn check_waiting(
    args: &NodeArgs,
    scenario: &Scenario,
    wake_early: Duration,
    spin: Duration,
) -> Result<(), NodeError> {
    if scenario.mode != tactile_scenario::Mode::Realtime {
        return Ok(());
    }
    let t_s = Duration::from_nanos(scenario.t_s_ns());
    let period = format!("the sampling period ({} us)", t_s.as_micros());
    if wake_early >= t_s {
        return Err(NodeError::BadInput(format!(
            "--wake-early-us {}: must be under {period}",
            wake_early.as_micros()
        )));
    }
    if spin >= t_s && args.sched == crate::sched::Policy::Fifo {
        return Err(NodeError::BadInput(format!(
            "--spin-us {}: under SCHED_FIFO the poll budget must be under {period} (or use --sched other)",
            spin.as_micros()
        )));
    }
    Ok(())
}

/// Applies the scheduling the arguments ask for (SCHED_FIFO only for a realtime
/// run, the CPUs kept awake only under SCHED_FIFO) and says in the log what the kernel
/// refused.
fn schedule(
    args: &NodeArgs,
    scenario: &Scenario,
    wake_early: Duration,
    spin: Duration,
) -> (crate::sched::Sched, Option<crate::sched::KeepAwake>) {
    use crate::sched::{apply, IdleMode, KeepAwake, Policy, Sched};
    let realtime = scenario.mode == tactile_scenario::Mode::Realtime;
    let policy = if realtime { args.sched } else { Policy::Other };
    let (fifo, memory_locked, mut notes) = apply(policy, args.priority);
    if !realtime && args.sched == Policy::Fifo {
        tracing::info!("lockstep: SCHED_OTHER (its loop never sleeps)");
    }
    if args.idle == IdleMode::Poll && !fifo {
        tracing::info!("--idle poll applies under SCHED_FIFO only: CPUs not kept awake");
    }
    let awake = match fifo && args.idle == IdleMode::Poll {
        false => None,
        true => KeepAwake::start()
            .map_err(|e| notes.push(format!("CPUs not kept awake ({e})")))
            .ok(),
    };
    for n in &notes {
        tracing::warn!("{n}");
    }
    let sched = Sched {
        policy: if fifo { "SCHED_FIFO" } else { "SCHED_OTHER" }.into(),
        priority: if fifo { args.priority } else { 0 },
        cpu: args.cpu,
        wake_early_us: wake_early.as_micros() as u64,
        poll_us: spin.as_micros() as u64,
        memory_locked,
        idle_poll: awake.is_some(),
        note: (!notes.is_empty()).then(|| notes.join("; ")),
    };
    (sched, awake)
}

/// Asks the kernel to send SIGTERM when the launcher dies (even by SIGKILL), and stops
/// at once if it is already gone.
fn supervise(parent: u32) -> Result<(), NodeError> {
    use rustix::process::{getppid, set_parent_process_death_signal, Signal};
    set_parent_process_death_signal(Some(Signal::TERM))
        .map_err(|e| NodeError::Failed(format!("setting the parent-death signal: {e}")))?;
    let now = getppid().map_or(0, |p| p.as_raw_nonzero().get() as u32);
    if now != parent {
        return Err(NodeError::Failed(format!(
            "the launcher (pid {parent}) is gone; not starting"
        )));
    }
    Ok(())
}

/// Pins the calling thread (the node's only thread) to `cpu`.
pub fn pin(cpu: usize) -> Result<(), String> {
    if !crate::sched::allowed_cpus()?.contains(&cpu) {
        return Err(format!("--cpu {cpu}: not a CPU this process may use"));
    }
    crate::sched::pin_thread(cpu).map_err(|e| format!("pinning to CPU {cpu}: {e}"))
}

/// The record file of `role` in `dir`.
pub fn record_path(dir: &Path, role: Role) -> PathBuf {
    dir.join(format!("{role}.rec"))
}

/// A node's record writer with its bookkeeping: events go to the log as well, and the
/// counters are written every second, so a node killed at any moment leaves counters
/// at most a second old.
#[derive(Debug)]
pub struct Recorder<S, C> {
    writer: RecordWriter<Record<S, C>>,
    next_counters_ns: u64,
}

/// Counters are written this often, ns.
pub const COUNTERS_EVERY_NS: u64 = 1_000_000_000;

impl<S: Serialize, C: Serialize> Recorder<S, C> {
    /// Opens `ROLE.rec` in `dir` (afresh, or appended to with `append`).
    pub fn open(dir: &Path, role: Role, append: bool) -> Result<Self, NodeError> {
        let path = record_path(dir, role);
        let writer = RecordWriter::create(&path, append)
            .map_err(|e| NodeError::Failed(format!("opening {}: {e}", path.display())))?;
        Ok(Recorder {
            writer,
            next_counters_ns: now_ns() + COUNTERS_EVERY_NS,
        })
    }

    fn put(&mut self, r: &Record<S, C>) -> Result<(), NodeError> {
        self.writer.write(r).map_err(|e| {
            NodeError::Failed(format!("writing {}: {e}", self.writer.path().display()))
        })
    }

    /// The start of a segment.
    pub fn start(&mut self, start: Start) -> Result<(), NodeError> {
        tracing::info!(
            "start: {} of run {:?} ({} link, scenario {:?}, {} samples at {} Hz, {} {}, wake {} us early, poll {} us{})",
            start.role,
            start.prefix,
            start.link,
            start.scenario,
            start.samples,
            start.rate_hz,
            start.sched.policy,
            start.sched.priority,
            start.sched.wake_early_us,
            start.sched.poll_us,
            start.sched.cpu.map_or(String::new(), |c| format!(", CPU {c}"))
        );
        self.put(&Record::Start(start))
    }

    /// The run token this node joined.
    pub fn run(&mut self, token: u64) -> Result<(), NodeError> {
        tracing::info!("joined run {token:016x}");
        self.put(&Record::Run(token))
    }

    /// One sample's record.
    pub fn sample(&mut self, s: S) -> Result<(), NodeError> {
        self.put(&Record::Sample(s))
    }

    /// An event, logged and recorded.
    pub fn event(&mut self, sample: u64, what: impl Into<String>) -> Result<(), NodeError> {
        let what = what.into();
        tracing::info!("sample {sample}: {what}");
        self.put(&Record::Event(Event {
            sample,
            mono_ns: now_ns(),
            what,
        }))
    }

    /// True once a second has passed since the counters were last written (then the
    /// node writes them with [`Recorder::counters`]).
    pub fn counters_due(&mut self) -> bool {
        let now = now_ns();
        if now < self.next_counters_ns {
            return false;
        }
        self.next_counters_ns = now + COUNTERS_EVERY_NS;
        true
    }

    /// Writes the counters now.
    pub fn counters(&mut self, counters: C) -> Result<(), NodeError> {
        self.put(&Record::Counters(Totals {
            counters,
            peak_rss_kb: peak_rss_kb(),
        }))
    }

    /// The end of the segment: final counters, then `Stop`.
    pub fn stop(&mut self, counters: C, reason: &str) -> Result<(), NodeError> {
        self.counters(counters)?;
        tracing::info!("stop: {reason} (peak RSS {} kB)", peak_rss_kb());
        self.put(&Record::Stop(Stop {
            reason: reason.to_string(),
            mono_ns: now_ns(),
        }))
    }
}

/// This node's clock domain: `TACTILE_CLOCK_DOMAIN` if set, else the kernel's boot id
/// (processes under one kernel, network namespaces included, share CLOCK_MONOTONIC).
pub fn clock_domain() -> String {
    if let Ok(d) = std::env::var("TACTILE_CLOCK_DOMAIN") {
        return d;
    }
    std::fs::read_to_string("/proc/sys/kernel/random/boot_id")
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|_| {
            rustix::system::uname()
                .nodename()
                .to_string_lossy()
                .into_owned()
        })
}

/// The link in words, for the record and the log.
pub fn describe_link(a: &NodeArgs) -> String {
    let zenoh_used = !a.listen.is_empty() || !a.connect.is_empty();
    match a.link {
        LinkKind::Iceoryx2 if zenoh_used => format!(
            "iceoryx2 and zenoh (listen {:?}, connect {:?})",
            a.listen, a.connect
        ),
        LinkKind::Iceoryx2 => "iceoryx2".into(),
        LinkKind::Udp => format!("udp ports {} on {}", a.udp_ports, a.udp_hosts),
        LinkKind::Zenoh => format!(
            "zenoh (listen {:?}, connect {:?}{})",
            a.listen,
            a.connect,
            if a.scout { ", scouting" } else { "" }
        ),
    }
}

/// The `Start` of a node's record from its arguments.
pub fn start_record(role: Role, args: &NodeArgs, p: &Prepared) -> Start {
    let unix_ms = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64);
    Start {
        role: role.name().to_string(),
        version: env!("CARGO_PKG_VERSION").to_string(),
        pid: std::process::id(),
        host: rustix::system::uname()
            .nodename()
            .to_string_lossy()
            .into_owned(),
        clock: clock_domain(),
        prefix: args.prefix.clone(),
        link: describe_link(args),
        scenario: p.scenario.name.clone(),
        scenario_toml: p.scenario.resolved(&p.base_dir).to_toml(),
        samples: p.scenario.samples,
        rate_hz: p.scenario.rate_hz,
        sched: p.sched.clone(),
        unix_ms,
        mono_ns: now_ns(),
    }
}

/// Parses a node's command line; on an error prints clap's message and returns the
/// exit status (2 for bad arguments, 0 for --help and --version).
pub fn parse<T: clap::Parser>() -> Result<T, ExitCode> {
    // First thing, while the node has one thread.
    #[cfg(feature = "zenoh")]
    crate::zlink::default_runtime();
    T::try_parse().map_err(|e| {
        let _ = e.print();
        ExitCode::from(if e.use_stderr() {
            EXIT_BAD_INPUT
        } else {
            EXIT_OK
        })
    })
}

/// A fresh run token: random, never zero (zero means "unknown").
pub fn new_run_token() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(now_ns());
    h.write_u32(std::process::id());
    h.finish().max(1)
}

fn udp_ports(a: &NodeArgs) -> Result<crate::udp::UdpPorts, NodeError> {
    let ports = crate::udp::UdpPorts::parse(&a.udp_ports).ok_or_else(|| {
        NodeError::BadInput(format!(
            "--udp-ports {:?}: expected three ports m,e,s",
            a.udp_ports
        ))
    })?;
    ports.on_hosts(&a.udp_hosts).ok_or_else(|| {
        NodeError::BadInput(format!(
            "--udp-hosts {:?}: expected three IP addresses a,b,c",
            a.udp_hosts
        ))
    })
}

/// What a build without the `zenoh` feature answers to `--link zenoh`.
pub const NO_ZENOH: &str = "--link zenoh: this build has no Zenoh link; build with \
`cargo build --release --workspace --features zenoh` (README, Across hosts)";

/// The Zenoh endpoints of the arguments.
#[cfg(feature = "zenoh")]
pub fn zenoh_options(a: &NodeArgs) -> crate::zlink::ZenohOptions {
    crate::zlink::ZenohOptions {
        listen: a.listen.clone(),
        connect: a.connect.clone(),
        scout: a.scout,
    }
}

/// Checks the options of the links in use, before anything starts.
pub fn check_link_args(a: &NodeArgs, links: &[LinkKind]) -> Result<(), NodeError> {
    if links.contains(&LinkKind::Udp) {
        udp_ports(a)?;
    }
    if links.contains(&LinkKind::Zenoh) {
        if !cfg!(feature = "zenoh") {
            return Err(NodeError::BadInput(NO_ZENOH.into()));
        }
        if a.listen.is_empty() && a.connect.is_empty() && !a.scout {
            return Err(NodeError::BadInput(
                "--link zenoh: give --listen ENDPOINT and/or --connect ENDPOINT (or --scout) so the nodes can meet".into(),
            ));
        }
        for e in a.listen.iter().chain(&a.connect) {
            let ok = e.split_once('/').is_some_and(|(proto, addr)| {
                matches!(proto, "tcp" | "udp") && addr.parse::<std::net::SocketAddr>().is_ok()
            });
            if !ok {
                return Err(NodeError::BadInput(format!(
                    "Zenoh endpoint {e:?}: expected tcp/ADDRESS:PORT or udp/ADDRESS:PORT"
                )));
            }
        }
        #[cfg(feature = "zenoh")]
        zenoh_options(a)
            .config()
            .map_err(|e| NodeError::BadInput(e.to_string()))?;
    }
    Ok(())
}

fn opened<T>(r: Result<T, crate::link::LinkError>) -> Result<T, NodeError> {
    r.map_err(|e| NodeError::Failed(e.to_string()))
}

/// The master's link as the arguments choose it; `direct`: no emulator, the slave
/// is the master's peer (Zenoh only).
pub fn master_link(
    a: &NodeArgs,
    spin: Duration,
    direct: bool,
) -> Result<Box<dyn crate::link::MasterLink>, NodeError> {
    let wait = crate::link::WaitPolicy { spin };
    if direct && a.link != LinkKind::Zenoh {
        return Err(NodeError::BadInput(
            "--direct (no emulator) needs --link zenoh".into(),
        ));
    }
    Ok(match a.link {
        LinkKind::Iceoryx2 => Box::new(opened(crate::ipc::IoxMaster::open(&a.prefix, wait))?),
        LinkKind::Udp => Box::new(opened(crate::udp::UdpMaster::open(udp_ports(a)?, wait))?),
        LinkKind::Zenoh => zenoh_open::master(a, direct, wait)?,
    })
}

/// The emulator's link: `towards_master` and `towards_slave` chosen on their own, so
/// the emulator can sit on either host (Zenoh on one side, iceoryx2 on the other).
pub fn emulator_link(
    a: &NodeArgs,
    spin: Duration,
    towards_master: LinkKind,
    towards_slave: LinkKind,
) -> Result<Box<dyn crate::link::EmulatorLink>, NodeError> {
    use LinkKind::{Iceoryx2, Udp, Zenoh};
    let wait = crate::link::WaitPolicy { spin };
    Ok(match (towards_master, towards_slave) {
        (Iceoryx2, Iceoryx2) => Box::new(opened(crate::ipc::IoxEmulator::open(&a.prefix, wait))?),
        (Udp, Udp) => Box::new(opened(crate::udp::UdpEmulator::open(udp_ports(a)?, wait))?),
        (Zenoh, Zenoh) | (Zenoh, Iceoryx2) | (Iceoryx2, Zenoh) => zenoh_open::emulator(
            a,
            towards_master == Iceoryx2,
            towards_slave == Iceoryx2,
            wait,
        )?,
        (m, s) => {
            return Err(NodeError::BadInput(format!(
                "--master-link {} with --slave-link {}: UDP cannot be mixed with another link (Zenoh and iceoryx2 can)",
                m.name(),
                s.name()
            )))
        }
    })
}

/// The slave's link as the arguments choose it.
pub fn slave_link(
    a: &NodeArgs,
    spin: Duration,
) -> Result<Box<dyn crate::link::SlaveLink>, NodeError> {
    let wait = crate::link::WaitPolicy { spin };
    Ok(match a.link {
        LinkKind::Iceoryx2 => Box::new(opened(crate::ipc::IoxSlave::open(&a.prefix, wait))?),
        LinkKind::Udp => Box::new(opened(crate::udp::UdpSlave::open(udp_ports(a)?, wait))?),
        LinkKind::Zenoh => zenoh_open::slave(a, wait)?,
    })
}

/// Opening the Zenoh links, in a build with the `zenoh` feature.
#[cfg(feature = "zenoh")]
mod zenoh_open {
    use super::{opened, zenoh_options, NodeArgs, NodeError};
    use crate::link::WaitPolicy;
    use crate::link::{EmulatorLink, MasterLink, SlaveLink};
    use crate::zlink::{ZenohEmulator, ZenohMaster, ZenohSlave};

    pub fn master(
        a: &NodeArgs,
        direct: bool,
        wait: WaitPolicy,
    ) -> Result<Box<dyn MasterLink>, NodeError> {
        let o = zenoh_options(a);
        Ok(Box::new(opened(ZenohMaster::open(
            &o, &a.prefix, direct, wait,
        ))?))
    }

    pub fn emulator(
        a: &NodeArgs,
        master_on_iceoryx2: bool,
        slave_on_iceoryx2: bool,
        wait: WaitPolicy,
    ) -> Result<Box<dyn EmulatorLink>, NodeError> {
        let o = zenoh_options(a);
        Ok(Box::new(opened(ZenohEmulator::open(
            &o,
            &a.prefix,
            master_on_iceoryx2,
            slave_on_iceoryx2,
            wait,
        ))?))
    }

    pub fn slave(a: &NodeArgs, wait: WaitPolicy) -> Result<Box<dyn SlaveLink>, NodeError> {
        let o = zenoh_options(a);
        Ok(Box::new(opened(ZenohSlave::open(&o, &a.prefix, wait))?))
    }
}

/// In a build without the `zenoh` feature every Zenoh link is a configuration error
/// that says how to build with it.
#[cfg(not(feature = "zenoh"))]
mod zenoh_open {
    use super::{NodeArgs, NodeError, NO_ZENOH};
    use crate::link::WaitPolicy;
    use crate::link::{EmulatorLink, MasterLink, SlaveLink};

    pub fn master(_: &NodeArgs, _: bool, _: WaitPolicy) -> Result<Box<dyn MasterLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }

    pub fn emulator(
        _: &NodeArgs,
        _: bool,
        _: bool,
        _: WaitPolicy,
    ) -> Result<Box<dyn EmulatorLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }

    pub fn slave(_: &NodeArgs, _: WaitPolicy) -> Result<Box<dyn SlaveLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        node: NodeArgs,
    }

    fn args(extra: &[&str]) -> NodeArgs {
        let mut v = vec!["node", "--scenario", "s.toml", "--out", "o"];
        v.extend_from_slice(extra);
        Cli::parse_from(v).node
    }

    #[test]
    fn the_zenoh_link_is_checked_or_refused_by_the_build() {
        let a = args(&["--link", "zenoh", "--connect", "tcp/127.0.0.1:7447"]);
        let r = check_link_args(&a, &[LinkKind::Zenoh]);
        if cfg!(feature = "zenoh") {
            assert!(r.is_ok(), "{:?}", r.err());
        } else {
            let e = r.expect_err("no Zenoh in this build").to_string();
            assert!(e.contains("--workspace --features zenoh"), "{e}");
        }
    }

    #[test]
    fn a_realtime_node_must_sleep_in_every_period() {
        let mut sc = Scenario::from_toml_str(
            "name = \"t\"\nmode = \"realtime\"\nrate_hz = 1000.0\nsamples = 10\n\n[operator]\nkind = \"paper\"\n",
        )
        .expect("scenario");
        let check = |a: &NodeArgs, sc: &Scenario| {
            let (early, spin) = waiting(sc, a.wake_early_us, a.spin_us);
            check_waiting(a, sc, early, spin).map(|()| (early, spin))
        };
        let ok = check(&args(&[]), &sc).expect("defaults");
        assert_eq!(ok, (Duration::from_micros(200), Duration::from_micros(400)));
        let e = check(&args(&["--wake-early-us", "1000"]), &sc).expect_err("a period");
        assert!(
            e.to_string()
                .contains("under the sampling period (1000 us)"),
            "{e}"
        );
        assert!(check(&args(&["--spin-us", "1500"]), &sc).is_err());
        assert!(check(&args(&["--spin-us", "1500", "--sched", "other"]), &sc).is_ok());
        // Lockstep never sleeps: nothing to check, and no margin.
        sc.mode = tactile_scenario::Mode::Lockstep;
        let l = check(&args(&["--wake-early-us", "5000"]), &sc).expect("lockstep");
        assert_eq!(l.0, Duration::ZERO);
    }
}
