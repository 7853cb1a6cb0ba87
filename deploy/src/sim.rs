//! The in-process simulation: the same master, emulator and slave code as the three
//! processes, called in sequence with no shared memory and no clock.
//!
//! It is the reference the process tests compare against: a lockstep run of the trio
//! must produce the same signals, bit for bit. Time stamps here are synthetic
//! (n * t_s), so round trips equal the injected delay and overheads are zero.

use std::path::Path;
use tactile_common::samples::stage;
use tactile_common::scenario::Scenario;
use tactile_common::trace::TraceRow;
use tactile_master::hmd::{Master, MasterCounters};
use tactile_master::operator::OperatorSource;
use tactile_network_emulator::emulator::{Emulator, EmulatorCounters};
use tactile_slave::hsd::{Slave, SlaveCounters};

use crate::error::Error;

/// Everything a simulated run produced.
#[derive(Debug)]
pub struct SimRun {
    /// One row per sample.
    pub rows: Vec<TraceRow>,
    /// Master counters.
    pub master: MasterCounters,
    /// Emulator counters.
    pub emulator: EmulatorCounters,
    /// Slave counters.
    pub slave: SlaveCounters,
}

/// Runs `scenario` in-process; `base_dir` resolves a trajectory file's path.
pub fn simulate(scenario: &Scenario, base_dir: &Path) -> Result<SimRun, Error> {
    let source = OperatorSource::load(&scenario.operator, base_dir)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    let bad = |e: tactile_common::scenario::ScenarioError| Error::BadInput(e.to_string());
    let mut master = Master::new(scenario, source).map_err(bad)?;
    let mut emulator = Emulator::new(scenario);
    let mut slave = Slave::new(scenario).map_err(bad)?;
    let t_s_ns = scenario.t_s_ns();
    let mut rows = Vec::with_capacity(usize::try_from(scenario.samples).unwrap_or(0));
    for n in 0..scenario.samples {
        let now = n * t_s_ns;
        let (c, _) = master.forward(n, now);
        let answer = emulator
            .forward(&c)
            .map(|v| slave.step(&v))
            .and_then(|h| emulator.backward(&h));
        let row = match answer {
            Some(mut q) => {
                q.stamps[stage::MASTER_DONE] = now;
                let mut row = master.backward(&c, &q);
                master.account(&mut row);
                row
            }
            None => master.missing(&c),
        };
        rows.push(row);
    }
    Ok(SimRun {
        rows,
        master: master.counters(),
        emulator: emulator.counters(),
        slave: slave.counters(),
    })
}
