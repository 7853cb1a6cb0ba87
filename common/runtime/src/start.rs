//! What the three node programs share before their loop: the start-up checks, the
//! scheduling, and the start of their record ([`crate::program`] runs the rest).

use crate::args::{LinkKind, NodeArgs, NodeError};
use crate::lock::{self, Lock};
use std::path::PathBuf;
use std::time::Duration;
use tactile_messages::clock::now_ns;
use tactile_messages::Role;
use tactile_records::{record_path, Start};
use tactile_scenario::Scenario;

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
pub fn prepare(role: Role, args: &NodeArgs, links: &Links) -> Result<Prepared, NodeError> {
    let bad = NodeError::BadInput;
    // From here on a stop request is never fatal: it is noticed by the loop's driver
    // and the record is closed.
    crate::signals::stop_flag().map_err(|e| bad(format!("installing signal handlers: {e}")))?;
    lock::check_prefix(&args.link.prefix)?;
    let (scenario, base_dir) = crate::files::load_scenario(&args.scenario)?;
    args.link
        .check(&links.kinds())
        .map_err(|e| bad(e.to_string()))?;
    crate::outside::check(&scenario, role)?;
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
    let lock = lock::take(&args.link.prefix, role.name(), &holder)?;
    crate::logging::init(&args.out, role, args.supervised.is_none())?;
    if let Some(parent) = args.supervised {
        supervise(parent)?;
    }
    if let Some(cpu) = args.cpu {
        pin(cpu)?;
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
/// (docs/07-latency.md, "Waiting"). Lockstep never sleeps: it polls two sampling periods, then
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
pub fn pin(cpu: usize) -> Result<(), crate::sched::SchedError> {
    use crate::sched::SchedError;
    if !crate::sched::allowed_cpus()?.contains(&cpu) {
        return Err(SchedError::NotAllowed(cpu));
    }
    crate::sched::pin_thread(cpu).map_err(|source| SchedError::Pin {
        who: "",
        cpu,
        source,
    })
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

/// Which transport each of a node's streams takes: the emulator may carry the two
/// streams to the master on another than the two to the slave; `direct`: a master
/// without an emulator (Zenoh only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Links {
    /// For c(n) and q(n).
    pub master_side: LinkKind,
    /// For v(n) and h(n).
    pub slave_side: LinkKind,
    /// The master talks to the slave without an emulator.
    pub direct: bool,
}

impl Links {
    /// Every stream on `kind`.
    pub fn all(kind: LinkKind) -> Links {
        Links {
            master_side: kind,
            slave_side: kind,
            direct: false,
        }
    }

    /// The transport of `stream`.
    pub fn of(&self, stream: tactile_transport::Stream) -> LinkKind {
        if stream.touches_master() && !self.direct {
            self.master_side
        } else {
            self.slave_side
        }
    }

    /// The transports in use.
    pub fn kinds(&self) -> [LinkKind; 2] {
        [self.master_side, self.slave_side]
    }

    /// The links in words, for the record and the log.
    pub fn describe(&self, a: &tactile_transport::LinkArgs) -> String {
        let words = a.describe();
        if self.master_side == self.slave_side {
            words
        } else {
            format!(
                "towards the master {}, towards the slave {}; {words}",
                self.master_side.name(),
                self.slave_side.name()
            )
        }
    }
}

/// The `Start` of a node's record from its arguments.
pub fn start_record(role: Role, args: &NodeArgs, links: &Links, p: &Prepared) -> Start {
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
        prefix: args.link.prefix.clone(),
        link: links.describe(&args.link),
        scenario: p.scenario.name.clone(),
        scenario_toml: p.scenario.resolved(&p.base_dir).to_toml(),
        samples: p.scenario.samples,
        rate_hz: p.scenario.rate_hz,
        sched: p.sched.clone(),
        unix_ms,
        mono_ns: now_ns(),
    }
}

/// A fresh run token: random, never zero (zero means "unknown").
pub fn new_run_token() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(now_ns());
    h.write_u32(std::process::id());
    h.finish().max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::testing::args;
    use crate::args::NodeArgs;

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
