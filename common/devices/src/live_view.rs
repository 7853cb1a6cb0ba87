//! The live view: a node's state as ROS 2 topics while it runs, at a set rate, never
//! blocking the loop. The loop offers the state every k-th sample into a queue of a
//! few; a publisher thread encodes and puts it. A full queue drops the offer and
//! counts it: the view thins out, the loop keeps its time.

use crate::live_arm::{ArmPublishers, LiveArm};
use crate::rmw_node::{wall_ns, RosNode, RosPublisher};
use crate::{LiveSink, RosError};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, SyncSender, TrySendError};
use std::sync::Arc;
use tactile_ros::view::{At, SampleView, Sink, Typed};
use tactile_ros::{CdrWriter, Message};

/// States the queue holds before offers are dropped.
const QUEUE: usize = 4;

/// The live view of one node.
#[derive(Debug)]
pub struct LiveView {
    tx: Option<SyncSender<SampleView>>,
    every: u64,
    dropped: Arc<AtomicU64>,
    published: Arc<AtomicU64>,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// The live view's publishers, by their topic's place in `tactile_ros::topics::TOPICS`.
struct Publishers {
    by_topic: Vec<Option<RosPublisher>>,
    cdr: CdrWriter,
    published: u64,
}

impl Sink for Publishers {
    type Error = std::convert::Infallible;
    fn put<M: Message>(&mut self, t: Typed<M>, _: At, m: &M) -> Result<(), Self::Error> {
        if let Some(Some(p)) = self.by_topic.get(t.index()) {
            self.cdr.reset();
            m.encode(&mut self.cdr);
            self.published += u64::from(p.put(self.cdr.bytes()));
        }
        Ok(())
    }
}

impl LiveView {
    /// Declares `topics` (places in `tactile_ros::topics::TOPICS`) on `node` and starts
    /// the publisher thread; every `every`-th sample is published. A simulated URDF
    /// `arm` is served as `robot_state_publisher` serves a robot ([`ArmPublishers`]). The thread first calls `below_loop`, which puts it below
    /// the loop's scheduling (a SCHED_FIFO node's threads inherit its policy, and the
    /// view must wait for the loop, never the loop for the view).
    pub fn start(
        node: Arc<RosNode>,
        every: u64,
        below_loop: fn() -> std::io::Result<()>,
        topics: &[usize],
        arm: Option<LiveArm>,
    ) -> Result<LiveView, RosError> {
        let arm = arm.map(|a| ArmPublishers::start(&node, a)).transpose()?;
        let mut by_topic: Vec<Option<RosPublisher>> = Vec::new();
        for &i in topics {
            let t = &tactile_ros::topics::TOPICS[i];
            by_topic.resize_with(by_topic.len().max(i + 1), || None);
            by_topic[i] = Some(node.publisher(&node.in_namespace(t.name), t.ty)?);
        }
        let mut pubs = Publishers {
            by_topic,
            cdr: CdrWriter::new(),
            published: 0,
        };
        let (tx, rx) = sync_channel::<SampleView>(QUEUE);
        let published = Arc::new(AtomicU64::new(0));
        let count = Arc::clone(&published);
        let thread = std::thread::Builder::new()
            .name("live-view".into())
            .spawn(move || {
                if let Err(e) = below_loop() {
                    tracing::warn!("the live view's thread stays at the node's priority: {e}");
                }
                let _node = node;
                for state in rx {
                    let before = pubs.published;
                    let stamp = wall_ns();
                    let Ok(()) = state.emit(stamp, &mut pubs);
                    if let (Some(a), Some(s)) = (&arm, &state.arm) {
                        pubs.published += u64::from(a.put_tf(stamp, s));
                    }
                    count.fetch_add(pubs.published - before, Ordering::Relaxed);
                }
            })
            .map_err(|e| RosError::new("starting the live view", e))?;
        Ok(LiveView {
            tx: Some(tx),
            every: every.max(1),
            dropped: Arc::new(AtomicU64::new(0)),
            published,
            thread: Some(thread),
        })
    }

    /// `(messages published, states dropped)` so far.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.published.load(Ordering::Relaxed),
            self.dropped.load(Ordering::Relaxed),
        )
    }
}

impl LiveSink<SampleView> for LiveView {
    fn due(&self, n: u64) -> bool {
        n.is_multiple_of(self.every)
    }

    fn offer(&mut self, state: SampleView) {
        if let Some(tx) = &self.tx {
            if let Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) = tx.try_send(state) {
                self.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        let (published, dropped) = self.counts();
        tracing::info!(
            "live view: {published} messages published, {dropped} states dropped (the publisher behind)"
        );
    }
}

/// Every how many samples the live view publishes: round(loop rate / live rate), at
/// least 1.
pub fn every(rate_hz: f64, live_hz: f64) -> u64 {
    ((rate_hz / live_hz).round() as u64).max(1)
}
