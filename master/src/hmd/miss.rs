//! [`Master`]'s answers that did not come (held, or the loop broken) and the round trip
//! of those that did: the part of the backward path that runs without a q(n).

use super::switch::Rendering;
use super::Master;
use tactile_control::codec::Estimate;
use tactile_messages::samples::{stage, Flags};
use tactile_records::master::{Answer, Miss};

impl Master {
    /// Sample n got no answer in time. Within the peer timeout the last force is held
    /// (one lost sample must not jerk the operator's hand; with waves, the last wave
    /// against the present velocity); past it the loop is broken and the master
    /// commands zero torque.
    pub fn missing(&mut self, n: u64) -> Miss {
        self.silent += 1;
        let (flags, out) = if self.peer_lost() {
            if self.silent == self.peer_timeout {
                self.counters.loop_breaks += 1;
            }
            self.counters.peer_lost_samples += 1;
            let out = self.control.release();
            self.last_tau = [0.0; 3];
            self.last_felt = self
                .switch
                .render(Rendering::Broken, [0.0; 3], self.last_felt);
            (Flags::PEER_LOST, out)
        } else {
            self.counters.held_samples += 1;
            let estimate = self.predictor.estimate(n, None);
            let flags = match estimate {
                Estimate::Refused(_) => Flags::HELD | Flags::GUESS_REFUSED,
                _ => Flags::HELD,
            };
            // MMT's model needs no answer: it is rendered against the handle as before.
            let guess = self.model_force(estimate.value());
            let out = self
                .control
                .receive(guess, [0.0; 3], self.limits.force_limit);
            self.command(&out);
            (flags, out)
        };
        Miss {
            n,
            effect: self.effect(flags, &out),
        }
    }

    /// Fills the answer's round trip and overhead from its final stamps: round trip is
    /// done-time minus the oldest origin among q's values, on the master's clock alone.
    pub fn account(&self, a: &mut Answer) {
        let done = a.stamps[stage::MASTER_DONE];
        let (i, origin) = (0..3)
            .map(|i| (i, a.q.origin_ns[i]))
            .min_by_key(|&(_, t)| t)
            .unwrap_or((0, 0));
        a.round_trip_ns = done.saturating_sub(origin);
        let injected = u64::from(a.q.delay_samples[i]) * self.t_s_ns;
        a.overhead_ns = a.round_trip_ns as i64 - injected as i64;
    }
}
