//! A sweep's traces as one dataset: every run's `trace.parquet` (which carries its
//! combination as text columns) linked into `OUT/traces/` under the run's name, so
//! `pandas.read_parquet("OUT/traces")` reads the whole study as one table.

use crate::error::Error;
use std::path::Path;

/// The dataset's folder in a sweep's output.
pub const DIR: &str = "traces";

/// Links (or copies, across file systems) each run folder's `trace.parquet` into
/// `out/traces/RUN.parquet`, replacing what was there; returns how many.
pub fn gather<'a>(out: &Path, runs: impl IntoIterator<Item = &'a Path>) -> Result<usize, Error> {
    let dir = out.join(DIR);
    let mut n = 0;
    for run in runs {
        let from = run.join(tactile_report::write::PARQUET_FILE);
        let Some(name) = run.file_name() else {
            continue;
        };
        if !from.is_file() {
            continue;
        }
        std::fs::create_dir_all(&dir).map_err(Error::io(format!("creating {}", dir.display())))?;
        let to = dir.join(format!("{}.parquet", name.to_string_lossy()));
        let _ = std::fs::remove_file(&to);
        std::fs::hard_link(&from, &to)
            .or_else(|_| std::fs::copy(&from, &to).map(|_| ()))
            .map_err(Error::io(format!("linking {}", to.display())))?;
        n += 1;
    }
    Ok(n)
}
