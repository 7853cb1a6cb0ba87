//! `tactile run`: starts the three node programs for a scenario, watches them, and
//! writes the report from their records.

use crate::cli::RunArgs;
use crate::error::Error;
use crate::nodes;
use crate::report_cmd::{write_report, Launch, REPORT_FILES};
use crate::summary::{render, Summary};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_master::operator::OperatorSource;
use tactile_node::files::{self, same_file};
use tactile_node::runtime::{LinkKind, EXIT_BAD_INPUT, EXIT_INTERRUPTED};
use tactile_scenario::overrides::Set;
use tactile_scenario::{Mode, Operator, Scenario};

/// The paper scenario, built into the executable so `tactile run` works from any folder.
pub const PAPER_SCENARIO: &str = include_str!("../scenarios/paper.toml");

/// A scenario ready to run: validated, its trajectory checked, and where it came from.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The scenario.
    pub scenario: Scenario,
    /// Folder its relative paths are resolved against.
    pub base_dir: PathBuf,
    /// The files it was read from (the scenario, a trajectory), which a run must never
    /// overwrite.
    pub inputs: Vec<PathBuf>,
}

/// Reads and validates a scenario; `None` is the built-in paper scenario. A trajectory
/// file is read too, so a bad one stops the run before anything starts.
pub fn load_scenario(path: Option<&Path>, sets: &[Set]) -> Result<Loaded, Error> {
    let (text, base_dir, name) = match path {
        None => (
            PAPER_SCENARIO.to_string(),
            std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
            "deploy/scenarios/paper.toml (built in)".to_string(),
        ),
        Some(p) => (
            files::read_text(p, "scenario", files::MAX_SCENARIO_BYTES).map_err(Error::BadInput)?,
            files::base_dir(p),
            p.display().to_string(),
        ),
    };
    let text = tactile_scenario::overrides::apply(&text, sets)
        .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
    let with = if sets.is_empty() {
        String::new()
    } else {
        let s: Vec<&str> = sets.iter().map(|s| s.text.as_str()).collect();
        format!(" with --set {}", s.join(" --set "))
    };
    let scenario = Scenario::from_toml_str(&text).map_err(|e| {
        let msg = e.to_string();
        // A line and column would point into the changed text, not the user's file.
        let msg = match msg.strip_prefix("line ").and_then(|r| r.split_once(": ")) {
            Some((_, rest)) if !sets.is_empty() => rest.to_string(),
            _ => msg,
        };
        Error::BadInput(format!("{name}{with}: {}", msg.trim_end()))
    })?;
    OperatorSource::load(&scenario.operator, &base_dir)
        .map_err(|e| Error::BadInput(format!("{name}: operator: {e}")))?;
    tactile_network_emulator::replay::load(&scenario, &base_dir)
        .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
    let mut inputs: Vec<PathBuf> = path.map(Path::to_path_buf).into_iter().collect();
    for c in [&scenario.network.forward, &scenario.network.backward] {
        if let Some(r) = &c.replay {
            inputs.push(base_dir.join(&r.path));
        }
    }
    if let Operator::Csv { path } = &scenario.operator {
        inputs.push(base_dir.join(path));
    }
    Ok(Loaded {
        scenario,
        base_dir,
        inputs,
    })
}

/// How `tactile sweep --processes` runs each combination: as `tactile run` does by
/// default, no restarts, no progress line.
pub fn sweep_supervision(no_trace: bool) -> Supervision {
    Supervision {
        prefix: format!("tactile{}s", std::process::id()),
        spin: None,
        wake_early: None,
        progress: false,
        max_restarts: 0,
        link: Links {
            kind: LinkKind::Iceoryx2,
            args: Default::default(),
        },
        wrap: Default::default(),
        pin: true,
        sched: tactile_node::sched::Policy::Fifo,
        idle: tactile_node::sched::IdleMode::Halt,
        no_trace,
    }
}

