//! `tactile bench`: the loop's own overhead, beside what a user would pick instead.
//!
//! In one run, for each rate: the trio over iceoryx2 with zero injected delay (the
//! product, with its default wait strategy), the same trio over UDP on loopback
//! (blocking receives, what most teleoperation stacks do), and the bare iceoryx2 hop:
//! a ping-pong between this process and an echo process (two hops, no computing), the
//! floor any loop over iceoryx2 stands on. Then the lockstep throughput of the trio.
//! Everything is reported as percentiles and as ratios taken in the same run.

mod hop;
#[cfg(feature = "zenoh")]
mod live;
mod stalls;

pub use hop::echo;

use clap::Args;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use tactile_launch::error::Error;
use tactile_launch::netns::Pair;
use tactile_launch::{run_processes, Loaded, Supervision, PAPER_SCENARIO};
use tactile_report::analysis::{us_header, us_line, Percentiles};
use tactile_report::summary::Summary;
use tactile_report::write::write_json;
use tactile_runtime::args::LinkKind;
use tactile_scenario::{Mode, Scenario};

/// Runs of this bench so far (their prefixes' suffix).
static RUNS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

/// One loop of a rate: a transport, on one host or across two.
#[derive(Debug, Clone, Serialize)]
pub struct LoopResult {
    /// `iceoryx2`, `udp`, `zenoh` (one host) or `zenoh-hosts`, `udp-hosts` (master in
    /// one network namespace, emulator and slave in the other).
    pub name: String,
    /// System overhead per round trip, ns.
    pub overhead_ns: Option<Percentiles>,
    /// Answers not back by the next tick.
    pub deadline_misses: u64,
    /// Samples lost.
    pub samples_lost: u64,
    /// Per-stage times (compute per process, transport per hop), ns.
    pub stages_ns: BTreeMap<String, Percentiles>,
    /// Each node's scheduling as its record says (the same for every loop of a rate,
    /// so the comparison is fair).
    pub sched: BTreeMap<String, tactile_runtime::sched::Sched>,
}

/// One rate's results.
#[derive(Debug, Clone, Serialize)]
pub struct RateResult {
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Samples per run.
    pub samples: u64,
    /// Each loop, in the order run.
    pub loops: Vec<LoopResult>,
    /// Round trip of the bare iceoryx2 hop pair (two hops), ns.
    pub bare_hop_round_trip_ns: Option<Percentiles>,
    /// Bare-hop round trips not back within their sampling period.
    pub bare_hop_deadline_misses: u64,
    /// Overhead ratios at p50, p99 and p99.9 taken in this run: `iceoryx2/udp`, and
    /// `zenoh-hosts/udp-hosts` across hosts, `live-on/live-off` (the live view's
    /// cost: the iceoryx2 loop without and with it, run back to back).
    pub ratios: BTreeMap<String, [f64; 3]>,
    /// Live-view messages the viewer received in the `live-on` loop.
    pub live_messages: Option<u64>,
}

impl RateResult {
    fn get(&self, name: &str) -> Option<&Percentiles> {
        self.loops
            .iter()
            .find(|l| l.name == name)
            .and_then(|l| l.overhead_ns.as_ref())
    }

