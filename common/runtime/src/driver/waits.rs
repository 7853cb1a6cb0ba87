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
