//! Starts a scenario's three node programs, watches them until the master ends
//! (restarting the emulator or the slave when one dies, as allowed), stops them, and
//! writes the report from their records.

use super::links::node_command;
use super::proc::{describe, log_tail, stopped_by_signal, Proc};
use super::stall::{self, Progress};
use super::{nodes, prepare_out, survivor_grace, two_cpus, Loaded, Supervision};
use crate::error::Error;
use std::io::Write as _;
use std::path::Path;
use std::process::{Child, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_messages::Role;
use tactile_report::summary::Summary;
use tactile_report::write::{write_report, Launch};
use tactile_runtime::exit::{EXIT_BAD_INPUT, EXIT_INTERRUPTED};
use tactile_scenario::{Mode, Scenario};

/// Wait before restarting a dead process: a process that dies at once again must not
/// spin the launcher, and the peers see a clear break (longer than the peer timeout
/// of 10 samples at 100 Hz) rather than a flicker.
pub const RESTART_BACKOFF: Duration = Duration::from_millis(200);

/// How long the emulator and the slave have to end after a master that completed
/// (they end on its end-of-run sample, at once).
const END_GRACE: Duration = Duration::from_secs(3);

/// How often the launcher looks at its processes.
const POLL: Duration = Duration::from_millis(20);

/// Starts the node of a role (`true`: appending to its record after a restart).
type Spawn<'a> = dyn Fn(Role, bool) -> Result<Child, Error> + 'a;

/// What the supervision saw.
struct Watch {
    events: Vec<String>,
    failed: bool,
    interrupted: bool,
    /// A node refused its configuration (exit 2): its message.
    config_error: Option<String>,
    /// How the master ended, once it has.
    master: Option<ExitStatus>,
}

/// The nodes of a run and what happened to them.
struct Supervisor<'a> {
    sup: &'a Supervision,
    spawn: &'a Spawn<'a>,
    out: &'a Path,
    procs: Vec<Proc>,
    started: Instant,
    watch: Watch,
}

impl<'a> Supervisor<'a> {
    /// Starts the emulator, the slave and the master, in that order (the master
    /// waits for its peers); stops those started if one cannot start.
    fn start(
        sup: &'a Supervision,
        spawn: &'a Spawn<'a>,
        out: &'a Path,
        notes: Vec<String>,
    ) -> Result<Self, Error> {
        let mut procs: Vec<Proc> = Vec::new();
        for role in [Role::Emulator, Role::Slave, Role::Master] {
            match spawn(role, false) {
                Ok(child) => procs.push(Proc {
                    role,
                    child,
                    status: None,
                    restarts: 0,
                    restart_at: None,
                    progress: Progress::new(),
                }),
                Err(e) => {
                    procs
                        .iter_mut()
                        .for_each(|p| p.stop(Duration::from_secs(1)));
                    return Err(e);
                }
            }
        }
        let watch = Watch {
            events: notes,
            failed: false,
            interrupted: false,
            config_error: None,
            master: None,
        };
        Ok(Supervisor {
            sup,
            spawn,
            out,
            procs,
            started: Instant::now(),
            watch,
        })
    }

    fn elapsed_s(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }

    fn master(&mut self) -> Option<&mut Proc> {
        self.procs.iter_mut().find(|p| p.role == Role::Master)
    }

    /// A stop request asks the master to stop; the others follow its end-of-run
    /// sample, and the report of what ran is written.
    fn on_stop_request(&mut self) {
        if self.watch.interrupted {
            return;
        }
        self.watch.interrupted = true;
        let at = self.elapsed_s();
        self.watch.events.push(format!(
            "stop requested after {at:.2} s: stopping the master"
        ));
        if let Some(m) = self.master() {
            m.signal(rustix::process::Signal::TERM);
        }
    }

    /// Restarts the processes whose backoff is over.
    fn restart_due(&mut self) -> Result<(), Error> {
        let now = Instant::now();
        for k in 0..self.procs.len() {
            if self.watch.interrupted {
                // A stop was asked for while it waited: it stays stopped.
                self.procs[k].restart_at = None;
                continue;
            }
            if self.procs[k].restart_at.is_some_and(|at| now >= at) {
                let role = self.procs[k].role;
                self.procs[k].restart_at = None;
                self.procs[k].child = (self.spawn)(role, true)?;
                self.procs[k].progress = Progress::new();
                let at = self.elapsed_s();
                self.watch
                    .events
                    .push(format!("{role} restarted after {at:.2} s"));
            }
        }
        Ok(())
    }

