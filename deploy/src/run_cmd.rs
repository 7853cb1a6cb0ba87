//! `tactile run`: starts the three processes for a scenario, watches them, and merges
//! their results into one report.

use crate::cli::RunArgs;
use crate::error::Error;
use crate::roles::{write_json, MasterSummary};
use crate::summary::{read_json, render, summarise, Summary};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_common::scenario::{Mode, Scenario};
use tactile_master::operator::OperatorSource;

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

/// How `tactile run` supervises its processes.
#[derive(Debug, Clone)]
pub struct Supervision {
    /// iceoryx2 prefix of the run.
    pub prefix: String,
    /// Busy-poll budget of every process.
    pub spin: Duration,
    /// Progress line on a terminal.
    pub progress: bool,
    /// Restarts allowed per process (emulator, slave) when one dies mid-run.
    pub max_restarts: u32,
    /// What carries the samples.
    pub transport: crate::roles::Transport,
    /// Pin master to CPU 0, emulator and slave to CPU 1.
    pub pin: bool,
    /// SCHED_FIFO priority for the three processes, if permitted.
    pub rt: bool,
}

/// Wraps a role's command in taskset and chrt as the supervision asks; falls back to
/// the plain command (with a note) when a tool is missing or refuses.
fn wrapped(sup: &Supervision, role: &str, exe: &Path, notes: &mut Vec<String>) -> Vec<String> {
    let mut argv: Vec<String> = Vec::new();
    if sup.pin {
        let cpu = if role == "master" { "0" } else { "1" };
        if tool_works(&["taskset", "-c", cpu, "true"]) {
            argv.extend(["taskset", "-c", cpu].map(String::from));
        } else if !notes.iter().any(|n| n.contains("taskset")) {
            notes.push("taskset unavailable: processes not pinned".into());
        }
    }
    if sup.rt {
        if tool_works(&["chrt", "-f", "10", "true"]) {
            argv.extend(["chrt", "-f", "10"].map(String::from));
        } else if !notes.iter().any(|n| n.contains("chrt")) {
            notes.push("SCHED_FIFO not permitted: processes run SCHED_OTHER".into());
        }
    }
    argv.push(exe.display().to_string());
    argv.extend(["role".to_string(), role.to_string()]);
    argv
}

