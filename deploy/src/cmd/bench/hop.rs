//! The bare iceoryx2 hop: a ping-pong between the bench and an echo process (two
//! hops, no computing), the floor any loop over iceoryx2 stands on.

use crate::error::Error;
use crate::launch::Supervision;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tactile_messages::clock::{now_ns, sleep_until_ns};
use tactile_messages::samples::{Forward, FLAG_END, FLAG_PROBE};
use tactile_node::ipc::{self, Inbox, Outbox, Waker};
use tactile_node::link::{Idle, LinkError, WaitPolicy};
use tactile_report::analysis::Latency;

/// The echo side of the bare hop: sends back every sample it gets, until the end mark.
pub fn echo(prefix: &str, wait: WaitPolicy) -> Result<(), LinkError> {
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

/// The bare hop's poll budget: as given, else two periods (it has no pacer).
fn hop_spin(sup: &Supervision, rate: f64) -> Duration {
    sup.spin
        .unwrap_or_else(|| Duration::from_nanos((2e9 / rate) as u64))
}

/// Ping-pong with an echo process at `rate` for `n` round trips.
pub fn bare_hop(rate: f64, n: u64, sup: &Supervision) -> Result<(Latency, u64), Error> {
    let prefix = format!("{}h", sup.prefix);
    // Held while the hop runs, so no cleaner takes its shared memory for a dead run's.
    let _lock = tactile_node::lock::take(&prefix, "run", "tactile bench's bare hop")
        .map_err(Error::BadInput)?;
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
        .arg(hop_spin(sup, rate).as_micros().to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| Error::Failed(format!("starting the echo process: {e}")))?;
    let saved_affinity = rustix::thread::sched_getaffinity(None).ok();
    let result = (|| -> Result<(Latency, u64), Error> {
        let fail = |e: LinkError| Error::Failed(e.to_string());
        if sup.pin {
            let _ = tactile_node::sched::pin_thread(0);
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
            sleep_until_ns(tick.saturating_sub(tactile_node::pace::default_wake_early_ns(t_s)));
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
                    .wait(&node, hop_spin(sup, rate), deadline, || inbox.try_recv())
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
