//! The loop in one process: the master's, the emulator's and the slave's handlers,
//! the same as the node programs run, over in-memory streams
//! ([`tactile_transport::ports::in_memory`]) with simulated timing. While the master
//! waits for an answer, the emulator and the slave are stepped in turn until neither
//! has anything left to do; if the answer has not come by then it never will, and the
//! master counts a miss at once. The emulator and the slave never idle: a peer of
//! theirs cannot die in one process.

use super::follow::Follow;
use super::lead::Lead;
use super::{Block, Failure, Follower, Leader};
use std::time::Instant;

/// The emulator and the slave, stepped while the master waits.
struct Followers<'a, E: Follower, S: Follower> {
    emulator: &'a mut Follow<E>,
    slave: &'a mut Follow<S>,
}

impl<E: Follower, S: Follower> Followers<'_, E, S> {
    /// Steps both until neither moves; whether anything moved.
    fn settle(&mut self) -> Result<bool, Failure> {
        let mut moved = false;
        loop {
            let (e, _) = self.emulator.step()?;
            let (s, _) = self.slave.step()?;
            if !(e || s) {
                return Ok(moved);
            }
            moved = true;
        }
    }
}

impl<E: Follower, S: Follower> Block for Followers<'_, E, S> {
    fn block(
        &mut self,
        _: &[Box<dyn tactile_transport::Wake>],
        _: Option<Instant>,
    ) -> Result<bool, Failure> {
        self.settle()
    }
}

/// Runs the loop to its end (true) or a stop request (false); each node's record is
/// closed as the master's ended.
pub fn run<M: Leader, E: Follower, S: Follower>(
    master: Lead<M>,
    mut emulator: Follow<E>,
    mut slave: Follow<S>,
) -> Result<bool, Failure> {
    let mut others = Followers {
        emulator: &mut emulator,
        slave: &mut slave,
    };
    let ended = master.run(&mut others);
    // The end of the run is on its way to them.
    others.settle()?;
    emulator.close(&ended)?;
    slave.close(&ended)?;
    ended
}
