//! `tactile bench`: the loop's own overhead, beside what a user would pick instead.
//!
//! In one run, for each rate: the trio over iceoryx2 with zero injected delay (the
//! product, with its default wait strategy), the same trio over UDP on loopback
//! (blocking receives, what most teleoperation stacks do), and the bare iceoryx2 hop:
//! a ping-pong between this process and an echo process (two hops, no computing), the
//! floor any loop over iceoryx2 stands on. Then the lockstep throughput of the trio.
//! Everything is reported as percentiles and as ratios taken in the same run.

use crate::cli::BenchArgs;
use crate::error::Error;
use crate::report::{us_header, us_line, Latency, Percentiles};
use crate::report_cmd::write_json;
use crate::run_cmd::{default_spin, run_processes, Loaded, Supervision, PAPER_SCENARIO};
use crate::summary::Summary;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tactile_common::clock::{now_ns, sleep_until_ns};
use tactile_common::samples::{Forward, FLAG_END, FLAG_PROBE};
use tactile_common::scenario::{Mode, Scenario};
use tactile_node::ipc::{self, Idle, Inbox, IpcError, Outbox, WaitPolicy, Waker};
use tactile_node::runtime::LinkKind;

/// One rate's results.
#[derive(Debug, Clone, Serialize)]
pub struct RateResult {
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Samples per run.
    pub samples: u64,
    /// System overhead of the iceoryx2 trio, ns.
    pub iceoryx2_overhead_ns: Option<Percentiles>,
    /// Its deadline misses.
    pub iceoryx2_deadline_misses: u64,
    /// Its per-stage times (compute per process, transport per hop), ns.
    pub iceoryx2_stages_ns: BTreeMap<String, Percentiles>,
    /// System overhead of the UDP trio, ns.
    pub udp_overhead_ns: Option<Percentiles>,
    /// Its deadline misses.
    pub udp_deadline_misses: u64,
    /// Its per-stage times, ns.
    pub udp_stages_ns: BTreeMap<String, Percentiles>,
    /// Round trip of the bare iceoryx2 hop pair (two hops), ns.
    pub bare_hop_round_trip_ns: Option<Percentiles>,
    /// Bare-hop round trips not back within their sampling period.
    pub bare_hop_deadline_misses: u64,
    /// iceoryx2 overhead / UDP overhead at p50.
    pub ratio_p50: f64,
    /// iceoryx2 overhead / UDP overhead at p99.
    pub ratio_p99: f64,
}

/// `bench.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Per rate.
    pub rates: Vec<RateResult>,
    /// Lockstep throughput of the iceoryx2 trio, samples per second.
    pub lockstep_samples_per_s: f64,
    /// Samples of the lockstep run.
    pub lockstep_samples: u64,
    /// Wait strategy used.
    pub strategy: String,
}

fn scenario(rate: f64, samples: u64, mode: Mode) -> Result<Scenario, Error> {
    let mut s = Scenario::from_toml_str(PAPER_SCENARIO)
        .map_err(|e| Error::Failed(format!("built-in scenario: {e}")))?;
    s.name = format!("bench-{rate}Hz");
    s.rate_hz = rate;
    s.samples = samples;
    s.mode = mode;
    s.validate()
        .map_err(|e| Error::BadInput(format!("bench at {rate} Hz: {e}")))?;
    Ok(s)
}

fn trio(sc: &Scenario, out: &Path, sup: &Supervision, link: LinkKind) -> Result<Summary, Error> {
    let sup = Supervision {
        link: crate::run_cmd::Links::on_this_host(link)?,
        prefix: format!(
            "{}{}",
            sup.prefix,
            out.file_name().map_or("", |n| n.to_str().unwrap_or(""))
        ),
        ..sup.clone()
    };
    let loaded = Loaded {
        scenario: sc.clone(),
        base_dir: std::env::current_dir().unwrap_or_else(|_| ".".into()),
        inputs: Vec::new(),
    };
    run_processes(&loaded, out, &sup)
}

/// The echo side of the bare hop: sends back every sample it gets, until the end mark.
pub fn echo(prefix: &str, wait: WaitPolicy) -> Result<(), IpcError> {
    let node = ipc::node(prefix, "echo")?;
    let inbox: Inbox<Forward> = Inbox::open(&node, "hop/ping")?;
    let out: Outbox<Forward> = Outbox::open(&node, "hop/pong", "bench")?;
    let waker = Waker::open(&node, "echo")?;
    loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        match waker.wait(&node, wait.spin, deadline, || inbox.try_recv())? {
            Ok(f) if f.signal.flags & FLAG_END != 0 => return Ok(()),
            Ok(f) => {
                out.publish(f, f.signal.flags & FLAG_PROBE != 0)?;
            }
            Err(Idle::Terminate) => return Ok(()),
            Err(Idle::Timeout) => {}
        }
    }
}

