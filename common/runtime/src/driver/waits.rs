//! Every wait a node makes before its loop runs, in one shape: it says what it waits
//! for (in the log at once and every 5 s), ends at a stop request, and has a deadline
//! (or says it has none).

use super::Failure;
use std::time::{Duration, Instant};

/// How a wait ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Waited {
    /// What it waited for came.
    Ready,
    /// A stop request came first.
    Stopped,
    /// The deadline passed first.
    TimedOut,
}

/// How often a wait says it still waits.
pub const NOTE_EVERY: Duration = Duration::from_secs(5);

/// Says in the log, every [`NOTE_EVERY`], that the wait for `who` goes on.
#[derive(Debug)]
pub struct Notes {
    who: String,
    start: Instant,
    limit: Option<Duration>,
    next: Duration,
}

impl Notes {
    /// Starts the notes (and logs that the wait for `who` begins).
    pub fn new(who: &str, limit: Option<Duration>) -> Notes {
        tracing::info!("waiting for {who}");
        Notes {
            who: who.to_string(),
            start: Instant::now(),
            limit,
            next: NOTE_EVERY,
        }
    }

    /// True once the deadline passed.
    pub fn timed_out(&self) -> bool {
        self.limit.is_some_and(|t| self.start.elapsed() > t)
    }

    /// Logs a line if one is due.
    pub fn tick(&mut self) {
        let e = self.start.elapsed();
        if e > self.next {
            match self.limit {
                Some(t) => tracing::info!(
                    "still waiting for {} ({:.0} s of {:.0} s)",
                    self.who,
                    e.as_secs_f64(),
                    t.as_secs_f64()
                ),
                None => tracing::info!(
                    "still waiting for {} ({:.0} s, no deadline)",
                    self.who,
                    e.as_secs_f64()
                ),
            }
            self.next += NOTE_EVERY;
        }
    }
}

/// Waits until `ready()`, a stop request, or `limit` (None: as long as it takes),
/// looking every 10 ms.
pub fn until(
    who: &str,
    limit: Option<Duration>,
    ready: &dyn Fn() -> bool,
) -> Result<Waited, Failure> {
    until_doing(who, limit, ready, &mut || Ok(()))
}

/// [`until`], calling `meanwhile` at each look (a node answering its peers' probes
/// while it waits for its robot).
pub fn until_doing(
    who: &str,
    limit: Option<Duration>,
    ready: &dyn Fn() -> bool,
    meanwhile: &mut dyn FnMut() -> Result<(), Failure>,
) -> Result<Waited, Failure> {
    let mut notes = Notes::new(who, limit);
    loop {
        meanwhile()?;
        if ready() {
            return Ok(Waited::Ready);
        }
        if crate::signals::stop_requested() {
            return Ok(Waited::Stopped);
        }
        if notes.timed_out() {
            return Ok(Waited::TimedOut);
        }
        notes.tick();
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// While a node waits for its device or robot: once a second, if messages came, what
/// came and why the last were dropped, so a wait that never ends says why (a wrong
/// joint name, a unit that maps out of range) rather than only that it waits.
#[derive(Debug)]
pub struct Delivered {
    next: Instant,
    seen: (u64, u64),
    /// The newest reason a message was dropped.
    pub reason: Option<String>,
    /// Why nothing can come (the session reached nobody), as last said in the log.
    pub unreached: Option<String>,
}

impl Default for Delivered {
    fn default() -> Self {
        Delivered {
            next: Instant::now() + Duration::from_secs(1),
            seen: (0, 0),
            reason: None,
            unreached: None,
        }
    }
}

impl Delivered {
    /// Looks at `p`'s counters if a second passed, and logs what changed.
    pub fn tick(&mut self, p: &dyn tactile_peripheral::Peripheral) {
        if Instant::now() < self.next {
            return;
        }
        self.next += Duration::from_secs(1);
        let unreached = p.unreached();
        if unreached != self.unreached {
            match &unreached {
                Some(why) => tracing::warn!("{} cannot come yet: {why}", p.describe()),
                None => tracing::info!("the ROS 2 session reached a router or a peer"),
            }
            self.unreached = unreached;
        }
        if let Some(r) = p.take_reject() {
            self.reason = Some(r.to_string());
        }
        let c = p.counters();
        if (c.messages, c.rejected) != self.seen {
            tracing::warn!(
                "{} while waiting: {} messages, {} dropped{}",
                p.describe(),
                c.messages,
                c.rejected,
                self.reason
                    .as_ref()
                    .map_or(String::new(), |r| format!(" (last: {r})"))
            );
            self.seen = (c.messages, c.rejected);
        }
    }

    /// `; the last dropped: ...` for a message, or nothing.
    pub fn why(&self) -> String {
        self.reason
            .as_ref()
            .map_or(String::new(), |r| format!("; the last dropped: {r}"))
    }

    /// What to say when nothing came from `p`: the session reached nobody, or (it did)
    /// the driver's side to check.
    pub fn nothing_came(&self, p: &dyn tactile_peripheral::Peripheral) -> String {
        match p.unreached() {
            Some(why) => format!(": {why}"),
            None => ": the session reached a router or a peer; is the driver running, with the same ROS_DOMAIN_ID, publishing on that topic?".into(),
        }
    }
}
