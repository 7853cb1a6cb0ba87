//! The network emulator's per-sample logic: both channels of the paper's NW subsystem.
//!
//! Forward, v_i(n) = c_i(n - d^f_i(n)) + r^f_i(n); backward, q_i(n) = h_i(n - d^b_i(n)) +
//! r^b_i(n). Each arriving sample is pushed through its [`Channel`]; what comes out
//! keeps the sample number and stamps of the sample that triggered it, with values (and
//! their provenance) taken from the delayed one. The noise added is recorded in the
//! sample so reports can separate it from the signal.

use serde::{Deserialize, Serialize};
use tactile_common::channel::{Channel, Value, BACKWARD_STREAM, FORWARD_STREAM};
use tactile_common::samples::{Backward, Forward, Signal, FLAG_SUBSTITUTED};
use tactile_common::scenario::Scenario;

/// What the emulator counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorCounters {
    /// Forward samples passed.
    pub forward: u64,
    /// Backward samples passed.
    pub backward: u64,
    /// Forward samples with a value substituted (delay line not yet filled).
    pub forward_substituted: u64,
    /// Backward samples with a value substituted.
    pub backward_substituted: u64,
}

/// Both channels.
#[derive(Debug)]
pub struct Emulator {
    forward: Channel,
    backward: Channel,
    counters: EmulatorCounters,
}

fn values(s: &Signal) -> [Value; 3] {
    [0, 1, 2].map(|i| Value {
        v: s.value[i],
        origin_seq: s.origin_seq[i],
        origin_ns: s.origin_ns[i],
        delay_samples: s.delay_samples[i],
    })
}

fn apply(s: &mut Signal, e: &tactile_common::channel::Emitted) {
    for i in 0..3 {
        s.value[i] = e.values[i].v;
        s.origin_seq[i] = e.values[i].origin_seq;
        s.origin_ns[i] = e.values[i].origin_ns;
        s.delay_samples[i] = e.values[i].delay_samples;
    }
    s.noise = e.noise;
    if e.substituted {
        s.flags |= FLAG_SUBSTITUTED;
    }
}

impl Emulator {
    /// Channels as the scenario configures them, seeded from its seed.
    pub fn new(scenario: &Scenario) -> Emulator {
        Emulator {
            forward: Channel::new(&scenario.network.forward, scenario.seed, FORWARD_STREAM),
            backward: Channel::new(&scenario.network.backward, scenario.seed, BACKWARD_STREAM),
            counters: EmulatorCounters::default(),
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> EmulatorCounters {
        self.counters
    }

    /// c(n) in, v(n) out.
    pub fn forward(&mut self, c: &Forward) -> Forward {
        let e = self.forward.push(c.seq, values(&c.signal));
        let mut v = *c;
        apply(&mut v.signal, &e);
        self.counters.forward += 1;
        self.counters.forward_substituted += u64::from(e.substituted);
        v
    }

    /// h(n) in, q(n) out.
    pub fn backward(&mut self, h: &Backward) -> Backward {
        let e = self.backward.push(h.seq, values(&h.signal));
        let mut q = *h;
        apply(&mut q.signal, &e);
        self.counters.backward += 1;
        self.counters.backward_substituted += u64::from(e.substituted);
        q
    }
}