    fn ratio(&mut self, a: &str, b: &str) {
        if let (Some(x), Some(y)) = (self.get(a).copied(), self.get(b).copied()) {
            let r = |p: u64, q: u64| if q > 0 { p as f64 / q as f64 } else { f64::NAN };
            self.ratios.insert(
                format!("{a}/{b}"),
                [r(x.p50, y.p50), r(x.p99, y.p99), r(x.p999, y.p999)],
            );
        }
    }
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
    /// The machine's own stalls, probed after the loops (`--probe-s`).
    pub machine: stalls::StallReport,
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
    /// How the node programs wait and are scheduled (the same for every transport).
    #[command(flatten)]
    pub nodes: crate::cmd::node_options::NodeOptions,
    /// Also run the loops across two hosts: Zenoh in clear, Zenoh over mutual TLS
    /// (certificates made with `openssl` for the run) and UDP, in two network
    /// namespaces joined by a veth pair (made and removed by the bench; needs root).
    #[arg(long)]
    pub hosts: bool,
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

/// A loop's result; a stop request (SIGINT, SIGTERM) ends the bench, so the
/// namespaces it made are removed on the way out.
fn loop_result(name: &str, s: Summary) -> Result<LoopResult, Error> {
    if s.interrupted {
        return Err(Error::Interrupted);
    }
    Ok(LoopResult {
        name: name.to_string(),
        overhead_ns: s.overhead_ns,
        deadline_misses: s.deadline_misses,
        samples_lost: s.samples_lost,
        stages_ns: s.stages_ns,
        sched: s
            .nodes
            .iter()
            .map(|(role, n)| (role.to_string(), n.sched.clone()))
            .collect(),
    })
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
    trio_with(
        sc,
        out,
        sup,
        tactile_launch::Links::on_this_host(link)?,
        Default::default(),
    )
}

/// A trio with these links and command prefixes (to put nodes on other hosts).
fn trio_with(
    sc: &Scenario,
    out: &Path,
    sup: &Supervision,
    links: tactile_launch::Links,
    wrap: [Vec<String>; 3],
) -> Result<Summary, Error> {
    let sup = Supervision {
        link: links,
        wrap,
        // A short suffix per run: iceoryx2's socket paths leave room for prefixes of
        // 26 characters at most (see tactile_runtime::lock::MAX_PREFIX_LEN).
        prefix: format!(
            "{}{:x}",
            sup.prefix,
            RUNS.fetch_add(1, std::sync::atomic::Ordering::SeqCst)
        ),
        ..sup.clone()
    };
    let loaded = Loaded {
        scenario: sc.clone(),
        base_dir: std::env::current_dir().unwrap_or_else(|_| ".".into()),
        inputs: Vec::new(),
        warnings: Vec::new(),
    };
    run_processes(&loaded, out, &sup)
}

/// Whether this build can run a loop on `link`: the Zenoh loops need the `zenoh`
/// feature, and a bench without it says once that it leaves them out.
fn zenoh_built(link: LinkKind) -> bool {
    link != LinkKind::Zenoh || cfg!(feature = "zenoh")
}

/// `tactile bench`.
pub fn main(args: &BenchArgs) -> Result<(), Error> {
    if !(0.0..=600.0).contains(&args.probe_s) {
        return Err(Error::BadInput(format!(
            "--probe-s {}: must be 0 to 600 seconds",
            args.probe_s
        )));
    }
    tactile_report::ours::refuse_foreign(&args.out)?;
    tactile_report::write::make_out_dir(&args.out)?;
    tactile_launch::clean_stale_runs();
    // From here a stop request is a flag the runs look at, not the end of this
    // process: the bench stops between runs and removes what it made.
    let stop =
        tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    if !cfg!(feature = "zenoh") {
        tactile_launch::noteln!(
            "tactile bench: no Zenoh loop: this build has no Zenoh link (build with --features zenoh)"
        );
    }
    let hosts = if args.hosts {
        let tag = format!("b{}", std::process::id() % 100_000);
        Some(tactile_launch::netns::Pair::new(&tag).map_err(|e| {
            Error::Failed(format!("--hosts: cannot make two network namespaces: {e}"))
        })?)
    } else {
        None
    };
    let bench = Bench {
        args,
        // No restarts (a death fails the bench), no progress line.
        sup: args
            .nodes
            .supervision(tactile_launch::Links::plain(LinkKind::Iceoryx2), "b"),
        stop: &stop,
    };
    let mut rates = Vec::new();
    for &rate in &args.rates {
        rates.push(bench.rate(rate, hosts.as_ref())?);
    }
    let report = bench.finish(rates)?;
    write_json(&args.out.join("bench.json"), &report)?;
    tactile_launch::out!("{}", render(&report));
    Ok(())
}

/// One bench invocation: its arguments, the supervision every loop gets, and the
/// stop request it looks at between runs.
struct Bench<'a> {
    args: &'a BenchArgs,
    sup: Supervision,
    stop: &'a Arc<AtomicBool>,
}