fn tool_works(argv: &[&str]) -> bool {
    Command::new(argv[0])
        .args(&argv[1..])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Removes the shared memory of earlier runs whose launcher is gone (a crashed or
/// killed run leaves it behind; iceoryx2 would clean it only for the same prefix).
pub fn clean_stale_runs() {
    let Ok(dir) = std::fs::read_dir(tactile_common::ipc::ROOT) else {
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
            tactile_common::ipc::remove_run_files(&name);
        }
    }
}

/// Runs the scenario's three processes; returns the summary (which says whether the
/// run failed: a process died, or a stop request cut it short).
pub fn run_processes(
    scenario: &Scenario,
    base_dir: &Path,
    out: &Path,
    sup: &Supervision,
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
    // SIGINT and SIGTERM stop the run cleanly: the master is asked to stop, the
    // others follow its end-of-run sample, and the report of what ran is written.
    let stop_requested = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop_requested))
            .map_err(Error::io("installing signal handlers"))?;
    }
    let mut notes = Vec::new();
    let commands: Vec<(&'static str, Vec<String>)> = ["emulator", "slave", "master"]
        .into_iter()
        .map(|role| (role, wrapped(sup, role, &exe, &mut notes)))
        .collect();
    let udp_arg = match sup.transport {
        crate::roles::Transport::Udp(p) => Some(p.arg()),
        crate::roles::Transport::Iceoryx2 => None,
    };
    let spawn = |role: &'static str| -> Result<Child, Error> {
        let log = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(out.join(format!("{role}.log")))
            .map_err(Error::io(format!("creating {role}.log")))?;
        let argv = &commands
            .iter()
            .find(|(r, _)| *r == role)
            .ok_or_else(|| Error::Failed(format!("no command for {role}")))?
            .1;
        let mut cmd = Command::new(&argv[0]);
        cmd.args(&argv[1..]);
        if let Some(p) = &udp_arg {
            cmd.arg("--udp-ports").arg(p);
        }
        cmd.arg("--scenario")
            .arg(&scenario_file)
            .arg("--base-dir")
            .arg(base_dir)
            .arg("--prefix")
            .arg(&sup.prefix)
            .arg("--out")
            .arg(out)
            .arg("--spin-us")
            .arg(sup.spin.as_micros().to_string())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .map_err(|e| Error::Failed(format!("cannot start {} as {role}: {e}", exe.display())))
    };
    for role in ["master", "emulator", "slave"] {
        let _ = std::fs::remove_file(out.join(format!("{role}.log")));
    }
    let mut procs: Vec<Proc> = Vec::new();
    for role in ["emulator", "slave", "master"] {
        match spawn(role) {
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
    let mut events: Vec<String> = notes;
    let mut failed = false;
    let mut interrupted = false;
    let mut master_status = None;
    while master_status.is_none() {
        if stop_requested.swap(false, Ordering::SeqCst) && !interrupted {
            interrupted = true;
            events.push(format!(
                "stop requested after {:.2} s: stopping the master",
                started.elapsed().as_secs_f64()
            ));
            if let Some(m) = procs.iter().find(|p| p.role == "master") {
                if let Some(pid) = rustix::process::Pid::from_raw(m.child.id() as i32) {
                    let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
                }
            }
        }
        let mut stop_master = false;
        for p in procs.iter_mut() {
            if let Some(at) = p.restart_at {
                if Instant::now() >= at {
                    p.restart_at = None;
                    p.child = spawn(p.role)?;
                    events.push(format!(
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
            failed = true;
            let at = started.elapsed().as_secs_f64();
            let how = describe(status);
            if p.restarts < sup.max_restarts {
                p.restarts += 1;
                p.restart_at = Some(Instant::now() + RESTART_BACKOFF);
                events.push(format!("{} {how} after {at:.2} s; restarting", p.role));
            } else {
                p.status = Some(status);
                events.push(format!(
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
    let master_ok = master_status.is_some_and(|s| s.success());
    if let Some(s) = master_status.filter(|s| !s.success()) {
        failed = true;
        events.push(format!(
            "master {} after {:.2} s; its last words:\n{}",
            describe(s),
            started.elapsed().as_secs_f64(),
            log_tail(out, "master")
        ));
        // Let the survivors notice (the slave holds its position), then stop them.
        let grace = crate::run_cmd::survivor_grace(scenario);
        std::thread::sleep(grace);
    }
    // After a clean master the end-of-run sample stops the others; give them a moment.
    let until = Instant::now() + Duration::from_secs(if master_ok { 3 } else { 0 });
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
    tactile_common::ipc::remove_run_files(&sup.prefix);
    let emulator = read_json(&out.join("emulator.json"));
    let slave = read_json(&out.join("slave.json"));
    let Some(master) = read_json::<MasterSummary>(&out.join("master.json")) else {
        return Err(Error::Failed(format!(
            "the run failed, no report from the master:\n{}",
            events.join("\n")
        )));
    };
    events.extend(
        master
            .events
            .iter()
            .map(|e| format!("sample {}: {}", e.sample, e.what)),
    );
    let mut summary = summarise(scenario, "processes", master, emulator, slave);
    summary.events = events;
    summary.failed = failed;
    summary.interrupted = interrupted;
    write_json(&out.join("summary.json"), &summary)?;
    Ok(summary)
}

/// The measured default wait: poll (yielding) for two sampling periods before
/// blocking, so the processes of a running loop never pay a wake-up.
pub fn default_spin(scenario: &Scenario) -> Duration {
    Duration::from_nanos(2 * scenario.t_s_ns())
}

/// How long the launcher lets the emulator and slave run on after the master died:
/// long enough for the slave to notice and hold (its peer timeout) and to be seen.
pub fn survivor_grace(scenario: &Scenario) -> Duration {
    tactile_slave::process::hold_timeout(scenario) + Duration::from_millis(500)
}

/// `tactile run`.
pub fn main(args: &RunArgs) -> Result<(), Error> {
    let (scenario, base_dir) = load_scenario(args.scenario.as_deref())?;
    for w in scenario.warnings() {
        eprintln!("tactile: warning: {w}");
    }
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
        clean_stale_runs();
        let sup = Supervision {
            prefix: args
                .prefix
                .clone()
                .unwrap_or_else(|| format!("tactile{}", std::process::id())),
            spin: args
                .spin_us
                .map_or_else(|| default_spin(&scenario), Duration::from_micros),
            progress: !args.quiet,
            max_restarts: args.max_restarts,
            transport: if args.udp {
                crate::roles::Transport::Udp(
                    crate::udp::UdpPorts::free().map_err(|e| Error::Failed(e.to_string()))?,
                )
            } else {
                crate::roles::Transport::Iceoryx2
            },
            pin: !args.no_pin,
            rt: args.rt,
        };
        run_processes(&scenario, &base_dir, &args.out, &sup)?
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