    /// Takes in how process `k` ended; true if the master must be stopped.
    fn on_end(&mut self, k: usize, status: ExitStatus) -> bool {
        let role = self.procs[k].role;
        if status.code() == Some(i32::from(EXIT_BAD_INPUT)) {
            // A configuration error: restarting would fail the same way.
            self.procs[k].status = Some(status);
            let tail = log_tail(self.out, role);
            self.watch.config_error = Some(format!("{role}: {tail}"));
            if role == Role::Master {
                self.watch.master = Some(status);
            }
            return role != Role::Master;
        }
        if role == Role::Master {
            self.watch.master = Some(status);
            if !status.success() && !self.watch.interrupted && stopped_by_signal(status) {
                // Stopped by someone, like any other node: the run was interrupted,
                // it did not fail.
                self.stopped_from_outside(role, status);
            }
            return false;
        }
        if status.success() || self.watch.interrupted {
            // Passed on the master's end-of-run sample, or stopping as asked.
            self.procs[k].status = Some(status);
            return false;
        }
        if stopped_by_signal(status) {
            // Asked to stop (the terminal's Ctrl-C reaches every process of the group,
            // maybe before the launcher looks): not a death, not restarted.
            self.procs[k].status = Some(status);
            self.stopped_from_outside(role, status);
            return false;
        }
        self.on_death(k, status)
    }

    /// Someone stopped this node (or the whole group: the terminal's Ctrl-C reaches
    /// every process, maybe before the launcher looks): the run stops with it, as
    /// interrupted, whichever node it was.
    fn stopped_from_outside(&mut self, role: Role, status: ExitStatus) {
        let at = self.elapsed_s();
        let how = describe(status);
        self.watch.events.push(format!(
            "{role} {how} after {at:.2} s: a stop request, not restarted"
        ));
        self.on_stop_request();
    }

    /// The emulator or the slave died while the master runs: restart it if allowed.
    fn on_death(&mut self, k: usize, status: ExitStatus) -> bool {
        self.watch.failed = true;
        let at = self.elapsed_s();
        let how = describe(status);
        let p = &mut self.procs[k];
        if p.restarts < self.sup.max_restarts {
            p.restarts += 1;
            p.restart_at = Some(Instant::now() + RESTART_BACKOFF);
            let role = p.role;
            let tail = log_tail(self.out, role);
            self.watch.events.push(format!(
                "{role} {how} after {at:.2} s; restarting; its last words:\n{tail}"
            ));
            return false;
        }
        p.status = Some(status);
        let role = p.role;
        let tail = log_tail(self.out, role);
        self.watch.events.push(format!(
            "{role} {how} after {at:.2} s; no restarts left, stopping the run; its last words:\n{tail}"
        ));
        true
    }

    /// A node stopped for longer than the stall limit is frozen (SIGSTOP, a debugger):
    /// killed, its death then handled like any other (restarted if
    /// allowed, else the run stops), and the run counts as failed.
    /// Every process is looked at, whatever the limit (or none): a node still
    /// stopped when the run ends is named with the moment it stopped.
    fn kill_frozen(&mut self) {
        let now = Instant::now();
        let at = self.elapsed_s();
        for p in &mut self.procs {
            if p.status.is_some() || p.restart_at.is_some() {
                continue;
            }
            let stopped = p.progress.stopped_for(p.child.id(), now);
            let Some(limit) = self.sup.stall else {
                continue;
            };
            if stopped.is_none_or(|s| s < limit) {
                continue;
            }
            let state = stall::state_of(p.child.id());
            self.watch.events.push(format!(
                "{} made no progress for {:.1} s (the process is {state}): frozen, killed after {at:.2} s",
                p.role,
                limit.as_secs_f64()
            ));
            self.watch.failed = true;
            let _ = p.child.kill();
            p.progress = Progress::new();
        }
    }

    /// One look at every process.
    fn poll(&mut self) -> Result<(), Error> {
        self.kill_frozen();
        self.restart_due()?;
        let mut stop_master = false;
        for k in 0..self.procs.len() {
            if let Some(status) = self.procs[k].ended() {
                stop_master |= self.on_end(k, status);
            }
        }
        if stop_master {
            if let Some(m) = self.master() {
                m.stop(Duration::from_secs(2));
                let status = m.status;
                self.watch.master = status;
            }
        }
        Ok(())
    }