/// The `--set KEY=VALUE` arguments, parsed (bad input when one is malformed).
pub fn parse_sets(args: &[String]) -> Result<Vec<Set>, Error> {
    args.iter()
        .map(|a| Set::parse(a).map_err(Error::BadInput))
        .collect()
}

/// Every file a run writes into its output folder.
pub fn output_files(out: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = REPORT_FILES.iter().map(|f| out.join(f)).collect();
    for role in crate::join::ROLES {
        v.push(out.join(format!("{role}.rec")));
        v.push(out.join(format!("{role}.log")));
    }
    v
}

/// Makes `out` ready for a new run: refuses if a file the run would write is one of
/// its inputs, then removes the files of an earlier run, so the folder never mixes
/// two runs' files.
pub fn prepare_out(out: &Path, inputs: &[PathBuf]) -> Result<(), Error> {
    std::fs::create_dir_all(out).map_err(Error::io(format!("creating {}", out.display())))?;
    let outputs = output_files(out);
    for i in inputs {
        if let Some(o) = outputs.iter().find(|o| same_file(o, i)) {
            return Err(Error::BadInput(format!(
                "--out {}: the run would overwrite its input {} (as {}); choose another output folder",
                out.display(),
                i.display(),
                o.display()
            )));
        }
    }
    for o in outputs {
        match std::fs::remove_file(&o) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(format!("removing {}", o.display()))(e)),
        }
    }
    Ok(())
}

/// How a child process ended, in words.
pub fn describe(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(c), _) => format!("exited with status {c}"),
        (None, Some(s)) => format!("was killed by signal {s}"),
        _ => "ended".to_string(),
    }
}

struct Proc {
    role: &'static str,
    child: Child,
    status: Option<ExitStatus>,
    restarts: u32,
    /// Set while a dead process waits out the restart backoff.
    restart_at: Option<Instant>,
}

/// Wait before restarting a dead process: a process that dies at once again must not
/// spin the launcher, and the peers see a clear break (longer than the peer timeout
/// of 10 samples at 100 Hz) rather than a flicker.
pub const RESTART_BACKOFF: Duration = Duration::from_millis(200);

fn signal(child: &Child, sig: rustix::process::Signal) {
    if let Some(pid) = rustix::process::Pid::from_raw(child.id() as i32) {
        let _ = rustix::process::kill_process(pid, sig);
    }
}

