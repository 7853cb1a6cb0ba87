//! `tactile run`: starts the three processes for a scenario, watches them, and merges
//! their results into one report.

use crate::cli::RunArgs;
use crate::error::Error;
use crate::report::{us_header, us_line, Percentiles};
use crate::roles::{write_json, MasterSummary};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use tactile_common::scenario::{Mode, Scenario};
use tactile_master::operator::OperatorSource;
use tactile_network_emulator::process::EmulatorRun;
use tactile_slave::process::SlaveRun;

/// The paper scenario, built into the executable so `tactile run` works from any folder.
pub const PAPER_SCENARIO: &str = include_str!("../scenarios/paper.toml");

/// Reads and validates a scenario; `None` is the built-in paper scenario. Returns the
/// scenario and the folder its relative paths are resolved against.
pub fn load_scenario(path: Option<&Path>) -> Result<(Scenario, PathBuf), Error> {
    let (text, name, base) = match path {
        None => (
            PAPER_SCENARIO.to_string(),
            "deploy/scenarios/paper.toml (built in)".to_string(),
            std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
        ),
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| {
                Error::BadInput(format!("cannot read scenario {}: {e}", p.display()))
            })?;
            let base = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
            (text, p.display().to_string(), base)
        }
    };
    let scenario = Scenario::from_toml_str(&text)
        .map_err(|e| Error::BadInput(format!("{name}: {}", e.to_string().trim_end())))?;
    // A trajectory file is read now, so a bad one stops the run before anything starts.
    OperatorSource::load(&scenario.operator, &base)
        .map_err(|e| Error::BadInput(format!("{name}: operator: {e}")))?;
    Ok((scenario, base))
}

/// Sent, received and lost on one stream.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ChannelCount {
    /// Published by the sender.
    pub sent: u64,
    /// Taken by the receiver.
    pub received: u64,
    /// sent - received.
    pub lost: u64,
}

impl ChannelCount {
    fn new(sent: u64, received: u64) -> Self {
        ChannelCount {
            sent,
            received,
            lost: sent.saturating_sub(received),
        }
    }
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// `realtime` or `lockstep`.
    pub mode: Mode,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Kernel arithmetic.
    pub arithmetic: String,
    /// `processes` or `in-process`.
    pub runner: &'static str,
    /// Round trip on the master's clock, ns.
    pub round_trip_ns: Percentiles,
    /// Round trip minus the injected delay, ns.
    pub overhead_ns: Percentiles,
    /// Per-stage times, ns.
    pub stages_ns: BTreeMap<String, Percentiles>,
    /// Forward samples the master sent.
    pub samples_sent: u64,
    /// Backward samples the master received.
    pub samples_received: u64,
    /// Samples whose round trip never completed.
    pub samples_lost: u64,
    /// Answers not back by the next tick.
    pub deadline_misses: u64,
    /// RMS distance of slave tool from operator target, m.
    pub tracking_rms_m: f64,
    /// Everything the master reported.
    pub master: MasterSummary,
    /// Per stream: c (master to emulator), v (emulator to slave), h, q.
    pub channels: BTreeMap<&'static str, ChannelCount>,
    /// The emulator's counters.
    pub emulator: Option<EmulatorRun>,
    /// The slave's counters.
    pub slave: Option<SlaveRun>,
}

/// Merges the three roles' results.
pub fn summarise(
    scenario: &Scenario,
    runner: &'static str,
    master: MasterSummary,
    emulator: Option<EmulatorRun>,
    slave: Option<SlaveRun>,
) -> Summary {
    let mut channels = BTreeMap::new();
    if let (Some(e), Some(s)) = (&emulator, &slave) {
        channels.insert(
            "c",
            ChannelCount::new(master.samples_sent, e.forward.received),
        );
        channels.insert("v", ChannelCount::new(e.forward.sent, s.stream.received));
        channels.insert("h", ChannelCount::new(s.stream.sent, e.backward.received));
        channels.insert(
            "q",
            ChannelCount::new(e.backward.sent, master.samples_received),
        );
    }
    Summary {
        scenario: scenario.name.clone(),
        mode: scenario.mode,
        rate_hz: scenario.rate_hz,
        arithmetic: scenario.arithmetic.to_string(),
        runner,
        round_trip_ns: master.round_trip_ns,
        overhead_ns: master.overhead_ns,
        stages_ns: master.stages_ns.clone(),
        samples_sent: master.samples_sent,
        samples_received: master.samples_received,
        samples_lost: master.samples_lost,
        deadline_misses: master.deadline_misses,
        tracking_rms_m: master.motion.tracking_rms_m,
        master,
        channels,
        emulator,
        slave,
    }
}

