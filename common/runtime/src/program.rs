//! A node program from its checks to its exit: the three node programs are each this,
//! with their own handler. [`Program::prepare`] checks everything a user controls
//! before anything starts (bad input: exit 2); [`Program::follow`] and
//! [`Program::lead`] start the record, open the node's ends, have the node open its own
//! peripherals (device, robot, live view) and make its handler, and run the driver;
//! every failure after the record started is in it.

use crate::args::{NodeArgs, NodeError};
use crate::driver::follow::Follow;
use crate::driver::lead::{Lead, LeadOptions};
use crate::driver::{Failure, Follower, Handler, Leader, Link, OnTransports, Timing};
use crate::start::{new_run_token, prepare, start_record, Links, Prepared};
use std::time::Duration;
use tactile_messages::Role;
use tactile_peripheral::LiveSink;
use tactile_records::{Events, Recorder};
use tactile_ros::view::SampleView;
use tactile_scenario::Scenario;

/// A node program that passed its checks.
#[derive(Debug)]
pub struct Program {
    role: Role,
    args: NodeArgs,
    links: Links,
    prepared: Prepared,
}

/// A node's live view, as the driver takes it.
pub type Live = Box<dyn LiveSink<SampleView>>;

/// What a node hands its driver: its handler (holding the device or robot the node
/// opened, if any) and its live view. The node opens them (it knows its arm or
/// gimbal); the runtime only drives them, through `tactile-peripheral`'s traits.
pub struct Opened<H> {
    /// The node's handler.
    pub handler: H,
    /// The live view, when `[ros.live]` asks for one.
    pub live: Option<Live>,
}

impl<H> std::fmt::Debug for Opened<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Opened")
            .field("live", &self.live.is_some())
            .finish_non_exhaustive()
    }
}

impl<H> Opened<H> {
    /// A handler without a live view.
    pub fn alone(handler: H) -> Opened<H> {
        Opened {
            handler,
            live: None,
        }
    }
}

/// What a node's handler is made from, once the record started and its ends are
/// open: a failure here is recorded.
pub type Make<'a, H> = Box<dyn FnOnce(&Prepared) -> Result<Opened<H>, NodeError> + 'a>;

impl Program {
    /// Checks the arguments, the scenario and the prefix, takes the role's lock,
    /// installs the log, schedules the node (see [`prepare`]).
    pub fn prepare(role: Role, args: &NodeArgs, links: Links) -> Result<Program, NodeError> {
        let prepared = prepare(role, args, &links)?;
        Ok(Program {
            role,
            args: args.clone(),
            links,
            prepared,
        })
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.prepared.scenario
    }

    /// What the checks found.
    pub fn prepared(&self) -> &Prepared {
        &self.prepared
    }

    /// The record, started.
    fn record<H: Handler>(&self) -> Result<Recorder<H::Sample, H::Totals>, NodeError> {
        let failed = |e: tactile_records::WriteError| NodeError::Failed(e.to_string());
        // `--append` to a file that is no record of this format: bad input, as the
        // docs say (exit 2), the file untouched.
        let mut rec = Recorder::open(&self.args.out, self.role, self.args.append).map_err(|e| {
            match e.source.kind() {
                std::io::ErrorKind::InvalidData => NodeError::BadInput(e.to_string()),
                _ => failed(e),
            }
        })?;
        let start = start_record(self.role, &self.args, &self.links, &self.prepared);
        rec.start(start).map_err(failed)?;
        Ok(rec)
    }

    /// The node's ends, and its handler and live view as the node opened them; a
    /// failure is recorded.
    fn open<H: Handler>(
        &self,
        rec: &mut Recorder<H::Sample, H::Totals>,
        make: Make<'_, H>,
    ) -> Result<(Link, Opened<H>), NodeError> {
        let opened = (|| {
            let links = self.links;
            let ports = tactile_transport::ports::open(
                self.role,
                &self.args.link,
                |s| links.of(s),
                links.direct,
            )
            .map_err(|e| NodeError::Failed(e.to_string()))?;
            let opened = make(&self.prepared)?;
            Ok((Link::new(ports, self.prepared.spin), opened))
        })();
        if let Err(e) = &opened {
            let _ = rec.event(0, &format!("failed: {e}"));
            let _ = rec.stop(
                H::Totals::default(),
                crate::sys::max_rss_kb(),
                &format!("failed: {e}"),
            );
        }
        opened
    }

    fn timing(&self) -> Timing {
        Timing::of(&self.prepared.scenario, self.prepared.wake_early)
    }

    /// Runs a follower (the emulator, the slave) until the master's end of the run
    /// (`Ok(true)`) or a stop request (`Ok(false)`).
    pub fn follow<H: Follower>(self, make: Make<'_, H>) -> Result<bool, NodeError> {
        let ended = (|| {
            let mut rec = self.record::<H>()?;
            let (link, o) = self.open(&mut rec, make)?;
            Follow::new(o.handler, link, rec, self.timing(), o.live)
                .run(&mut OnTransports)
                .map_err(failed)
        })();
        self.leave();
        ended
    }

    /// The node's lock given back and, if it was the last process of its run (a node
    /// started by hand; a launcher cleans up its own run), the run's shared memory and
    /// iceoryx2 files removed, however the node ended.
    fn leave(self) {
        let prefix = self.args.link.prefix.clone();
        drop(self.prepared);
        if let Some(locks) = crate::lock::take_all(&prefix, "a node cleaning up after its run") {
            tactile_transport::ipc::remove_run_files(&prefix);
            drop(locks);
        }
    }

    /// Runs the leader (the master) until every sample was sent (`Ok(true)`) or a
    /// stop request (`Ok(false)`); `startup_timeout` bounds the waits for the device
    /// and the peers.
    pub fn lead<H: Leader>(
        self,
        startup_timeout: Duration,
        make: Make<'_, H>,
    ) -> Result<bool, NodeError> {
        let ended = (|| {
            let mut rec = self.record::<H>()?;
            let (link, o) = self.open(&mut rec, make)?;
            let opts = LeadOptions {
                run: new_run_token(),
                samples: self.prepared.scenario.samples,
                startup_timeout,
                // Lockstep only (realtime waits for the next tick): drops come as
                // the emulator's notice, so this waits out only a peer that is gone
                // or stalled; at 100 ms a loaded machine's stall counted as a miss
                // and lockstep traces differed from run to run.
                answer_timeout: Duration::from_secs(1),
                timing: self.timing(),
            };
            Lead::new(o.handler, link, rec, opts, o.live)
                .run(&mut OnTransports)
                .map_err(failed)
        })();
        self.leave();
        ended
    }
}

fn failed(e: Failure) -> NodeError {
    NodeError::Failed(e.to_string())
}