fn stop(p: &mut Proc, grace: Duration) {
    if p.status.is_some() {
        return;
    }
    signal(&p.child, rustix::process::Signal::TERM);
    let until = Instant::now() + grace;
    while Instant::now() < until {
        if let Ok(Some(s)) = p.child.try_wait() {
            p.status = Some(s);
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = p.child.kill();
    p.status = p.child.wait().ok();
}

/// The last lines of a node's log, bounded: the log of a long run can be large.
fn log_tail(out: &Path, role: &str) -> String {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::File::open(out.join(format!("{role}.log"))) else {
        return String::new();
    };
    let len = f.metadata().map_or(0, |m| m.len());
    let _ = f.seek(SeekFrom::Start(len.saturating_sub(4096)));
    let mut text = String::new();
    let _ = f.take(4096).read_to_string(&mut text);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(5)..].join("\n")
}

/// How `tactile run` supervises its processes.
#[derive(Debug, Clone)]
pub struct Supervision {
    /// iceoryx2 prefix of the run.
    pub prefix: String,
    /// Poll budget of every process (None: each node's default, README "Waiting").
    pub spin: Option<Duration>,
    /// How long before a sample is due each node wakes (None: each node's default).
    pub wake_early: Option<Duration>,
    /// Progress line on a terminal.
    pub progress: bool,
    /// Restarts allowed per process (emulator, slave) when one dies mid-run.
    pub max_restarts: u32,
    /// What carries the samples, and the link options of each node.
    pub link: Links,
    /// Command prefix of the master, the emulator and the slave (e.g. `ip netns exec
    /// A` to put a node on another host); empty: run the program directly.
    pub wrap: [Vec<String>; 3],
    /// Pin master to CPU 0, emulator and slave to CPU 1.
    pub pin: bool,
    /// Scheduling of the three processes, which each node sets on itself.
    pub sched: tactile_node::sched::Policy,
    /// What each node's CPU does while the node sleeps (realtime, SCHED_FIFO).
    pub idle: tactile_node::sched::IdleMode,
    /// Write no trace.csv.
    pub no_trace: bool,
}

/// The link of a run on one host, with the options each node needs for it.
#[derive(Debug, Clone)]
pub struct Links {
    /// The link.
    pub kind: LinkKind,
    /// Options of the master, the emulator and the slave.
    pub args: [Vec<String>; 3],
}

impl Links {
    /// Every node on `kind`, on this host: UDP on three free ports; Zenoh with the
    /// emulator listening on a free loopback TCP port and the others connecting to it.
    pub fn on_this_host(kind: LinkKind) -> Result<Links, Error> {
        if kind == LinkKind::Zenoh && !cfg!(feature = "zenoh") {
            return Err(Error::BadInput(tactile_node::runtime::NO_ZENOH.into()));
        }
        let failed = |e: std::io::Error| Error::Failed(format!("picking a free port: {e}"));
        let args = match kind {
            LinkKind::Iceoryx2 => Default::default(),
            LinkKind::Udp => {
                let p = tactile_node::udp::UdpPorts::free()
                    .map_err(|e| Error::Failed(e.to_string()))?
                    .arg();
                let a = vec!["--udp-ports".to_string(), p];
                [a.clone(), a.clone(), a]
            }
            LinkKind::Zenoh => {
                let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(failed)?;
                let port = l.local_addr().map_err(failed)?.port();
                let at = format!("tcp/127.0.0.1:{port}");
                let connect = vec!["--connect".to_string(), at.clone()];
                [connect.clone(), vec!["--listen".to_string(), at], connect]
            }
        };
        Ok(Links { kind, args })
    }

    /// The link options of `role`.
    pub fn args(&self, role: &str) -> &[String] {
        &self.args[role_index(role)]
    }

    /// Master on host 0 of `hosts`, emulator and slave on host 1, every hop on
    /// `kind` (Zenoh or UDP) across the veth pair.
    pub fn across(kind: LinkKind, hosts: &crate::netns::Pair) -> Links {
        let [a, b] = &hosts.addrs;
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let args = match kind {
            LinkKind::Zenoh => {
                let (la, lb) = (format!("tcp/{a}:7447"), format!("tcp/{b}:7448"));
                [
                    s(&["--listen", &la]),
                    s(&["--connect", &la, "--listen", &lb]),
                    s(&["--connect", &lb]),
                ]
            }
            _ => {
                let u = s(&[
                    "--udp-ports",
                    "47501,47502,47503",
                    "--udp-hosts",
                    &format!("{a},{b},{b}"),
                ]);
                [u.clone(), u.clone(), u]
            }
        };
        Links { kind, args }
    }
}

/// 0 for the master, 1 the emulator, 2 the slave.
fn role_index(role: &str) -> usize {
    match role {
        "master" => 0,
        "emulator" => 1,
        _ => 2,
    }
}

/// The command line of one node.
fn node_command(
    sup: &Supervision,
    exe: &Path,
    role: &str,
    scenario_file: &Path,
    out: &Path,
    append: bool,
) -> Command {
    let mut argv: Vec<String> = sup.wrap[role_index(role)].clone();
    argv.push(exe.display().to_string());
    let mut cmd = Command::new(&argv[0]);
    cmd.args(&argv[1..]);
    cmd.arg("--scenario")
        .arg(scenario_file)
        .arg("--out")
        .arg(out)
        .args(["--prefix", &sup.prefix])
        .args(["--sched", sup.sched.name()])
        .args(["--idle", sup.idle.name()])
        .args(["--supervised", &std::process::id().to_string()]);
    if let Some(spin) = sup.spin {
        cmd.args(["--spin-us", &spin.as_micros().to_string()]);
    }
    if let Some(early) = sup.wake_early {
        cmd.args(["--wake-early-us", &early.as_micros().to_string()]);
    }
    cmd.args(["--link", sup.link.kind.name()]);
    cmd.args(sup.link.args(role));
    if sup.pin {
        cmd.args(["--cpu", if role == "master" { "0" } else { "1" }]);
    }
    if role == "master" {
        cmd.args(["--startup-timeout-s", "10"]);
    }
    if append {
        cmd.arg("--append");
    }
    cmd
}

/// True if this machine lets the process use CPUs 0 and 1.
pub fn two_cpus() -> bool {
    rustix::thread::sched_getaffinity(None).is_ok_and(|s| s.is_set(0) && s.is_set(1))
}

/// Removes the shared memory of earlier runs whose launcher is gone (a crashed or
/// killed run leaves it behind; iceoryx2 would clean it only for the same prefix).
pub fn clean_stale_runs() {
    let Ok(dir) = std::fs::read_dir(tactile_node::ipc::ROOT) else {
        return;
    };
    for entry in dir.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let Some(pid) = name
            .strip_prefix("tactile")
            .and_then(|p| p.parse::<i32>().ok())
        else {
            continue;
        };
        if !Path::new(&format!("/proc/{pid}")).exists() {
            tactile_node::ipc::remove_run_files(&name);
        }
    }
}

