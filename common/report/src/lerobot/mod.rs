//! Runs as a LeRobot v3.0 dataset (`tactile export lerobot`): one episode per run, a
//! sweep's runs in its folders' order, each resampled to the dataset's frame rate.
//!
//! Frame k (at k / fps s) takes the sample at or before its time, sample
//! floor(k rate / fps): every value in the dataset is one the loop really had (an
//! average would mix samples across a contact's onset or a lost answer, and a flag or
//! a delay averaged is no flag or delay at all). The records are joined as `tactile
//! report` joins them ([`crate::join`]) and frames are written to Parquet as they
//! come, a row group every [`ROW_GROUP`] frames, so a run of any length takes the same
//! memory. The dataset is written into a hidden sibling folder and renamed when
//! whole: a failed export leaves nothing.

mod damage;
pub mod features;
pub mod meta;
pub mod runs;
pub mod stats;
pub mod table;

use crate::join;
use crate::Error;
use features::{Held, Layout, FEATURES};
use meta::Episode;
use runs::Run;
use stats::Stats;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use table::{Cell, Col, Table};

/// Frames per row group of the data file (about 1.7 MB of values for a 7-joint arm).
pub const ROW_GROUP: usize = 10_000;

/// What to export.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Frames per second (at most the runs' sample rate).
    pub fps: u32,
    /// Every episode's task text; None: each run's scenario's name.
    pub task: Option<String>,
}

/// What an export wrote.
#[derive(Debug, Clone)]
pub struct Exported {
    /// The episodes, in order (episode k is `episodes[k]`).
    pub episodes: Vec<Episode>,
    /// Frames in all.
    pub frames: u64,
    /// What the dataset leaves out (a run's episode ended by a damaged record).
    pub warnings: Vec<String>,
}

/// Exports the runs of `inputs` (run folders, sweep folders) into the new folder `out`,
/// looking at `stop` (a stop request) as it reads: a stopped export writes nothing
/// ([`Error::Stopped`]), since a dataset of part of the runs would pass for all of them.
pub fn export(
    inputs: &[PathBuf],
    out: &Path,
    opts: &Options,
    stop: &dyn Fn() -> bool,
) -> Result<Exported, Error> {
    if opts.fps == 0 {
        return Err(Error::BadInput(
            "--fps 0: give at least 1 frame per second".into(),
        ));
    }
    check_out(out)?;
    if inputs.is_empty() {
        return Err(Error::BadInput("no run given".into()));
    }
    let runs = runs::gather(inputs)?;
    for r in &runs {
        if f64::from(opts.fps) > r.scenario.rate_hz {
            return Err(Error::BadInput(format!(
                "--fps {}: above {}'s sample rate, {} Hz (a frame is a sample; give at most its rate)",
                opts.fps,
                r.dir.display(),
                r.scenario.rate_hz
            )));
        }
    }
    let tmp = partial(out)?;
    let _ = std::fs::remove_dir_all(&tmp);
    let done = write_dataset(&runs, &tmp, opts, stop).and_then(|x| {
        // An empty folder given as --out is replaced; check_out refused any other.
        let _ = std::fs::remove_dir(out);
        std::fs::rename(&tmp, out)
            .map_err(Error::io(format!("renaming into {}", out.display())))?;
        Ok(x)
    });
    if done.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    done
}

/// Refuses an `out` that holds anything: an export never mixes with other files.
fn check_out(out: &Path) -> Result<(), Error> {
    match std::fs::read_dir(out).map(|mut e| e.next().is_none()) {
        Ok(true) => Ok(()),
        Ok(false) => Err(Error::BadInput(format!(
            "--out {}: the folder is not empty (give a new folder: a dataset is written whole, never into other files)",
            out.display()
        ))),
        Err(_) if out.exists() => Err(Error::BadInput(format!(
            "--out {}: not a folder",
            out.display()
        ))),
        Err(_) => Ok(()),
    }
}

/// The hidden sibling the dataset is written into: `.NAME.partial`.
fn partial(out: &Path) -> Result<PathBuf, Error> {
    let name = out
        .file_name()
        .ok_or_else(|| Error::BadInput(format!("--out {}: give a folder's name", out.display())))?;
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !parent.is_dir() {
        return Err(Error::BadInput(format!(
            "--out {}: {} is not a folder",
            out.display(),
            parent.display()
        )));
    }
    Ok(parent.join(format!(".{}.partial", name.to_string_lossy())))
}

/// The data file's columns: the features, then LeRobot's default columns.
fn data_columns() -> Vec<(String, Col)> {
    FEATURES
        .iter()
        .map(|f| (f.to_string(), Col::ListF32))
        .chain(meta::DEFAULTS.iter().map(|(n, d)| {
            let col = if *d == "float32" { Col::F32 } else { Col::I64 };
            (n.to_string(), col)
        }))
        .collect()
}

