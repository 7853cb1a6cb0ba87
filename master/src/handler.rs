//! What the master does with its samples, as the loop's driver hands them over
//! (`tactile_runtime::driver`): c(n) from the simulated hand and device or the real
//! device's encoders, q(n) into torques and the force felt, what it does when q(n)
//! does not come, and what goes back to a real device. The driver owns the pacing,
//! the waits and the protocol; [`Master`] owns the signals.

use crate::hmd::{DeviceReading, Input, Master};
use tactile_devices::held::Held;
use tactile_devices::{Change, HapticDevice, Peripheral};
use tactile_messages::samples::{stage, Backward, Forward};
use tactile_records::master::{MasterCounters, MasterSample, MasterTotals, Sent};
use tactile_ros::msg::SampleTiming;
use tactile_ros::view::{MasterView, SampleView};
use tactile_runtime::driver::{changed, Counts, Failure, Handler, Io, Leader};

/// The master's handler: its state machine, the real device if there is one, and what
/// it keeps between the driver's calls.
pub struct MasterHandler {
    master: Master,
    device: Option<Box<dyn HapticDevice>>,
    /// The real device's reading as the loop holds it.
    held: Held<tactile_devices::hand::Hand>,
    peer_timeout: u64,
    /// The sample in hand, as it went out.
    sent: Sent,
    /// The last answer as the live view shows it: its sample, q(n)'s value and its
    /// timing (an answer's record is 336 bytes, copied here at every answer before).
    heard: Option<(u64, [f64; 3], SampleTiming)>,
    /// The force the operator was last made to feel (zero while the device is lost).
    felt: [f64; 3],
    clamps_seen: (u64, u64),
}

impl std::fmt::Debug for MasterHandler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MasterHandler")
            .field("device", &self.device.as_ref().map(|d| d.describe()))
            .finish_non_exhaustive()
    }
}