/// What the supervision loop saw.
struct Watch {
    events: Vec<String>,
    failed: bool,
    interrupted: bool,
    master_ok: bool,
    /// A node refused its configuration (exit 2): its message.
    config_error: Option<String>,
}

/// Starts the nodes and watches them until the master ends; restarts the emulator or
/// the slave when one dies, as `sup` allows.
fn supervise(
    sup: &Supervision,
    scenario: &Scenario,
    spawn: &dyn Fn(&'static str, bool) -> Result<Child, Error>,
    out: &Path,
    notes: Vec<String>,
) -> Result<(Vec<Proc>, Watch), Error> {
    // SIGINT and SIGTERM stop the run cleanly: the master is asked to stop, the
    // others follow its end-of-run sample, and the report of what ran is written.
    let stop_requested = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop_requested))
            .map_err(Error::io("installing signal handlers"))?;
    }
    let mut procs: Vec<Proc> = Vec::new();
    for role in ["emulator", "slave", "master"] {
        match spawn(role, false) {
            Ok(child) => procs.push(Proc {
                role,
                child,
                status: None,
                restarts: 0,
                restart_at: None,
            }),
            Err(e) => {
                for p in &mut procs {
                    stop(p, Duration::from_secs(1));
                }
                return Err(e);
            }
        }
    }
    let started = Instant::now();
    let expected = match scenario.mode {
        Mode::Realtime => Some(scenario.samples as f64 * scenario.t_s()),
        Mode::Lockstep => None,
    };
    let mut w = Watch {
        events: notes,
        failed: false,
        interrupted: false,
        master_ok: false,
        config_error: None,
    };
    let mut master_status = None;
    while master_status.is_none() {
        if stop_requested.swap(false, Ordering::SeqCst) && !w.interrupted {
            w.interrupted = true;
            w.events.push(format!(
                "stop requested after {:.2} s: stopping the master",
                started.elapsed().as_secs_f64()
            ));
            if let Some(m) = procs.iter().find(|p| p.role == "master") {
                signal(&m.child, rustix::process::Signal::TERM);
            }
        }
        let mut stop_master = false;
        for p in procs.iter_mut() {
            if let Some(at) = p.restart_at {
                if Instant::now() >= at {
                    p.restart_at = None;
                    p.child = spawn(p.role, true)?;
                    w.events.push(format!(
                        "{} restarted after {:.2} s",
                        p.role,
                        started.elapsed().as_secs_f64()
                    ));
                }
                continue;
            }
            if p.status.is_some() {
                continue;
            }
            let Ok(Some(status)) = p.child.try_wait() else {
                continue;
            };
            if status.code() == Some(i32::from(EXIT_BAD_INPUT)) {
                // A configuration error: restarting would fail the same way.
                p.status = Some(status);
                w.config_error = Some(format!("{}: {}", p.role, log_tail(out, p.role)));
                stop_master = p.role != "master";
                if p.role == "master" {
                    master_status = Some(status);
                }
                continue;
            }
            if p.role == "master" {
                master_status = Some(status);
                continue;
            }
            if status.success() {
                // Passed on the master's end-of-run sample: finished, not dead.
                p.status = Some(status);
                continue;
            }
            // The emulator or the slave died while the master runs.
            w.failed = true;
            let at = started.elapsed().as_secs_f64();
            let how = describe(status);
            if p.restarts < sup.max_restarts {
                p.restarts += 1;
                p.restart_at = Some(Instant::now() + RESTART_BACKOFF);
                w.events
                    .push(format!("{} {how} after {at:.2} s; restarting", p.role));
            } else {
                p.status = Some(status);
                w.events.push(format!(
                    "{} {how} after {at:.2} s; no restarts left, stopping the run; its last words:\n{}",
                    p.role,
                    log_tail(out, p.role)
                ));
                stop_master = true;
            }
        }
        if stop_master {
            if let Some(m) = procs.iter_mut().find(|m| m.role == "master") {
                stop(m, Duration::from_secs(2));
                master_status = m.status;
            }
        }
        if sup.progress && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            let el = started.elapsed().as_secs_f64();
            match expected {
                Some(total) => eprint!("\r  running: {el:5.1} s of {total:.1} s"),
                None => eprint!("\r  running (lockstep): {el:5.1} s"),
            }
            let _ = std::io::stderr().flush();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    if sup.progress && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!();
    }
    w.master_ok = master_status.is_some_and(|s| s.success());
    if let Some(s) = master_status.filter(|s| !s.success() && w.config_error.is_none()) {
        let interrupted = s.code() == Some(i32::from(EXIT_INTERRUPTED)) && w.interrupted;
        if !interrupted {
            w.failed = true;
            w.events.push(format!(
                "master {} after {:.2} s; its last words:\n{}",
                describe(s),
                started.elapsed().as_secs_f64(),
                log_tail(out, "master")
            ));
            // Let the survivors notice (the slave holds its position), then stop them.
            std::thread::sleep(survivor_grace(scenario));
        }
    }
    Ok((procs, w))
}

