//! `tactile export lerobot RUN_OR_SWEEP... --out DIR`: runs and sweeps as a LeRobot
//! v3.0 dataset (docs/17-lerobot.md).

use clap::{Args, Subcommand};
use std::path::PathBuf;
use tactile_launch::error::Error;
use tactile_report::lerobot::{export, Options};

/// Arguments of `tactile export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The format to write.
    #[command(subcommand)]
    pub format: Format,
}

/// The formats `tactile export` writes.
#[derive(Debug, Subcommand)]
pub enum Format {
    /// A LeRobot v3.0 dataset: one episode per run (a sweep's runs in order), the
    /// master's pose, the slave's joints, their commands, torques and forces and the
    /// network's delays and losses per frame, the run's conditions per episode.
    Lerobot(LerobotArgs),
}

/// Arguments of `tactile export lerobot`.
#[derive(Debug, Args)]
pub struct LerobotArgs {
    /// Run folders (a `tactile run`'s) and sweep folders (a `tactile sweep`'s).
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// The dataset's folder: new, or empty.
    #[arg(long)]
    pub out: PathBuf,
    /// Frames per second: each frame takes the sample at or before its time (at most
    /// the runs' sample rate).
    #[arg(long, default_value_t = 50)]
    pub fps: u32,
    /// Every episode's task text [default: each run's scenario's name].
    #[arg(long)]
    pub task: Option<String>,
}

/// `tactile export FORMAT ...`.
pub fn main(args: &ExportArgs) -> Result<(), Error> {
    let Format::Lerobot(a) = &args.format;
    let opts = Options {
        fps: a.fps,
        task: a.task.clone(),
    };
    let stop =
        tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let stopped = || stop.load(std::sync::atomic::Ordering::SeqCst);
    let done = export(&a.runs, &a.out, &opts, &stopped)?;
    for w in &done.warnings {
        tactile_launch::noteln!("tactile export: warning: {w}");
    }
    tactile_launch::outln!(
        "wrote {}: {} episodes, {} frames at {} fps",
        a.out.display(),
        done.episodes.len(),
        done.frames,
        a.fps
    );
    Ok(())
}
