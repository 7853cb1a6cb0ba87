//! The live view: a node's state as ROS 2 topics while it runs, at a set rate, never
//! blocking the loop. The loop offers the state every k-th sample into a queue of a
//! few; a publisher thread encodes and puts it. A full queue drops the offer and
//! counts it: the view thins out, the loop keeps its time.

use crate::device::LiveSink;
use crate::link::LinkError;
use crate::ros2::{wall_ns, RosNode, RosPublisher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, SyncSender, TrySendError};
use std::sync::Arc;
use tactile_ros::live::LiveState;

/// States the queue holds before offers are dropped.
const QUEUE: usize = 4;

/// The live view of one node.
#[derive(Debug)]
pub struct LiveView<S: LiveState> {
    tx: Option<SyncSender<S>>,
    every: u64,
    dropped: Arc<AtomicU64>,
    published: Arc<AtomicU64>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl<S: LiveState> LiveView<S> {
    /// Declares the topics on `node` and starts the publisher thread; every `every`-th
    /// sample is published.
    pub fn start(node: Arc<RosNode>, every: u64) -> Result<LiveView<S>, LinkError> {
        let pubs: Vec<RosPublisher> = S::TOPICS
            .iter()
            .map(|(topic, ty)| node.publisher(&node.in_namespace(topic), ty))
            .collect::<Result<_, _>>()?;
        let (tx, rx) = sync_channel::<S>(QUEUE);
        let published = Arc::new(AtomicU64::new(0));
        let count = Arc::clone(&published);
        let thread = std::thread::Builder::new()
            .name("live-view".into())
            .spawn(move || {
                // Below the loop: a SCHED_FIFO node's threads inherit its policy, and
                // the view must wait for the loop, never the loop for the view.
                if let Err(e) = crate::sched::set_thread_other() {
                    tracing::warn!("the live view's thread stays at the node's priority: {e}");
                }
                let _node = node;
                for state in rx {
                    let msgs = state.encode(wall_ns());
                    for (p, m) in pubs.iter().zip(&msgs) {
                        if p.put(m) {
                            count.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                }
            })
            .map_err(|e| LinkError {
                context: "starting the live view".into(),
                detail: e.to_string(),
            })?;
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

impl<S: LiveState> LiveSink<S> for LiveView<S> {
    fn due(&self, n: u64) -> bool {
        n % self.every == 0
    }

    fn offer(&mut self, state: S) {
        if let Some(tx) = &self.tx {
            if let Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) = tx.try_send(state) {
                self.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

impl<S: LiveState> Drop for LiveView<S> {
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

/// A node's ROS 2 side for one run: the node (its session carries everything below),
/// its device or robot if the scenario has one, and the live view if it is on.
#[derive(Debug)]
pub struct RosSide<D, S: LiveState> {
    _node: Arc<RosNode>,
    /// The device or robot.
    pub device: Option<D>,
    /// The live view.
    pub live: Option<LiveView<S>>,
}

impl<D, S: LiveState> RosSide<D, S> {
    /// Opens node `name` on `[ros]`, the device with `device` if given, and the live
    /// view if `ros.live` is on.
    pub fn open(
        sc: &tactile_scenario::Scenario,
        name: &str,
        device: Option<impl FnOnce(&RosNode) -> Result<D, LinkError>>,
    ) -> Result<Self, LinkError> {
        let node = Arc::new(RosNode::open(&sc.ros, name)?);
        let device = device.map(|open| open(&node)).transpose()?;
        let live = if sc.ros.live.enabled {
            Some(LiveView::start(
                Arc::clone(&node),
                every(sc.rate_hz, sc.ros.live.rate_hz),
            )?)
        } else {
            None
        };
        Ok(RosSide {
            _node: node,
            device,
            live,
        })
    }
}