/// The summary as the terminal shows it.
pub fn render(s: &Summary, out: &Path) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let m = &s.master;
    let _ = writeln!(
        t,
        "Tactile run {:?}: {:?} at {} Hz, {} arithmetic, {}",
        s.scenario, s.mode, s.rate_hz, s.arithmetic, s.runner
    );
    let _ = writeln!(t, "{}", us_header());
    let _ = writeln!(t, "{}", us_line("round trip", &s.round_trip_ns));
    let _ = writeln!(t, "{}", us_line("system overhead", &s.overhead_ns));
    for (name, p) in &s.stages_ns {
        if p.count > 0 {
            let _ = writeln!(t, "{}", us_line(&format!("  {name}"), p));
        }
    }
    let _ = writeln!(
        t,
        "samples: sent {}, received {}, lost {}; deadline misses {}, late {}",
        s.samples_sent, s.samples_received, s.samples_lost, s.deadline_misses, m.late
    );
    for (name, c) in &s.channels {
        let _ = writeln!(
            t,
            "  stream {name}: sent {}, received {}, lost {}",
            c.sent, c.received, c.lost
        );
    }
    let mo = &m.motion;
    let _ = writeln!(
        t,
        "tracking error: rms {:.2} mm, max {:.2} mm",
        mo.tracking_rms_m * 1e3,
        mo.tracking_max_m * 1e3
    );
    let _ = writeln!(
        t,
        "forces: {} samples in contact, slave max {:.3} N, felt rms {:.3} N max {:.3} N, master torque max {:.4} N m",
        mo.contact_samples, mo.force_max_n, mo.felt_rms_n, mo.felt_max_n, mo.tau_max_nm
    );
    if let Some(sl) = &s.slave {
        let c = &sl.counters;
        let _ = writeln!(
            t,
            "slave: {} IK targets clamped, {} samples rejected, {} torque clamps",
            c.ik_clamped, c.rejected, c.torque_clamps
        );
    }
    let _ = writeln!(
        t,
        "wrote {}: summary.json trace.csv round_trip.hgrm overhead.hgrm latency.svg positions.svg forces.svg",
        out.display()
    );
    t
}

fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Option<T> {
    let text = std::fs::read_to_string(path).ok()?;
    serde_json::from_str(&text).ok()
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
}

fn stop(p: &mut Proc, grace: Duration) {
    if p.status.is_some() {
        return;
    }
    let pid = rustix::process::Pid::from_raw(p.child.id() as i32);
    if let Some(pid) = pid {
        let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
    }
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

fn log_tail(out: &Path, role: &str) -> String {
    let text = std::fs::read_to_string(out.join(format!("{role}.log"))).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(5)..].join("\n")
}