    /// A progress line is asked for and stderr is a terminal.
    fn shows_progress(&self) -> bool {
        self.sup.progress && std::io::IsTerminal::is_terminal(&std::io::stderr())
    }

    fn progress(&self, expected_s: Option<f64>) {
        if !self.shows_progress() {
            return;
        }
        let el = self.elapsed_s();
        match expected_s {
            Some(total) => crate::note!("\r  running: {el:5.1} s of {total:.1} s"),
            None => crate::note!("\r  running (lockstep): {el:5.1} s"),
        }
        let _ = std::io::stderr().flush();
    }

    /// Watches until the master has ended.
    fn watch(&mut self, scenario: &Scenario, stop: &AtomicBool) -> Result<(), Error> {
        let expected_s = match scenario.mode {
            Mode::Realtime => Some(scenario.samples as f64 * scenario.t_s()),
            Mode::Lockstep => None,
        };
        while self.watch.master.is_none() {
            if stop.load(Ordering::SeqCst) {
                self.on_stop_request();
            }
            if let Err(e) = self.poll() {
                // A restart that cannot start: nothing may run on without a launcher.
                self.procs
                    .iter_mut()
                    .for_each(|p| p.stop(Duration::from_secs(1)));
                return Err(e);
            }
            self.progress(expected_s);
            std::thread::sleep(POLL);
        }
        if self.shows_progress() {
            crate::noteln!();
        }
        self.after_master(scenario);
        Ok(())
    }

    /// A master that failed (not on a stop request): say so, and let the survivors
    /// notice (the slave holds its position) before they are stopped.
    fn after_master(&mut self, scenario: &Scenario) {
        let Some(s) = self.watch.master else { return };
        let asked = s.code() == Some(i32::from(EXIT_INTERRUPTED)) && self.watch.interrupted;
        if s.success() || asked || self.watch.config_error.is_some() {
            return;
        }
        self.watch.failed = true;
        let (how, at) = (describe(s), self.elapsed_s());
        let tail = log_tail(self.out, Role::Master);
        self.watch.events.push(format!(
            "master {how} after {at:.2} s; its last words:\n{tail}"
        ));
        std::thread::sleep(survivor_grace(scenario));
    }

    /// After a clean master the end-of-run sample stops the others: a moment for
    /// them, then every process still running is stopped.
    /// A node that has not ended by then is a failed run: frozen (its process
    /// stopped, however briefly: the samples it missed are lost), or not answering the
    /// end-of-run sample. One that ended badly on its own is named with its last words.
    fn finish(mut self) -> Watch {
        let master_ok = self.watch.master.is_some_and(|s| s.success());
        let until = Instant::now() + END_GRACE * u32::from(master_ok);
        while Instant::now() < until && self.procs.iter_mut().any(Proc::running) {
            std::thread::sleep(Duration::from_millis(10));
        }
        let now = Instant::now();
        for p in &mut self.procs {
            if p.status.is_none() {
                p.progress.stopped_for(p.child.id(), now);
            }
        }
        for k in 0..self.procs.len() {
            let p = &mut self.procs[k];
            if p.status.is_none() {
                p.status = p.child.try_wait().ok().flatten();
                // One waiting out its restart backoff was named when it died.
                let waiting = p.restart_at.is_some();
                match p.status {
                    _ if waiting => {}
                    Some(s) if p.role != Role::Master => self.ended_badly(k, s),
                    None => self.unfinished(k, master_ok),
                    _ => {}
                }
            }
            self.procs[k].stop(Duration::from_secs(2));
        }
        self.watch
    }

    /// A node that ended on its own after the master, by a failure (not a stop
    /// request): named, with its last words, and the run failed.
    fn ended_badly(&mut self, k: usize, status: ExitStatus) {
        if status.success() || stopped_by_signal(status) || self.watch.interrupted {
            return;
        }
        let role = self.procs[k].role;
        self.watch.failed = true;
        let (how, at) = (describe(status), self.elapsed_s());
        let tail = log_tail(self.out, role);
        self.watch.events.push(format!(
            "{role} {how} after {at:.2} s; its last words:\n{tail}"
        ));
    }

