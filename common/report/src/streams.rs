//! What a report streams its rows into besides the statistics: the trace
//! (`trace.csv`, `trace.parquet`), a URDF arm's `joints.csv` and the recording
//! (`run.mcap`), each written under its partial name and renamed when whole.

use crate::summary::JOINTS_FILE;
use crate::{run_mcap, trace, Error};
use std::io::Write as _;
use std::path::Path;
use tactile_scenario::Scenario;

/// The Parquet trace's file name.
pub const PARQUET_FILE: &str = "trace.parquet";

/// Which trace files a report writes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TraceFormat {
    /// `trace.csv` (the default: text that any tool and any diff reads, and what the
    /// determinism checks compare).
    #[default]
    Csv,
    /// `trace.parquet` alone (long runs, studies read with pandas or Arrow).
    Parquet,
    /// Both.
    Both,
}

impl std::str::FromStr for TraceFormat {
    type Err = crate::error::UnknownChoice;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "csv" => Ok(TraceFormat::Csv),
            "parquet" => Ok(TraceFormat::Parquet),
            "both" => Ok(TraceFormat::Both),
            _ => Err(crate::error::UnknownChoice {
                given: s.to_string(),
                choices: "csv, parquet or both",
            }),
        }
    }
}

impl TraceFormat {
    pub(crate) fn csv(self) -> bool {
        self != TraceFormat::Parquet
    }
    pub(crate) fn parquet(self) -> bool {
        self != TraceFormat::Csv
    }
}

/// What a report writes besides its summary, histograms and plots: the one
/// description the CLI, the launcher and the report share.
#[derive(Debug, Clone, Default)]
pub struct Outputs {
    /// No trace and no run.mcap (long runs).
    pub no_trace: bool,
    /// `trace.csv`, `trace.parquet` or both.
    pub trace_format: TraceFormat,
    /// Constant text columns `trace.parquet` carries after the trace's (a sweep's
    /// combination: key, value).
    pub trace_columns: Vec<(String, String)>,
    /// How `run.mcap`'s chunks are compressed.
    pub mcap_compression: crate::mcap::Compression,
}

/// What a report streams its rows into besides the statistics: `trace.csv` and
/// `run.mcap` (neither with `--no-trace`).
pub(crate) struct Streams {
    trace: Option<std::io::BufWriter<std::fs::File>>,
    parquet: Option<crate::parquet_trace::ParquetTrace>,
    /// A URDF arm's joints, one row a sample (`[slave.arm]`).
    joints: Option<std::io::BufWriter<std::fs::File>>,
    recording: Option<run_mcap::FileRecording>,
    /// A physics world's moving bodies, rows a sample (`engine = "physics"`).
    bodies: Option<crate::bodies::BodiesCsv>,
    /// Why the recording leaves something out, for the summary's events.
    pub(crate) warning: Option<String>,
    line: String,
    t0: Option<u64>,
}

impl Streams {
    /// Starts the files in `out` (or removes old ones with `no_trace`).
    pub(crate) fn create(
        out: &Path,
        scenario: &Scenario,
        want: &Outputs,
    ) -> Result<Streams, Error> {
        let trace_path = out.join("trace.csv");
        let parquet_path = out.join(PARQUET_FILE);
        let format = want.trace_format;
        if want.no_trace || !format.csv() {
            let _ = std::fs::remove_file(&trace_path);
        }
        if want.no_trace || !format.parquet() {
            let _ = std::fs::remove_file(&parquet_path);
        }
        if want.no_trace {
            let _ = std::fs::remove_file(out.join(run_mcap::FILE));
            let _ = std::fs::remove_file(out.join(JOINTS_FILE));
            let _ = std::fs::remove_file(out.join(crate::bodies::BODIES_FILE));
            return Ok(Streams {
                trace: None,
                parquet: None,
                joints: None,
                recording: None,
                bodies: None,
                warning: None,
                line: String::new(),
                t0: None,
            });
        }
        let trace = if format.csv() {
            let f = std::fs::File::create(crate::out::partial(&trace_path))
                .map_err(Error::io(format!("writing {}", trace_path.display())))?;
            let mut w = std::io::BufWriter::with_capacity(1 << 16, f);
            writeln!(w, "{}", trace::header()).map_err(Error::io("writing trace.csv"))?;
            Some(w)
        } else {
            None
        };
        let parquet = if format.parquet() {
            Some(
                crate::parquet_trace::ParquetTrace::create(
                    &crate::out::partial(&parquet_path),
                    want.trace_columns.clone(),
                )
                .map_err(Error::io(format!("writing {PARQUET_FILE}")))?,
            )
        } else {
            None
        };
        let (recording, warning) = run_mcap::create(out, scenario, want.mcap_compression)
            .map_err(Error::io("writing run.mcap"))?;
        let joints = match &scenario.slave.arm {
            Some(arm) => Some(joints_csv(out, arm.home.len())?),
            None => {
                let _ = std::fs::remove_file(out.join(JOINTS_FILE));
                None
            }
        };
        let bodies = crate::bodies::BodiesCsv::create(out, scenario)?;
        Ok(Streams {
            trace,
            parquet,
            joints,
            recording: Some(recording),
            bodies,
            warning,
            line: String::with_capacity(2048),
            t0: None,
        })
    }

