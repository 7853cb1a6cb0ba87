//! `tactile report DIR...`: the run's report from the nodes' records (one folder, or
//! one folder per node from several hosts).

use clap::Args;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use tactile_launch::error::Error;
use tactile_report::text::render;
use tactile_report::write::{write_mcap, write_report, Launch};

/// Arguments of `tactile report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Folders holding the nodes' records (master.rec, emulator.rec, slave.rec).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Folder for the report (default: the master's folder).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write no trace.csv and no run.mcap (a long run's trace is about 1 kB per
    /// sample).
    #[arg(long, conflicts_with = "mcap_only")]
    pub no_trace: bool,
    /// Write only run.mcap, the run as ROS 2 messages for Foxglove, Rerun and
    /// `ros2 bag` (converts old records without redoing the report).
    #[arg(long)]
    pub mcap_only: bool,
    /// The trace's and the recording's formats.
    #[command(flatten)]
    pub formats: super::formats::FormatArgs,
}

/// `tactile report DIR... [--out OUT]`.
pub fn main(args: &ReportArgs) -> Result<(), Error> {
    args.formats
        .refuse_unless(!args.no_trace, "with --no-trace")?;
    if args.mcap_only && args.formats.trace_format != tactile_report::write::TraceFormat::Csv {
        return Err(Error::BadInput(
            "--trace-format with --mcap-only: only run.mcap is written".into(),
        ));
    }
    let out = match &args.out {
        Some(o) => o.clone(),
        None => tactile_launch::report_out(&args.dirs)?,
    };
    let holder = format!("tactile report (pid {})", std::process::id());
    let _held = tactile_report::out::take(&out, &holder)?;
    let stop =
        tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    if args.mcap_only {
        return mcap_only(args, &out, &stop);
    }
    let launch = Launch {
        stop: Some(stop),
        outputs: args.formats.outputs(args.no_trace),
        ..Launch::default()
    };
    let summary = write_report(&args.dirs, &out, &launch)?;
    tactile_launch::out!("{}", render(&summary, &out));
    if summary.interrupted {
        return Err(Error::Interrupted);
    }
    Ok(())
}

/// `tactile report --mcap-only`: run.mcap alone; a stop request (SIGINT, SIGTERM)
/// ends it at once with no file written, exit 130.
fn mcap_only(args: &ReportArgs, out: &Path, stop: &AtomicBool) -> Result<(), Error> {
    let stopped = || stop.load(Ordering::SeqCst);
    let w = write_mcap(&args.dirs, out, args.formats.mcap_compression, &stopped)?;
    let file = out.join(tactile_report::run_mcap::FILE);
    if let Some(n) = w.stopped_at {
        tactile_launch::noteln!(
            "stopped at sample {n} by a stop request: {} not written",
            file.display()
        );
        return Err(Error::Interrupted);
    }
    if let Some(w) = w.warning {
        tactile_launch::noteln!("warning: {w}");
    }
    tactile_launch::outln!("wrote {}: {} samples", file.display(), w.samples);
    Ok(())
}