/// The data files being written, one at a time.
struct Data {
    root: PathBuf,
    table: Table,
    at: (u64, u64),
    hf: String,
}

impl Data {
    fn open(root: &Path, at: (u64, u64), hf: String) -> Result<Data, Error> {
        let path = root.join(meta::data_file(at.0, at.1));
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(Error::io(format!("creating {}", dir.display())))?;
        }
        let table = Table::create(&path, data_columns())
            .map_err(Error::io(format!("writing {}", path.display())))?;
        Ok(Data {
            root: root.to_path_buf(),
            table,
            at,
            hf,
        })
    }

    fn io(&self) -> impl FnOnce(std::io::Error) -> Error {
        Error::io(format!(
            "writing {}",
            meta::data_file(self.at.0, self.at.1).display()
        ))
    }

    /// Starts the next file if this one is past LeRobot's size (between episodes).
    fn roll(self) -> Result<Data, Error> {
        if self.table.bytes < meta::DATA_FILES_SIZE_IN_MB * 1024 * 1024 {
            return Ok(self);
        }
        let (chunk, file) = self.at;
        let next = if file + 1 == meta::CHUNKS_SIZE {
            (chunk + 1, 0)
        } else {
            (chunk, file + 1)
        };
        let (root, hf) = (self.root.clone(), self.hf.clone());
        self.finish()?;
        Data::open(&root, next, hf)
    }

    fn add(&mut self, row: &[Cell]) -> Result<(), Error> {
        self.table.add(row).map_err(self.io())?;
        if self.table.rows() >= ROW_GROUP {
            self.table.flush().map_err(self.io())?;
        }
        Ok(())
    }

    fn finish(self) -> Result<(), Error> {
        let io = self.io();
        self.table.finish(&[("huggingface", self.hf)]).map_err(io)
    }
}

/// Statistics for every feature and default column.
fn new_stats(layout: &Layout) -> Vec<Stats> {
    let mut s: Vec<Stats> = layout
        .entries()
        .iter()
        .map(|e| Stats::new(e.len()))
        .collect();
    s.extend(meta::DEFAULTS.iter().map(|_| Stats::new(1)));
    s
}

fn write_dataset(
    runs: &[Run],
    root: &Path,
    opts: &Options,
    stop: &dyn Fn() -> bool,
) -> Result<Exported, Error> {
    let Some(first) = runs.first() else {
        return Err(Error::BadInput("no run given".into()));
    };
    let layout = first.layout.clone();
    std::fs::create_dir_all(root.join("meta/episodes/chunk-000"))
        .map_err(Error::io(format!("creating {}", root.display())))?;
    let mut data = Data::open(root, (0, 0), meta::hf_features(&layout))?;
    let mut all = new_stats(&layout);
    let (mut tasks, mut episodes, mut warnings) = (Vec::<String>::new(), Vec::new(), Vec::new());
    let mut index = 0u64;
    for run in runs {
        data = data.roll()?;
        let task = opts
            .task
            .clone()
            .unwrap_or_else(|| run.scenario.name.clone());
        let task_index = match tasks.iter().position(|t| *t == task) {
            Some(k) => k,
            None => {
                tasks.push(task.clone());
                tasks.len() - 1
            }
        };
        let mut ep = Episode {
            run: run.dir.clone(),
            task,
            task_index: task_index as i64,
            length: 0,
            file: data.at,
            from: index,
            meta: run.meta.clone(),
            swept: run.swept.clone(),
            damaged_at: None,
            stats: new_stats(&layout),
        };
        episode(
            run,
            opts.fps,
            episodes.len() as i64,
            &mut ep,
            (&mut data, &mut all),
            stop,
        )?;
        if let Some(n) = ep.damaged_at {
            warnings.push(format!(
                "{}: the records are damaged at sample {n}: episode {} holds the {} frames before it",
                run.dir.display(),
                episodes.len(),
                ep.length
            ));
        }
        if ep.length == 0 {
            return Err(Error::BadInput(format!(
                "{}: no sample to export (damaged from its first sample?)",
                run.dir.display()
            )));
        }
        index += ep.length;
        episodes.push(ep);
    }
    data.finish()?;
    let m = root.join("meta");
    let info = meta::info(&layout, opts.fps, episodes.len(), index, tasks.len());
    crate::write::write_json(&m.join("info.json"), &info)?;
    crate::write::write_json(&m.join("stats.json"), &meta::stats_json(&all))?;
    meta::write_tasks(&m.join("tasks.parquet"), &tasks)?;
    meta::write_episodes(&m.join("episodes/chunk-000/file-000.parquet"), &episodes)?;
    Ok(Exported {
        episodes,
        frames: index,
        warnings,
    })
}

/// Frame k's sample: the one at or before k / fps s, floor(k rate / fps).
pub fn sample_of(k: u64, rate_hz: f64, fps: u32) -> u64 {
    ((k as f64 * rate_hz) / f64::from(fps)).floor() as u64
}