impl MasterHandler {
    /// The handler of `master`, with a real device (`None`: the simulated one);
    /// `peer_timeout`: samples without an answer before the loop counts as broken.
    pub fn new(master: Master, device: Option<Box<dyn HapticDevice>>, peer_timeout: u64) -> Self {
        MasterHandler {
            master,
            device,
            held: Held::default(),
            peer_timeout,
            sent: Sent::default(),
            heard: None,
            felt: [0.0; 3],
            clamps_seen: (0, 0),
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> MasterCounters {
        self.master.counters()
    }
}

impl Handler for MasterHandler {
    type Sample = MasterSample;
    type Totals = MasterTotals;

    fn totals(&self, c: &Counts) -> MasterTotals {
        MasterTotals {
            counters: self.master.counters(),
            deadline_misses: c.deadline_misses,
            late: c.late,
            unexpected: c.unexpected,
            c_out: c.ports.forward_out,
            q_in: c.ports.backward_in,
            elapsed_ns: c.elapsed_ns,
            device: self
                .device
                .as_ref()
                .map(|d| d.counters())
                .unwrap_or_default(),
        }
    }

    /// The force and torque clamps of the last second, if any (at most one line a
    /// second, however often the device saturates).
    fn log_second(&mut self, t: &MasterTotals) {
        let c = &t.counters;
        let now = (c.force_clamps, c.torque_clamps);
        if let Some((last, all)) = changed(&mut self.clamps_seen, now) {
            tracing::info!(
                "clamped to the device limits: {} force and {} torque components in the last second ({} and {} in all)",
                last.0, last.1, all.0, all.1
            );
        }
    }

    fn peripheral(&self) -> Option<&dyn Peripheral> {
        self.device.as_deref().map(|d| d as &dyn Peripheral)
    }

    fn release(&mut self) -> Option<String> {
        let d = self.device.as_deref_mut()?;
        let heard = d.release();
        Some(format!(
            "zero force sent to {}{}",
            d.describe(),
            if heard {
                ""
            } else {
                " (no driver was listening: it may hold its last force)"
            }
        ))
    }

    fn live(&self) -> Option<SampleView> {
        let s = &self.sent;
        let a = self.heard.filter(|(n, ..)| *n == s.n);
        let master = MasterView {
            theta: s.theta_md,
            velocity: None,
            tau: self.master.tau(),
            target: s.target,
            handle: s.handle,
            rotation: s.rotation.unwrap_or(tactile_ros::msg::IDENTITY),
            q: a.map_or([0.0; 3], |(_, q, _)| q),
            felt: self.felt,
        };
        let timing = SampleTiming {
            sample: s.n,
            answered: a.is_some(),
            ..a.map_or_else(SampleTiming::default, |(.., t)| t)
        };
        Some(SampleView {
            master: Some(master),
            timing: Some(timing),
            ..SampleView::default()
        })
    }
}

impl Leader for MasterHandler {
    /// b(n): the simulated hand and device, or the real device's newest angles (held
    /// while stale or lost; lost renders zero force).
    fn tick(
        &mut self,
        n: u64,
        origin_ns: u64,
        io: &mut Io,
        c: &mut Forward,
    ) -> Result<(), Failure> {
        let input = match self.device.as_deref_mut() {
            None => Input::Simulated,
            Some(d) => {
                let who = d.describe();
                let judged = d.read(io.now());
                if judged.1 == Change::Back {
                    // Back from a loss: the force rises from zero again, no jolt.
                    d.restart_ramp();
                }
                if let Some(what) = self
                    .held
                    .take(judged, ("device", &who), "rendering zero force")
                {
                    io.event(n, &what)?;
                }
                // A lost device's clutch is released: the robot holds until the
                // device is back and the button says engaged.
                let clutch = d.clutch().map(|c| c && !self.held.lost);
                Input::Device(DeviceReading {
                    hand: self.held.taken.then_some(self.held.theta),
                    kind: d.input(),
                    clutch,
                })
            }
        };
        self.master
            .forward(n, origin_ns, input, (c, &mut self.sent));
        Ok(())
    }

    fn sent(&mut self, c: &Forward) -> MasterSample {
        self.sent.send_ns = c.stamps[stage::MASTER_SEND];
        MasterSample::Sent(self.sent)
    }

    /// KFF-HMD on q(n); its round trip on the master's clock.
    fn answer(
        &mut self,
        q: &Backward,
        late: bool,
        io: &mut Io,
        record: &mut Option<MasterSample>,
    ) -> Result<(), Failure> {
        if self.master.peer_lost() {
            io.event(q.seq, "loop resumed: answers are back")?;
            if let Some(d) = self.device.as_deref_mut() {
                d.restart_ramp();
            }
        }
        let mut a = self.master.backward(q);
        a.stamps[stage::MASTER_DONE] = io.now();
        self.master.account(&mut a);
        a.late = late;
        let timing = SampleTiming {
            round_trip_ns: a.round_trip_ns as i64,
            overhead_ns: a.overhead_ns,
            delay_backward: a.q.delay_samples,
            flags_backward: a.q.flags.bits(),
            flags_master: a.effect.flags.bits(),
            observer_master: a.effect.observer,
            ..SampleTiming::default()
        };
        self.heard = Some((a.n, a.q.value, timing));
        *record = Some(MasterSample::Answer(a));
        Ok(())
    }

    /// Hold or zero the torque, and say so when the loop breaks.
    fn miss(&mut self, n: u64, io: &mut Io) -> Result<MasterSample, Failure> {
        let was_lost = self.master.peer_lost();
        let m = self.master.missing(n);
        if self.master.peer_lost() && !was_lost {
            let dead = io.dead_peers();
            let what = if dead.is_empty() {
                format!(
                    "loop broken: no answer for {} samples; zero torque",
                    self.peer_timeout
                )
            } else {
                format!(
                    "loop broken: no answer for {} samples, dead: {}; zero torque",
                    self.peer_timeout,
                    dead.join(", ")
                )
            };
            tracing::warn!("{what}");
            io.event(n, &what)?;
        }
        Ok(MasterSample::Miss(m))
    }

    /// The force to the real device: zero while it is lost.
    fn after(&mut self, _n: u64) {
        self.felt = if self.held.lost {
            [0.0; 3]
        } else {
            self.master.felt()
        };
        if let Some(d) = self.device.as_deref_mut() {
            d.render(self.felt, tactile_messages::clock::now_ns());
        }
    }
}