/// Puts back the CPU affinity the bench had, so the bare hop's pinning does not leak
/// into the next step of the bench.
struct Restore(Option<rustix::thread::CpuSet>);

impl Drop for Restore {
    fn drop(&mut self) {
        if let Some(set) = &self.0 {
            let _ = rustix::thread::sched_setaffinity(None, set);
        }
    }
}

fn pin_self(cpu: usize) {
    let mut set = rustix::thread::CpuSet::new();
    set.set(cpu);
    let _ = rustix::thread::sched_setaffinity(None, &set);
}

/// Ping-pong with an echo process at `rate` for `n` round trips.
fn bare_hop(rate: f64, n: u64, sup: &Supervision) -> Result<(Latency, u64), Error> {
    let prefix = format!("{}hop", sup.prefix);
    let exe = std::env::current_exe().map_err(Error::io("locating the tactile executable"))?;
    let mut cmd = if sup.pin {
        let mut c = Command::new("taskset");
        c.args(["-c", "1"]).arg(&exe);
        c
    } else {
        Command::new(&exe)
    };
    let mut child = cmd
        .arg("bench-echo")
        .args(["--prefix", &prefix, "--spin-us"])
        .arg(sup.spin.as_micros().to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| Error::Failed(format!("starting the echo process: {e}")))?;
    let saved_affinity = rustix::thread::sched_getaffinity(None).ok();
    let result = (|| -> Result<(Latency, u64), Error> {
        let fail = |e: IpcError| Error::Failed(e.to_string());
        if sup.pin {
            pin_self(0);
        }
        let _restore = Restore(saved_affinity);
        let node = ipc::node(&prefix, "bench").map_err(fail)?;
        let out: Outbox<Forward> = Outbox::open(&node, "hop/ping", "echo").map_err(fail)?;
        let inbox: Inbox<Forward> = Inbox::open(&node, "hop/pong").map_err(fail)?;
        let waker = Waker::open(&node, "bench").map_err(fail)?;
        // Probe until the echo answers.
        let start = Instant::now();
        loop {
            let mut p = Forward::default();
            p.signal.flags = FLAG_PROBE;
            out.send_control(p).map_err(fail)?;
            let got = waker
                .wait(
                    &node,
                    Duration::ZERO,
                    Instant::now() + Duration::from_millis(20),
                    || inbox.try_recv(),
                )
                .map_err(fail)?;
            if got.is_ok() {
                break;
            }
            if start.elapsed() > Duration::from_secs(10) {
                return Err(Error::Failed("the echo process did not answer".into()));
            }
        }
        while inbox.try_recv().map_err(fail)?.is_some() {}
        let t_s = (1e9 / rate) as u64;
        let t0 = now_ns() + 2_000_000;
        let mut lat = Latency::default();
        let mut misses = 0;
        for i in 0..n {
            let tick = t0 + i * t_s;
            sleep_until_ns(tick.saturating_sub(tactile_master::node::WAKE_EARLY_NS));
            while now_ns() < tick {
                std::hint::spin_loop();
            }
            let sent = now_ns();
            out.send(Forward {
                seq: i,
                ..Forward::default()
            })
            .map_err(fail)?;
            let deadline = Instant::now() + Duration::from_nanos(t_s);
            loop {
                match waker
                    .wait(&node, sup.spin, deadline, || inbox.try_recv())
                    .map_err(fail)?
                {
                    Ok(f) if f.seq == i => {
                        lat.record((now_ns() - sent) as i64);
                        break;
                    }
                    Ok(_) => {}
                    Err(_) => {
                        misses += 1;
                        break;
                    }
                }
            }
        }
        let mut end = Forward::default();
        end.signal.flags = FLAG_END;
        out.send_control(end).map_err(fail)?;
        Ok((lat, misses))
    })();
    let _ = child.wait();
    ipc::remove_run_files(&prefix);
    result
}

/// How the bench supervises its iceoryx2 runs: no restarts (a death fails the bench),
/// no progress line, pinned unless `--no-pin`.
fn supervision(args: &BenchArgs, prefix: &str, spin: Duration) -> Supervision {
    Supervision {
        prefix: prefix.to_string(),
        spin,
        progress: false,
        max_restarts: 0,
        link: crate::run_cmd::Links {
            kind: LinkKind::Iceoryx2,
            args: Default::default(),
        },
        pin: !args.no_pin,
        rt: false,
        no_trace: false,
    }
}

