//! The bare iceoryx2 hop: a ping-pong between the bench and an echo process (two
//! hops, no computing), the floor any loop over iceoryx2 stands on.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tactile_launch::error::Error;
use tactile_launch::Supervision;
use tactile_messages::clock::{now_ns, sleep_until_ns};
use tactile_messages::samples::{Control, Forward};
use tactile_report::analysis::Latency;
use tactile_runtime::driver::{Arrival, Failure, Idle, Link, OnTransports};
use tactile_transport::ipc::{self, IpcPublisher, IpcSubscriber, IpcWake};
use tactile_transport::{LinkError, Ports};

/// One end of the hop: a stream in, one out, over iceoryx2, waited on as a node waits.
fn hop_end(prefix: &str, me: &str, peer: &str, spin: Duration) -> Result<Link, LinkError> {
    let node = std::rc::Rc::new(ipc::node(prefix, me)?);
    let (out, inn) = if me == "echo" {
        ("hop/pong", "hop/ping")
    } else {
        ("hop/ping", "hop/pong")
    };
    let ports = Ports {
        forward_in: Some(Box::new(IpcSubscriber::<Forward>::open(&node, inn)?)),
        forward_out: Some(Box::new(IpcPublisher::<Forward>::open(&node, out, peer)?)),
        wakes: vec![Box::new(IpcWake::open(&node, me)?)],
        ..Ports::default()
    };
    Ok(Link::new(ports, spin))
}

/// The echo side of the bare hop: sends back every sample it gets, until the end mark.
pub fn echo(prefix: &str, spin: Duration) -> Result<(), Failure> {
    tactile_runtime::signals::stop_flag().map_err(|e| Failure::Node(e.to_string()))?;
    let mut link = hop_end(prefix, "echo", "bench", spin)?;
    loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        match link.wait(deadline, &mut OnTransports)? {
            Ok(Arrival::Forward(f)) if f.control_kind() == Some(Control::End) => return Ok(()),
            Ok(Arrival::Forward(f)) => {
                link.send_forward(&f, f.control_kind().is_some())?;
            }
            Ok(Arrival::Backward(_)) | Err(Idle::Timeout) => {}
            Err(Idle::Stop) => return Ok(()),
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

/// The bare hop's poll budget: as given, else two periods (it has no pacer).
fn hop_spin(sup: &Supervision, rate: f64) -> Duration {
    sup.spin
        .unwrap_or_else(|| Duration::from_nanos((2e9 / rate) as u64))
}

/// Starts the echo process of the hop `prefix` (on CPU 1 when pinned).
fn spawn_echo(prefix: &str, rate: f64, sup: &Supervision) -> Result<std::process::Child, Error> {
    let exe = std::env::current_exe().map_err(Error::io("locating the tactile executable"))?;
    let mut cmd = if sup.pin {
        let mut c = Command::new("taskset");
        c.args(["-c", "1"]).arg(&exe);
        c
    } else {
        Command::new(&exe)
    };
    cmd.arg("bench-echo")
        .args(["--prefix", prefix, "--spin-us"])
        .arg(hop_spin(sup, rate).as_micros().to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| Error::Failed(format!("starting the echo process: {e}")))
}

fn fail(e: impl Into<Failure>) -> Error {
    Error::Failed(e.into().to_string())
}

/// Probes until the echo answers (10 s at most), then lets the echoes pass.
fn find_echo(link: &mut Link) -> Result<(), Error> {
    let start = Instant::now();
    loop {
        let p = Forward::control(Control::Probe, 0, 0);
        link.send_forward(&p, true).map_err(fail)?;
        let until = Instant::now() + Duration::from_millis(20);
        if link.wait(until, &mut OnTransports).map_err(fail)?.is_ok() {
            break;
        }
        if start.elapsed() > Duration::from_secs(10) {
            return Err(Error::Failed("the echo process did not answer".into()));
        }
    }
    while link.poll().map_err(fail)?.is_some() {}
    Ok(())
}

/// `n` pings at `rate`, each at its tick; the round trips and the misses (no pong
/// within a period). A stop request (SIGINT, SIGTERM) ends them at the next tick (a
/// wait it cut short is no miss), the echo told to end all the same.
fn ping(link: &mut Link, rate: f64, n: u64) -> Result<(Latency, u64), Error> {
    let t_s = (1e9 / rate) as u64;
    let t0 = now_ns() + 2_000_000;
    let mut lat = Latency::default();
    let mut misses = 0;
    let mut stopped = false;
    for i in 0..n {
        if tactile_runtime::signals::stop_requested() {
            stopped = true;
            break;
        }
        let tick = t0 + i * t_s;
        sleep_until_ns(tick.saturating_sub(tactile_runtime::pace::default_wake_early_ns(t_s)));
        while now_ns() < tick {
            std::hint::spin_loop();
        }
        let sent = now_ns();
        let ping = Forward {
            seq: i,
            ..Forward::default()
        };
        link.send_forward(&ping, false).map_err(fail)?;
        let deadline = Instant::now() + Duration::from_nanos(t_s);
        loop {
            match link.wait(deadline, &mut OnTransports).map_err(fail)? {
                Ok(Arrival::Forward(f)) if f.seq == i => {
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
    let end = Forward::control(Control::End, 0, 0);
    link.send_forward(&end, true).map_err(fail)?;
    if stopped {
        return Err(Error::Interrupted);
    }
    Ok((lat, misses))
}

/// Ping-pong with an echo process at `rate` for `n` round trips.
pub fn bare_hop(rate: f64, n: u64, sup: &Supervision) -> Result<(Latency, u64), Error> {
    let prefix = format!("{}h", sup.prefix);
    // Held while the hop runs, so no cleaner takes its shared memory for a dead run's.
    let _lock = tactile_runtime::lock::take(&prefix, "run", "tactile bench's bare hop")?;
    let mut child = spawn_echo(&prefix, rate, sup)?;
    let saved_affinity = rustix::thread::sched_getaffinity(None).ok();
    let result = (|| -> Result<(Latency, u64), Error> {
        if sup.pin {
            let _ = tactile_runtime::sched::pin_thread(0);
        }
        let _restore = Restore(saved_affinity);
        let mut link = hop_end(&prefix, "bench", "echo", Duration::ZERO).map_err(fail)?;
        find_echo(&mut link)?;
        let mut link = Link::new(link.into_ports(), hop_spin(sup, rate));
        ping(&mut link, rate, n)
    })();
    let _ = child.wait();
    ipc::remove_run_files(&prefix);
    result
}