/// Runs the scenario's three node programs; returns the summary (which says whether
/// the run failed: a process died, or a stop request cut it short).
pub fn run_processes(loaded: &Loaded, out: &Path, sup: &Supervision) -> Result<Summary, Error> {
    let dir = nodes::node_dir()?;
    tactile_node::lock::check_prefix(&sup.prefix).map_err(Error::BadInput)?;
    prepare_out(out, &loaded.inputs)?;
    let holder = format!(
        "tactile run (pid {}, writing to {})",
        std::process::id(),
        out.display()
    );
    let _lock = tactile_node::lock::take(&sup.prefix, "run", &holder).map_err(Error::BadInput)?;
    // The nodes run the scenario as written here, relative paths made absolute, so
    // the copy also runs again as it is from any folder.
    let scenario_file = out.join("scenario.toml");
    let text = loaded.scenario.resolved(&loaded.base_dir).to_toml();
    std::fs::write(&scenario_file, text)
        .map_err(Error::io(format!("writing {}", scenario_file.display())))?;
    let mut notes = Vec::new();
    let pin = sup.pin && two_cpus();
    if sup.pin && !pin {
        notes.push("fewer than two CPUs: processes not pinned".to_string());
    }
    let sup = Supervision { pin, ..sup.clone() };
    let spawn = |role: &'static str, append: bool| -> Result<Child, Error> {
        let log = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(out.join(format!("{role}.log")))
            .map_err(Error::io(format!("creating {role}.log")))?;
        let exe = nodes::exe(&dir, role);
        node_command(&sup, &exe, role, &scenario_file, out, append)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .map_err(|e| Error::Failed(format!("cannot start {}: {e}", exe.display())))
    };
    let (mut procs, w) = supervise(&sup, &loaded.scenario, &spawn, out, notes)?;
    // After a clean master the end-of-run sample stops the others; give them a moment.
    let until = Instant::now() + Duration::from_secs(if w.master_ok { 3 } else { 0 });
    while Instant::now() < until
        && procs
            .iter_mut()
            .any(|p| p.status.is_none() && !matches!(p.child.try_wait(), Ok(Some(_))))
    {
        std::thread::sleep(Duration::from_millis(10));
    }
    for p in &mut procs {
        if p.status.is_none() {
            if let Ok(Some(s)) = p.child.try_wait() {
                p.status = Some(s);
            }
        }
        stop(p, Duration::from_secs(2));
    }
    tactile_node::ipc::remove_run_files(&sup.prefix);
    if let Some(msg) = w.config_error {
        return Err(Error::BadInput(msg));
    }
    if !out.join("master.rec").exists() {
        return Err(Error::Failed(format!(
            "the run failed, no record from the master:\n{}",
            w.events.join("\n")
        )));
    }
    let launch = Launch {
        events: w.events,
        failed: w.failed,
        interrupted: w.interrupted,
        no_trace: sup.no_trace,
    };
    write_report(&[out.to_path_buf()], out, &launch)
}