impl Bench<'_> {
    fn stopped(&self) -> Result<(), Error> {
        if self.stop.load(Ordering::SeqCst) {
            return Err(Error::Interrupted);
        }
        Ok(())
    }

    /// Every loop at `rate`, the percentile plot, the bare hop and the ratios.
    fn rate(&self, rate: f64, hosts: Option<&Pair>) -> Result<RateResult, Error> {
        let sc = scenario(rate, self.args.samples, Mode::Realtime)?;
        let mut loops = self.one_host(&sc)?;
        let live_messages = self.live(&sc, &mut loops)?;
        if let Some(pair) = hosts {
            loops.extend(self.across_hosts(&sc, pair)?);
        }
        percentile_plot(&self.args.out, rate, &loops)?;
        tactile_launch::noteln!("tactile bench: {rate} Hz: bare iceoryx2 hop");
        let (hop, hop_misses) = hop::bare_hop(rate, self.args.samples, &self.sup)?;
        let mut r = RateResult {
            rate_hz: rate,
            samples: self.args.samples,
            loops,
            bare_hop_round_trip_ns: hop.percentiles(),
            bare_hop_deadline_misses: hop_misses,
            ratios: BTreeMap::new(),
            live_messages,
        };
        r.ratio("live-on", "live-off");
        r.ratio("iceoryx2", "udp");
        r.ratio("zenoh", "udp");
        r.ratio("zenoh-hosts", "udp-hosts");
        r.ratio("zenoh-tls-hosts", "zenoh-hosts");
        Ok(r)
    }

    /// The loops on one host, with the same scheduling (pinned unless --no-pin,
    /// polling for the same budget).
    fn one_host(&self, sc: &Scenario) -> Result<Vec<LoopResult>, Error> {
        let mut loops = Vec::new();
        for (name, link) in [
            ("iceoryx2", LinkKind::Iceoryx2),
            ("udp", LinkKind::Udp),
            ("zenoh", LinkKind::Zenoh),
        ]
        .into_iter()
        .filter(|&(_, l)| zenoh_built(l))
        {
            let (rate, n) = (sc.rate_hz, sc.samples);
            tactile_launch::noteln!("tactile bench: {rate} Hz, {n} samples: {name} loop");
            let out = self.args.out.join(format!("{name}-{rate}"));
            let s = trio(sc, &out, &self.sup, link)?;
            loops.push(loop_result(name, s)?);
            self.stopped()?;
        }
        Ok(loops)
    }

    /// The iceoryx2 loop without and with the live view (publishing to a viewer in
    /// this process): what watching a run costs the loop. Messages the viewer
    /// received, or None in a build without Zenoh.
    fn live(&self, sc: &Scenario, loops: &mut Vec<LoopResult>) -> Result<Option<u64>, Error> {
        #[cfg(feature = "zenoh")]
        {
            let viewer = live::Viewer::open()?;
            let (rate, n) = (sc.rate_hz, sc.samples);
            // Off, then on, back to back: the machine's noise drifts over minutes, so
            // the pair compared is the pair run together.
            for (name, sc) in [("live-off", sc.clone()), ("live-on", viewer.scenario(sc))] {
                tactile_launch::noteln!(
                    "tactile bench: {rate} Hz, {n} samples: iceoryx2 loop, {name} (live view at {} Hz)",
                    live::LIVE_HZ.min(rate)
                );
                let out = self.args.out.join(format!("{name}-{rate}"));
                let s = trio(&sc, &out, &self.sup, LinkKind::Iceoryx2)?;
                loops.push(loop_result(name, s)?);
                self.stopped()?;
            }
            // Let the last messages land.
            std::thread::sleep(std::time::Duration::from_millis(200));
            Ok(Some(viewer.received()))
        }
        #[cfg(not(feature = "zenoh"))]
        {
            let _ = (sc, loops);
            Ok(None)
        }
    }

    /// The loops across the two namespaces (which share the CPUs: not pinned).
    /// Zenoh in clear and over mutual TLS (with a throwaway PKI for the two hosts,
    /// where `openssl` is installed), and UDP.
    fn across_hosts(&self, sc: &Scenario, pair: &Pair) -> Result<Vec<LoopResult>, Error> {
        let mut loops = Vec::new();
        let tls = if zenoh_built(LinkKind::Zenoh) {
            match tactile_launch::pki::make(&self.args.out.join("pki"), "bench", &pair.addrs) {
                Ok(files) => Some(files),
                Err(e) => {
                    tactile_launch::noteln!("tactile bench: no TLS loop: {e}");
                    None
                }
            }
        } else {
            None
        };
        let links = |name: &str| match (name, &tls) {
            ("zenoh-tls-hosts", Some(t)) => Some(tactile_launch::Links::across_tls(pair, t)),
            ("zenoh-tls-hosts", None) => None,
            ("zenoh-hosts", _) => Some(tactile_launch::Links::across(LinkKind::Zenoh, pair)),
            _ => Some(tactile_launch::Links::across(LinkKind::Udp, pair)),
        };
        for (name, link) in [
            ("zenoh-hosts", LinkKind::Zenoh),
            ("zenoh-tls-hosts", LinkKind::Zenoh),
            ("udp-hosts", LinkKind::Udp),
        ]
        .into_iter()
        .filter(|&(_, l)| zenoh_built(l))
        {
            let Some(links) = links(name) else { continue };
            let rate = sc.rate_hz;
            tactile_launch::noteln!(
                "tactile bench: {rate} Hz: {name} loop, master in {}, emulator and slave in {}",
                pair.names[0],
                pair.names[1]
            );
            let wrap = [pair.exec(0), pair.exec(1), pair.exec(1)];
            debug_assert_eq!(links.kind, link);
            let out = self.args.out.join(format!("{name}-{rate}"));
            let sup = Supervision {
                pin: false,
                ..self.sup.clone()
            };
            let s = trio_with(sc, &out, &sup, links, wrap)?;
            loops.push(loop_result(name, s)?);
            self.stopped()?;
        }
        Ok(loops)
    }

    /// The lockstep throughput and the machine's own stalls, with the rates' results.
    fn finish(&self, rates: Vec<RateResult>) -> Result<BenchReport, Error> {
        tactile_launch::noteln!("tactile bench: lockstep throughput");
        let n = self.args.lockstep_samples;
        let sc = scenario(1000.0, n, Mode::Lockstep)?;
        let lock = trio(
            &sc,
            &self.args.out.join("lockstep"),
            &self.sup,
            LinkKind::Iceoryx2,
        )?;
        let machine = if self.args.probe_s > 0.0 {
            let s = self.args.probe_s;
            tactile_launch::noteln!("tactile bench: the machine's own stalls, {s} s per CPU");
            stalls::probe(s, true, self.stop)
        } else {
            stalls::StallReport {
                note: Some("not probed (--probe-s 0)".into()),
                ..Default::default()
            }
        };
        self.stopped()?;
        Ok(BenchReport {
            machine,
            lockstep_samples_per_s: lock.master.samples_per_s,
            lockstep_samples: n,
            strategy: strategy(self.args),
            rates,
        })
    }
}