/// The stamps of one frame: its number in the episode and the dataset, the episode's.
struct At {
    k: u64,
    fps: u32,
    episode_index: i64,
    from: u64,
    task_index: i64,
}

/// Writes one frame and adds it to the episode's and the dataset's statistics.
fn write_frame(
    f: features::Frame,
    at: &At,
    stats: [&mut [Stats]; 2],
    data: &mut Data,
) -> Result<(), Error> {
    let timestamp = (at.k as f64 / f64::from(at.fps)) as f32;
    let ints = [
        at.k as i64,
        at.episode_index,
        (at.from + at.k) as i64,
        at.task_index,
    ];
    let defaults = std::iter::once(f64::from(timestamp)).chain(ints.map(|x| x as f64));
    for s in stats {
        for (s, v) in s.iter_mut().zip(&f) {
            s.add(v.iter().map(|&x| f64::from(x)));
        }
        for (s, x) in s[FEATURES.len()..].iter_mut().zip(defaults.clone()) {
            s.add([x]);
        }
    }
    let mut cells: Vec<Cell> = f.into_iter().map(Cell::ListF32).collect();
    cells.push(Cell::F32(timestamp));
    cells.extend(ints.map(Cell::I64));
    data.add(&cells)
}

/// Joins one run's records and writes its frames; a sample the master's record lost,
/// or the first a damaged stretch of the slave's or the emulator's may have held, ends
/// the episode there (`damaged_at`).
fn episode(
    run: &Run,
    fps: u32,
    episode_index: i64,
    ep: &mut Episode,
    (data, all): (&mut Data, &mut [Stats]),
    stop: &dyn Fn() -> bool,
) -> Result<(), Error> {
    let (rate, t_s) = (run.scenario.rate_hz, run.scenario.t_s());
    let mut held = Held::new(run.layout.joints.len());
    let end = damage::first_damaged_sample(&run.dir, stop)?;
    let mut at = At {
        k: 0,
        fps,
        episode_index,
        from: ep.from,
        task_index: ep.task_index,
    };
    let mut expected = 0u64;
    let arm = join::Arm::of(&run.scenario);
    let dirs = std::slice::from_ref(&run.dir);
    let logs = join::join_until(dirs, stop, arm, |row, j| {
        let (joints, rotation) = (j.joints, j.rotation);
        if row.n != expected || end == Some(row.n) {
            ep.damaged_at = Some(expected);
            return Ok(ControlFlow::Break(()));
        }
        expected += 1;
        held.take(row, joints);
        while sample_of(at.k, rate, fps) <= row.n {
            let f = features::frame(row, rotation, &held, t_s);
            write_frame(f, &at, [&mut ep.stats, all], data)?;
            at.k += 1;
        }
        Ok(ControlFlow::Continue(()))
    })?;
    // The join says it stopped when the episode ended at a damage too: only a stop
    // request ends the export.
    if let Some(n) = logs.stopped_at.filter(|_| ep.damaged_at.is_none()) {
        return Err(Error::Stopped(format!(
            "stopped at sample {n} of {} by a stop request: no dataset written",
            run.dir.display()
        )));
    }
    // A torn or damaged stretch the join read past without losing a sample's row
    // (the master's record's tail) still ends the episode where its rows ended, said.
    let damaged = logs.master.damaged.1 + logs.emulator.damaged.1 + logs.slave.damaged.1;
    if damaged > 0 && ep.damaged_at.is_none() {
        ep.damaged_at = Some(expected);
    }
    ep.length = at.k;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_takes_the_sample_at_or_before_its_time() {
        // 1 kHz at 50 fps: every 20th sample.
        let at_50: Vec<u64> = (0..4).map(|k| sample_of(k, 1000.0, 50)).collect();
        assert_eq!(at_50, [0, 20, 40, 60]);
        // 1 kHz at 30 fps: frame 1 at 33.3 ms takes sample 33 (at 33 ms), not 34.
        let at_30: Vec<u64> = (0..4).map(|k| sample_of(k, 1000.0, 30)).collect();
        assert_eq!(at_30, [0, 33, 66, 100]);
        // At the run's own rate every sample is a frame.
        assert!((0..1000).all(|k| sample_of(k, 100.0, 100) == k));
    }

    #[test]
    fn an_out_that_holds_anything_is_refused_and_an_empty_one_taken() {
        let dir = tempfile::tempdir().expect("tmp");
        assert!(check_out(&dir.path().join("new")).is_ok());
        assert!(check_out(dir.path()).is_ok());
        std::fs::write(dir.path().join("x"), "x").expect("write");
        assert!(matches!(check_out(dir.path()), Err(Error::BadInput(_))));
        assert!(matches!(
            check_out(&dir.path().join("x")),
            Err(Error::BadInput(_))
        ));
    }
}