/// How long the launcher lets the emulator and slave run on after the master died:
/// long enough for the slave to notice and hold (its peer timeout) and to be seen.
pub fn survivor_grace(scenario: &Scenario) -> Duration {
    tactile_slave::process::hold_timeout(scenario) + Duration::from_millis(500)
}

/// `tactile run`.
pub fn main(args: &RunArgs) -> Result<(), Error> {
    let sets = parse_sets(&args.set)?;
    let loaded = load_scenario(args.scenario.as_deref(), &sets)?;
    for w in loaded.scenario.warnings() {
        eprintln!("tactile: warning: {w}");
    }
    let summary = if args.in_process {
        prepare_out(&args.out, &loaded.inputs)?;
        crate::sim::simulate(&loaded.scenario, &loaded.base_dir, &args.out)?;
        let launch = Launch {
            no_trace: args.no_trace,
            ..Launch::default()
        };
        write_report(std::slice::from_ref(&args.out), &args.out, &launch)?
    } else {
        clean_stale_runs();
        let sup = Supervision {
            prefix: args
                .prefix
                .clone()
                .unwrap_or_else(|| format!("tactile{}", std::process::id())),
            spin: args.spin_us.map(Duration::from_micros),
            wake_early: args.wake_early_us.map(Duration::from_micros),
            progress: !args.quiet,
            max_restarts: args.max_restarts,
            link: Links::on_this_host(if args.udp { LinkKind::Udp } else { args.link })?,
            pin: !args.no_pin,
            sched: args.sched,
            idle: args.idle,
            no_trace: args.no_trace,
            wrap: Default::default(),
        };
        run_processes(&loaded, &args.out, &sup)?
    };
    print!("{}", render(&summary, &args.out));
    if summary.interrupted {
        return Err(Error::Interrupted);
    }
    if summary.failed {
        return Err(Error::Failed(format!(
            "the run failed: {}",
            summary
                .events
                .first()
                .map_or("", |e| e.lines().next().unwrap_or(""))
        )));
    }
    Ok(())
}