/// Runs the scenario's three processes; returns the summary.
pub fn run_processes(
    scenario: &Scenario,
    base_dir: &Path,
    out: &Path,
    prefix: &str,
    spin: Duration,
    progress: bool,
) -> Result<Summary, Error> {
    let exe = std::env::current_exe().map_err(Error::io("locating the tactile executable"))?;
    let scenario_file = out.join("scenario.toml");
    let text = toml::to_string(scenario)
        .map_err(|e| Error::Failed(format!("encoding the scenario: {e}")))?;
    std::fs::write(&scenario_file, text)
        .map_err(Error::io(format!("writing {}", scenario_file.display())))?;
    for f in ["master.json", "emulator.json", "slave.json", "summary.json"] {
        let _ = std::fs::remove_file(out.join(f));
    }
    let mut procs = Vec::new();
    for role in ["emulator", "slave", "master"] {
        let log = std::fs::File::create(out.join(format!("{role}.log")))
            .map_err(Error::io(format!("creating {role}.log")))?;
        let child = Command::new(&exe)
            .arg("role")
            .arg(role)
            .arg("--scenario")
            .arg(&scenario_file)
            .arg("--base-dir")
            .arg(base_dir)
            .arg("--prefix")
            .arg(prefix)
            .arg("--out")
            .arg(out)
            .arg("--spin-us")
            .arg(spin.as_micros().to_string())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            .spawn();
        match child {
            Ok(child) => procs.push(Proc {
                role,
                child,
                status: None,
            }),
            Err(e) => {
                for p in &mut procs {
                    stop(p, Duration::from_secs(1));
                }
                return Err(Error::Failed(format!(
                    "cannot start {} as {role}: {e}",
                    exe.display()
                )));
            }
        }
    }
    let started = Instant::now();
    let expected = match scenario.mode {
        Mode::Realtime => Some(scenario.samples as f64 * scenario.t_s()),
        Mode::Lockstep => None,
    };
    let mut failure: Option<String> = None;
    loop {
        for p in procs.iter_mut().filter(|p| p.status.is_none()) {
            if let Ok(Some(s)) = p.child.try_wait() {
                p.status = Some(s);
                if !s.success() && failure.is_none() {
                    failure = Some(format!(
                        "{} {}; its last words:\n{}",
                        p.role,
                        describe(s),
                        log_tail(out, p.role)
                    ));
                }
            }
        }
        let master_done = procs
            .iter()
            .any(|p| p.role == "master" && p.status.is_some());
        if failure.is_some() || master_done {
            break;
        }
        if progress && std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            let el = started.elapsed().as_secs_f64();
            match expected {
                Some(total) => eprint!("\r  running: {el:5.1} s of {total:.1} s"),
                None => eprint!("\r  running (lockstep): {el:5.1} s"),
            }
            let _ = std::io::stderr().flush();
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    if progress {
        eprintln!();
    }
    // The master's end-of-run sample stops the others; give them a moment, then insist.
    let until = Instant::now() + Duration::from_secs(3);
    while Instant::now() < until && procs.iter().any(|p| p.status.is_none()) {
        for p in procs.iter_mut().filter(|p| p.status.is_none()) {
            if let Ok(Some(s)) = p.child.try_wait() {
                p.status = Some(s);
            }
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    for p in &mut procs {
        stop(p, Duration::from_secs(2));
    }
    tactile_common::ipc::remove_run_files(prefix);
    if let Some(f) = failure {
        return Err(Error::Failed(f));
    }
    let master: MasterSummary = read_json(&out.join("master.json"))
        .ok_or_else(|| Error::Failed("the master wrote no master.json".into()))?;
    let emulator = read_json(&out.join("emulator.json"));
    let slave = read_json(&out.join("slave.json"));
    let summary = summarise(scenario, "processes", master, emulator, slave);
    write_json(&out.join("summary.json"), &summary)?;
    Ok(summary)
}

/// `tactile run`.
pub fn main(args: &RunArgs) -> Result<(), Error> {
    let (scenario, base_dir) = load_scenario(args.scenario.as_deref())?;
    std::fs::create_dir_all(&args.out)
        .map_err(Error::io(format!("creating {}", args.out.display())))?;
    let summary = if args.in_process {
        let sim = crate::sim::simulate(&scenario, &base_dir)?;
        let r = crate::roles::write_artifacts(&sim.rows, 0, scenario.t_s(), false, &args.out)?;
        let master = crate::roles::master_summary_from(&sim, &r);
        let s = summarise(&scenario, "in-process", master, None, None);
        write_json(&args.out.join("summary.json"), &s)?;
        s
    } else {
        let prefix = args
            .prefix
            .clone()
            .unwrap_or_else(|| format!("tactile{}", std::process::id()));
        run_processes(
            &scenario,
            &base_dir,
            &args.out,
            &prefix,
            Duration::from_micros(args.spin_us),
            !args.quiet,
        )?
    };
    print!("{}", render(&summary, &args.out));
    Ok(())
}