    /// A node still running when the run ends: frozen (stopped since a moment the
    /// launcher names), or deaf to the master's end of the run; either fails the run.
    /// A frozen one is killed outright (a stopped process cannot take SIGTERM).
    fn unfinished(&mut self, k: usize, master_ok: bool) {
        let at = self.elapsed_s();
        let started = self.started;
        let p = &mut self.procs[k];
        let role = p.role;
        let state = stall::state_of(p.child.id());
        if let Some(since) = p.progress.since() {
            let since = since.saturating_duration_since(started).as_secs_f64();
            self.watch.events.push(format!(
                "{role} was still frozen when the run ended after {at:.2} s: the process is {state} since {since:.2} s; killed"
            ));
            self.watch.failed = true;
            let _ = p.child.kill();
        } else if master_ok && !self.watch.interrupted {
            self.watch.events.push(format!(
                "{role} had not ended {:.1} s after the master's end of the run (the process is {state}): it never answered the end-of-run sample; stopped",
                END_GRACE.as_secs_f64()
            ));
            self.watch.failed = true;
        }
    }
}

/// Runs the scenario's three node programs; returns the summary (which says whether
/// the run failed: a process died, or a stop request cut it short).
pub fn run_processes(loaded: &Loaded, out: &Path, sup: &Supervision) -> Result<Summary, Error> {
    // Every check that can refuse the run comes before anything starts or is written:
    // a prefix held by any process (a launcher, a node started by hand), the output
    // folder, the node programs.
    tactile_runtime::lock::in_use(&sup.prefix)?;
    let holder = format!(
        "tactile run (pid {}, writing to {})",
        std::process::id(),
        out.display()
    );
    let _lock = tactile_runtime::lock::take(&sup.prefix, "run", &holder)?;
    let dir = nodes::node_dir()?;
    let (bundled, _held) = prepare_out(out, loaded)?;
    // The nodes run the scenario as written here, reading the copies of its inputs
    // (absolute paths); the report's scenario.toml refers to them relatively.
    let scenario_file = out.join("scenario.toml");
    let text = bundled.scenario.to_toml();
    std::fs::write(&scenario_file, text)
        .map_err(Error::io(format!("writing {}", scenario_file.display())))?;
    let mut notes = Vec::new();
    let pin = sup.pin && two_cpus();
    if sup.pin && !pin {
        notes.push("fewer than two CPUs: processes not pinned".to_string());
    }
    let sup = Supervision { pin, ..sup.clone() };
    let spawn = |role: Role, append: bool| -> Result<Child, Error> {
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
    let stop: Arc<AtomicBool> =
        tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let mut run = Supervisor::start(&sup, &spawn, out, notes)?;
    run.watch(&loaded.scenario, &stop)?;
    let w = run.finish();
    tactile_transport::ipc::remove_run_files(&sup.prefix);
    report(out, w, &sup.outputs, &loaded.warnings)
}

/// The report of a supervised run (with `warnings`, what its scenario and inputs
/// said before it), or the error that ended it.
fn report(
    out: &Path,
    w: Watch,
    outputs: &super::Outputs,
    warnings: &[String],
) -> Result<Summary, Error> {
    if let Some(msg) = w.config_error {
        return Err(Error::BadInput(msg));
    }
    if !out.join("master.rec").exists() {
        // Stopped before the master began its record (a Ctrl-C at once): a stop, not
        // a failure, with nothing to report.
        if w.interrupted {
            return Err(Error::Stopped(
                "before the master began its record: no report written".into(),
            ));
        }
        return Err(Error::Failed(format!(
            "the run failed, no record from the master:\n{}",
            w.events.join("\n")
        )));
    }
    let launch = Launch {
        events: w.events,
        failed: w.failed,
        stop: tactile_runtime::signals::stop_flag().ok(),
        outputs: outputs.clone(),
        warnings: warnings.to_vec(),
        ..Launch::default()
    };
    let launch = if w.interrupted {
        launch.interrupted()
    } else {
        launch
    };
    write_report(&[out.to_path_buf()], out, &launch).map_err(|e| {
        if !launch.failed {
            return Error::Report(e);
        }
        // The nodes failed first (a full disk stops them too): their failures, then
        // the report's, so the cause is not hidden behind the last symptom.
        Error::Failed(format!(
            "the run failed:\n{}\nand its report could not be written: {e}",
            launch.events.join("\n")
        ))
    })
}