/// `tactile bench`.
pub fn main(args: &BenchArgs) -> Result<(), Error> {
    std::fs::create_dir_all(&args.out)
        .map_err(Error::io(format!("creating {}", args.out.display())))?;
    crate::run_cmd::clean_stale_runs();
    let mut rates = Vec::new();
    let prefix = args
        .prefix
        .clone()
        .unwrap_or_else(|| format!("tactile{}b", std::process::id()));
    for &rate in &args.rates {
        let sc = scenario(rate, args.samples, Mode::Realtime)?;
        let spin = args
            .spin_us
            .map_or_else(|| default_spin(&sc), Duration::from_micros);
        let sup = supervision(args, &prefix, spin);
        eprintln!(
            "tactile bench: {rate} Hz, {} samples: iceoryx2 trio",
            args.samples
        );
        let iox = trio(
            &sc,
            &args.out.join(format!("iox-{rate}")),
            &sup,
            LinkKind::Iceoryx2,
        )?;
        eprintln!("tactile bench: {rate} Hz: UDP trio");
        let udp_sup = Supervision {
            spin: Duration::ZERO,
            pin: false,
            ..sup.clone()
        };
        let udp = trio(
            &sc,
            &args.out.join(format!("udp-{rate}")),
            &udp_sup,
            LinkKind::Udp,
        )?;
        eprintln!("tactile bench: {rate} Hz: bare iceoryx2 hop");
        let (hop, hop_misses) = bare_hop(rate, args.samples, &sup)?;
        let ratio = |a: Option<u64>, b: Option<u64>| match (a, b) {
            (Some(a), Some(b)) if b > 0 => a as f64 / b as f64,
            _ => f64::NAN,
        };
        rates.push(RateResult {
            rate_hz: rate,
            samples: args.samples,
            ratio_p50: ratio(
                iox.overhead_ns.map(|p| p.p50),
                udp.overhead_ns.map(|p| p.p50),
            ),
            ratio_p99: ratio(
                iox.overhead_ns.map(|p| p.p99),
                udp.overhead_ns.map(|p| p.p99),
            ),
            iceoryx2_overhead_ns: iox.overhead_ns,
            iceoryx2_deadline_misses: iox.deadline_misses,
            iceoryx2_stages_ns: iox.stages_ns,
            udp_overhead_ns: udp.overhead_ns,
            udp_deadline_misses: udp.deadline_misses,
            udp_stages_ns: udp.stages_ns,
            bare_hop_round_trip_ns: hop.percentiles(),
            bare_hop_deadline_misses: hop_misses,
        });
    }
    eprintln!("tactile bench: lockstep throughput");
    let n = args.lockstep_samples;
    let sc = scenario(1000.0, n, Mode::Lockstep)?;
    let spin = args
        .spin_us
        .map_or_else(|| Duration::from_millis(2), Duration::from_micros);
    let sup = supervision(args, &prefix, spin);
    let lock = trio(&sc, &args.out.join("lockstep"), &sup, LinkKind::Iceoryx2)?;
    let report = BenchReport {
        lockstep_samples_per_s: lock.master.samples_per_s,
        lockstep_samples: n,
        strategy: format!(
            "iceoryx2: poll with yield for {} then block{}; UDP: blocking receive",
            args.spin_us
                .map_or_else(|| "two sampling periods".to_string(), |u| format!("{u} us")),
            if args.no_pin {
                ""
            } else {
                ", master on CPU 0, emulator and slave on CPU 1"
            }
        ),
        rates,
    };
    write_json(&args.out.join("bench.json"), &report)?;
    print!("{}", render(&report));
    Ok(())
}

fn render(r: &BenchReport) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let _ = writeln!(t, "strategy: {}", r.strategy);
    for x in &r.rates {
        let _ = writeln!(
            t,
            "\n{} Hz, {} samples, zero injected delay: system overhead per round trip",
            x.rate_hz, x.samples
        );
        let _ = writeln!(t, "{}  misses", us_header());
        for (name, p, misses) in [
            (
                "iceoryx2 loop",
                &x.iceoryx2_overhead_ns,
                x.iceoryx2_deadline_misses,
            ),
            ("UDP loop", &x.udp_overhead_ns, x.udp_deadline_misses),
            (
                "bare iceoryx2 (2 hops)",
                &x.bare_hop_round_trip_ns,
                x.bare_hop_deadline_misses,
            ),
        ] {
            let _ = writeln!(t, "{}  {misses}", us_line(name, p.as_ref()));
        }
        let _ = writeln!(
            t,
            "iceoryx2 / UDP: p50 {:.2}, p99 {:.2}",
            x.ratio_p50, x.ratio_p99
        );
        let _ = writeln!(t, "iceoryx2 loop stages:");
        for (name, p) in &x.iceoryx2_stages_ns {
            let _ = writeln!(t, "{}", us_line(&format!("  {name}"), Some(p)));
        }
    }
    let _ = writeln!(
        t,
        "\nlockstep throughput: {:.0} samples/s over {} samples",
        r.lockstep_samples_per_s, r.lockstep_samples
    );
    t
}
