//! A sweep's traces as one dataset: every run's `trace.parquet` (which carries its
//! combination as text columns) linked into `OUT/traces/` under the run's name, so
//! `pandas.read_parquet("OUT/traces")` reads the whole study as one table.

use crate::error::Error;
use std::path::Path;

/// The dataset's folder in a sweep's output.
pub const DIR: &str = "traces";

/// Links (or copies, across file systems) the `trace.parquet` of each run folder that
/// holds a whole run (its summary written, not cut short: the runs `sweep.csv` holds)
/// into `out/traces/RUN.parquet`; a run without one loses what `traces/` had of it, so
/// the dataset never holds a stale or partial trace. Returns how many are linked.
pub fn gather<'a>(out: &Path, runs: impl IntoIterator<Item = &'a Path>) -> Result<usize, Error> {
    let dir = out.join(DIR);
    let mut n = 0;
    for run in runs {
        let from = run.join(tactile_report::write::PARQUET_FILE);
        let Some(name) = run.file_name() else {
            continue;
        };
        let to = dir.join(format!("{}.parquet", name.to_string_lossy()));
        match std::fs::remove_file(&to) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(Error::io(format!("removing {}", to.display()))(e));
            }
            _ => {}
        }
        if !from.is_file() || super::exec::finished(run).is_none() {
            continue;
        }
        std::fs::create_dir_all(&dir).map_err(Error::io(format!("creating {}", dir.display())))?;
        std::fs::hard_link(&from, &to)
            .or_else(|_| std::fs::copy(&from, &to).map(|_| ()))
            .map_err(Error::io(format!("linking {}", to.display())))?;
        n += 1;
    }
    Ok(n)
}
