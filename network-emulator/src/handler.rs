//! What the emulator does with its samples, as the loop's driver hands them over
//! (`tactile_runtime::driver`): each c(n) and h(n) through its channel of
//! [`Emulator`], what comes out passed on. The driver owns the pacing (asleep until
//! c(n) is due, but never while an h(n) is due back), the waits and the protocol.

use crate::emulator::Emulator;
use tactile_messages::samples::{Backward, Forward};
use tactile_records::emulator::{EmulatorStats, EmulatorTotals, Passage};
use tactile_runtime::driver::{Counts, Failure, Follower, Handler, Io, Reply};

/// The emulator's handler: both channels.
#[derive(Debug)]
pub struct EmulatorHandler {
    emulator: Emulator,
}

impl EmulatorHandler {
    /// The handler of `emulator`.
    pub fn new(emulator: Emulator) -> Self {
        EmulatorHandler { emulator }
    }
}

impl Handler for EmulatorHandler {
    type Sample = Passage;
    type Totals = EmulatorTotals;

    fn totals(&self, c: &Counts) -> EmulatorTotals {
        EmulatorTotals {
            counters: self.emulator.counters(),
            links: EmulatorStats {
                c_in: c.ports.forward_in,
                v_out: c.ports.forward_out,
                h_in: c.ports.backward_in,
                q_out: c.ports.backward_out,
            },
        }
    }
}

impl Follower for EmulatorHandler {
    fn forward(
        &mut self,
        c: &Forward,
        out: &mut Reply<Passage>,
        _: &mut Io,
    ) -> Result<(), Failure> {
        self.emulator.forward(c, &mut out.forward, &mut out.record);
        Ok(())
    }

    fn backward(
        &mut self,
        h: &Backward,
        out: &mut Reply<Passage>,
        _: &mut Io,
    ) -> Result<(), Failure> {
        self.emulator
            .backward(h, &mut out.backward, &mut out.record);
        Ok(())
    }
}