    pub(crate) fn add(
        &mut self,
        row: &trace::TraceRow,
        joined: &crate::join::Joined,
    ) -> Result<(), Error> {
        if let (Some(b), Some(w)) = (self.bodies.as_mut(), joined.world) {
            b.add(row.n, w)?;
        }
        if let (Some(w), Some(j)) = (self.joints.as_mut(), joined.joints) {
            self.line.clear();
            crate::joints::row(&mut self.line, row.n, j);
            w.write_all(self.line.as_bytes())
                .map_err(Error::io(format!("writing {JOINTS_FILE}")))?;
        }
        let t0 = *self.t0.get_or_insert(row.stamps[0]);
        if let Some(p) = self.parquet.as_mut() {
            p.add(row, t0)
                .map_err(Error::io(format!("writing {PARQUET_FILE}")))?;
        }
        if let Some(w) = self.trace.as_mut() {
            self.line.clear();
            row.write_csv(&mut self.line, t0);
            w.write_all(self.line.as_bytes())
                .map_err(Error::io("writing trace.csv"))?;
        }
        if let Some(r) = self.recording.as_mut() {
            r.add(row, joined).map_err(Error::io("writing run.mcap"))?;
        }
        Ok(())
    }

    /// Flushes the trace and gives the recording its name.
    pub(crate) fn finish(self, out: &Path) -> Result<(), Error> {
        if let Some(b) = self.bodies {
            b.finish(out)?;
        }
        if let Some(mut w) = self.joints {
            let path = out.join(JOINTS_FILE);
            w.flush()
                .and_then(|()| std::fs::rename(crate::out::partial(&path), &path))
                .map_err(Error::io(format!("writing {JOINTS_FILE}")))?;
        }
        if let Some(mut w) = self.trace {
            w.flush().map_err(Error::io("writing trace.csv"))?;
            let path = out.join("trace.csv");
            std::fs::rename(crate::out::partial(&path), &path)
                .map_err(Error::io("writing trace.csv"))?;
        }
        if let Some(p) = self.parquet {
            let path = out.join(PARQUET_FILE);
            p.finish()
                .and_then(|()| std::fs::rename(crate::out::partial(&path), &path))
                .map_err(Error::io(format!("writing {PARQUET_FILE}")))?;
        }
        if let Some(r) = self.recording {
            run_mcap::commit(r, out).map_err(Error::io("writing run.mcap"))?;
        }
        Ok(())
    }
}

/// Starts `joints.csv` (as its partial file) with its header, for `dof` joints.
fn joints_csv(out: &Path, dof: usize) -> Result<std::io::BufWriter<std::fs::File>, Error> {
    let path = out.join(JOINTS_FILE);
    let f = std::fs::File::create(crate::out::partial(&path))
        .map_err(Error::io(format!("writing {}", path.display())))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 16, f);
    writeln!(w, "{}", crate::joints::header(dof))
        .map_err(Error::io(format!("writing {JOINTS_FILE}")))?;
    Ok(w)
}
