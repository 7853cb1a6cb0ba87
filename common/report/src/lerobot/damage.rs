//! Where a run's slave or emulator record is first damaged, as a sample number, so an
//! episode ends before it: the join reads past a damaged stretch of those records
//! (their samples' rows left empty), which would put frames the slave never recorded
//! into the dataset. The master's record needs no look: a sample it lost is a gap in
//! the join's rows.

use crate::Error;
use serde::de::DeserializeOwned;
use std::path::Path;
use tactile_messages::Role;
use tactile_records::emulator::{EmulatorTotals, Passage};
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{record_path, Record, RecordError, RecordReader};

/// One past the highest sample `path` holds before its first damaged stretch; None if
/// it reads whole (or is not there: a run without that node's record).
fn first_damage<S: DeserializeOwned, C: DeserializeOwned>(
    path: &Path,
    key: fn(&S) -> Option<u64>,
    stop: &dyn Fn() -> bool,
) -> Result<Option<u64>, Error> {
    if !path.exists() {
        return Ok(None);
    }
    let mut r =
        RecordReader::<Record<S, C>>::open(path).map_err(|e| Error::BadInput(e.to_string()))?;
    let mut next = 0u64;
    loop {
        let rec = r.next_record_until(stop).map_err(|e| match e {
            RecordError::Stopped { .. } => Error::Stopped(format!("{e}: no dataset written")),
            e => Error::BadInput(e.to_string()),
        })?;
        if r.damaged().1 > 0 {
            return Ok(Some(next));
        }
        match rec {
            Some(Record::Sample(s)) => {
                if let Some(n) = key(&s) {
                    next = next.max(n.saturating_add(1));
                }
            }
            Some(_) => {}
            None => return Ok(None),
        }
    }
}

/// The first sample of `dir`'s run whose slave or emulator record part may be lost to
/// damage, if any, looking at `stop` (a stop request) as it reads.
pub fn first_damaged_sample(dir: &Path, stop: &dyn Fn() -> bool) -> Result<Option<u64>, Error> {
    let slave = first_damage::<SlaveSample, SlaveTotals>(
        &record_path(dir, Role::Slave),
        |s| s.step().map(|x| x.n),
        stop,
    )?;
    let emulator = first_damage::<Passage, EmulatorTotals>(
        &record_path(dir, Role::Emulator),
        |p| Some(p.n),
        stop,
    )?;
    Ok(slave.into_iter().chain(emulator).min())
}