/// The waiting and scheduling every loop of the bench gets, in words.
fn strategy(args: &BenchArgs) -> String {
    format!(
        "every loop: {}, each node sleeping until {} before its sample is due, then polling (yielding) for {} before it blocks{}",
        match (args.nodes.sched, args.nodes.idle) {
            (tactile_runtime::sched::Policy::Fifo, tactile_runtime::sched::IdleMode::Poll) => {
                "SCHED_FIFO where permitted (memory locked, each CPU kept awake while its node sleeps)"
            }
            (tactile_runtime::sched::Policy::Fifo, tactile_runtime::sched::IdleMode::Halt) => {
                "SCHED_FIFO where permitted (memory locked)"
            }
            (tactile_runtime::sched::Policy::Other, _) => "SCHED_OTHER",
        },
        args.nodes.wake_early_us
            .map_or_else(|| "200 us (at most 40 % of a period)".to_string(), |u| format!("{u} us")),
        args.nodes.spin_us
            .map_or_else(|| "twice that".to_string(), |u| format!("{u} us")),
        if args.nodes.no_pin {
            ""
        } else {
            "; master on CPU 0, emulator and slave on CPU 1 (one host)"
        }
    )
}

/// `percentiles-RATE.svg`: every loop's overhead by percentile, from its report's
/// `overhead.hgrm`, side by side.
fn percentile_plot(out: &Path, rate: f64, loops: &[LoopResult]) -> Result<(), Error> {
    let mut series = Vec::new();
    for l in loops {
        let file = out.join(format!("{}-{rate}", l.name)).join("overhead.hgrm");
        let text = std::fs::read_to_string(&file)
            .map_err(Error::io(format!("reading {}", file.display())))?;
        series.push((l.name.clone(), tactile_report::plots::read_hgrm(&text)));
    }
    tactile_report::plots::percentile_plot(
        &out.join(format!("percentiles-{rate}.svg")),
        &format!("System overhead by percentile, {rate} Hz"),
        &series,
    )
    .map_err(|e| Error::Failed(format!("plotting percentiles: {e}")))
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
        let _ = writeln!(t, "{}  misses  lost", us_header());
        for l in &x.loops {
            let _ = writeln!(
                t,
                "{}  {}  {}",
                us_line(&format!("{} loop", l.name), l.overhead_ns.as_ref()),
                l.deadline_misses,
                l.samples_lost
            );
        }
        let _ = writeln!(
            t,
            "{}  {}",
            us_line("bare iceoryx2 (2 hops)", x.bare_hop_round_trip_ns.as_ref()),
            x.bare_hop_deadline_misses
        );
        if let Some(m) = x.live_messages {
            let _ = writeln!(t, "live view: {m} messages reached the viewer");
        }
        for (k, [p50, p99, p999]) in &x.ratios {
            let _ = writeln!(t, "{k}: p50 {p50:.2}, p99 {p99:.2}, p99.9 {p999:.2}");
        }
        if let Some(l) = x.loops.first() {
            let _ = writeln!(t, "{} loop stages:", l.name);
            for (name, p) in &l.stages_ns {
                let _ = writeln!(t, "{}", us_line(&format!("  {name}"), Some(p)));
            }
        }
    }
    let _ = writeln!(
        t,
        "\nlockstep throughput: {:.0} samples/s over {} samples",
        r.lockstep_samples_per_s, r.lockstep_samples
    );
    let _ = write!(
        t,
        "\nthe machine's own stalls:\n{}",
        stalls::render(&r.machine)
    );
    t
}
