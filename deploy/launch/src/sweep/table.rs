//! A sweep's tables and plots from its runs' metrics, and `--merge`, which makes the
//! same from the folders of a sharded sweep. `sweep.json` records what the sweep is,
//! so slices of different sweeps are never joined.

use super::exec::RunFolderError;
use super::{parse_axes, run_dir, Spec};
use crate::error::Error;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use tactile_report::sweep::{
    columns, combinations, runs_header, runs_row, stats, summary_header, summary_row, values, Axis,
};
use tactile_report::sweep_grid::same_grid;
use tactile_report::sweep_map::sweep_maps;
use tactile_report::sweep_plots::{sweep_plots, Point};

/// A run that ended, as the tables take it.
#[derive(Debug, Clone)]
pub struct Ran {
    /// Its combination's index in the grid.
    pub k: usize,
    /// Its seed's index (0 without `--seeds`): names its folder.
    pub s: usize,
    /// The seed it ran with (its `scenario.toml`'s), what `sweep.csv` says.
    pub seed: u64,
    /// Its metrics.
    pub values: Vec<Option<f64>>,
}

fn write(path: &Path, text: &str) -> Result<(), Error> {
    Ok(tactile_report::out::write_file(path, text)?)
}

/// Records the sweep in `out/sweep.json`.
pub fn write_spec(out: &Path, spec: &Spec) -> Result<(), Error> {
    let text = serde_json::to_string_pretty(spec)
        .map_err(|e| Error::Failed(format!("sweep.json: {e}")))?;
    write(&out.join("sweep.json"), &(text + "\n"))
}

fn read_spec(dir: &Path) -> Result<Spec, Error> {
    let path = dir.join("sweep.json");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| Error::BadInput(format!("{}: not a sweep's folder ({e})", path.display())))?;
    serde_json::from_str(&text).map_err(|e| Error::BadInput(format!("{}: {e}", path.display())))
}

/// True if `a` and `b` are one sweep (any slices of it): the same scenario and the
/// same grid, its values compared as values (`tdpa` or `"tdpa"`, `1` or `1.0`: the
/// command and the Python package write them differently), so either front end
/// resumes or merges what the other started.
fn same_sweep(a: &Spec, b: &Spec) -> bool {
    let grid = match (parse_axes(&a.sets), parse_axes(&b.sets)) {
        (Ok(x), Ok(y)) => same_grid(&x, &y),
        _ => a.sets == b.sets,
    };
    a.scenario_hash == b.scenario_hash && grid
}

/// With `--resume`, the folder must hold this same sweep (any slice of it); without,
/// a folder of another sweep is left alone rather than mixed into.
pub fn check_resume(out: &Path, spec: &Spec, resume: bool) -> Result<(), Error> {
    let Ok(old) = read_spec(out) else {
        return Ok(());
    };
    if !same_sweep(&old, spec) {
        return Err(Error::BadInput(format!(
            "{}: holds another sweep (its scenario or --set differ); choose another --out",
            out.display()
        )));
    }
    if !resume && old.seeds == spec.seeds {
        crate::noteln!("tactile sweep: {} holds this sweep already; its runs are run again (--resume keeps them)", out.display());
    }
    Ok(())
}

/// `sweep.csv` (every run that ended), `sweep-summary.csv` and the plots (every
/// combination whose runs all ended), from `results` in any order: rows follow the
/// grid, so the files do not depend on the order the runs ended in.
pub fn write_tables(out: &Path, axes: &[Axis], seeds: usize, results: &[Ran]) -> Result<(), Error> {
    let combos = combinations(axes);
    let mut by: BTreeMap<usize, BTreeMap<usize, &Ran>> = BTreeMap::new();
    for r in results {
        by.entry(r.k).or_default().insert(r.s, r);
    }
    let mut points: Vec<Point> = Vec::new();
    let n = columns(results.iter().map(|r| r.values.as_slice()));
    let mut runs = runs_header(axes, n);
    let mut summary = summary_header(axes, n);
    for (&k, per_seed) in &by {
        let combo = &combos[k];
        for r in per_seed.values() {
            let dir = run_dir(Path::new(""), k, r.s, seeds);
            let name = dir.display().to_string();
            let cut = n.min(r.values.len());
            runs += &runs_row(&name, k, axes, combo, r.seed, &r.values[..cut]);
        }
        if per_seed.len() < seeds {
            continue;
        }
        let values: Vec<Vec<Option<f64>>> = per_seed.values().map(|r| r.values.clone()).collect();
        let stats = stats(&values);
        summary += &summary_row(k, axes, combo, values.len(), &stats[..n.min(stats.len())]);
        points.push((combo.clone(), stats));
    }
    write(&out.join("sweep.csv"), &runs)?;
    write(&out.join("sweep-summary.csv"), &summary)?;
    let (axes, points) = unpaired(axes, &points);
    let plot = |what: &str| {
        let what = what.to_string();
        move |source| Error::Report(tactile_report::Error::Plot { what, source })
    };
    sweep_plots(out, &axes, &points).map_err(plot("plotting the sweep"))?;
    sweep_maps(out, &axes, &points)
        .map(|_| ())
        .map_err(plot("drawing the sweep's maps"))
}

/// The axes a plot or a map draws, and the points on them: a paired key moves with
/// its partner, so the partner stands for both.
fn unpaired(axes: &[Axis], points: &[Point]) -> (Vec<Axis>, Vec<Point>) {
    let lead: Vec<usize> = (0..axes.len()).filter(|&j| !axes[j].paired).collect();
    let points = points
        .iter()
        .map(|(combo, stats)| (lead.iter().map(|&j| combo[j]).collect(), stats.clone()))
        .collect();
    (lead.iter().map(|&j| axes[j].clone()).collect(), points)
}

/// The slices' specs, all of one sweep (scenario, `--set`s and seeds).
fn slices_of_one_sweep(dirs: &[PathBuf]) -> Result<Spec, Error> {
    let specs = dirs
        .iter()
        .map(|d| read_spec(d))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &specs[0];
    for (d, s) in dirs.iter().zip(&specs) {
        if !(same_sweep(s, first) && s.seeds == first.seeds) {
            return Err(Error::BadInput(format!(
                "{}: a slice of another sweep (scenario, --set or --seeds differ from {})",
                d.display(),
                dirs[0].display()
            )));
        }
    }
    Ok(first.clone())
}

/// Every run of the grid found, and the runs whole in none of the folders (each with
/// why, where a folder holds it but not whole).
type Found = (Vec<Ran>, Vec<String>);

/// Each run of the grid from the one folder that holds it whole.
fn gather(dirs: &[PathBuf], spec: &Spec) -> Result<Found, Error> {
    let (mut results, mut missing) = (Vec::new(), Vec::new());
    for k in 0..spec.combinations {
        for s in 0..spec.seeds {
            let mut found = Vec::new();
            let mut why = Vec::new();
            for d in dirs {
                let dir = run_dir(d, k, s, spec.seeds);
                match ran(&dir) {
                    Ok(r) => found.push(r),
                    // A slice holds only its own runs' folders.
                    Err(_) if !dir.is_dir() => {}
                    Err(e) => why.push(format!("{}: {e}", dir.display())),
                }
            }
            match found.len() {
                0 => {
                    let name = run_dir(Path::new(""), k, s, spec.seeds);
                    missing.push(if why.is_empty() {
                        format!("{}: in none of the folders", name.display())
                    } else {
                        why.join("; ")
                    });
                }
                1 => results.extend(found.into_iter().map(|(seed, values)| Ran {
                    k,
                    s,
                    seed,
                    values,
                })),
                _ => {
                    return Err(Error::BadInput(format!(
                        "combination {k}, seed {s}: in more than one folder"
                    )))
                }
            }
        }
    }
    Ok((results, missing))
}

/// The seed and metrics of the whole run in `dir`, read back from its folder, or why
/// there are none.
fn ran(dir: &Path) -> Result<(u64, Vec<Option<f64>>), RunFolderError> {
    let summary = super::exec::read_summary(dir)?;
    if summary["interrupted"] != false {
        return Err(RunFolderError::Interrupted);
    }
    Ok((super::exec::seed_of(dir)?, values(&summary)))
}

/// `--out` is none of the folders merged (compared as canonical paths, so `./a` and
/// `a` are one): merging into an input would overwrite its tables with the whole
/// sweep's while its runs stay a slice.
fn refuse_out_among(dirs: &[PathBuf], out: &Path) -> Result<(), Error> {
    let Ok(target) = out.canonicalize() else {
        return Ok(()); // not there yet, so none of the inputs
    };
    match dirs
        .iter()
        .find(|d| d.canonicalize().is_ok_and(|d| d == target))
    {
        Some(d) => Err(Error::BadInput(format!(
            "--out {}: it is {}, one of the folders merged; merge into another folder",
            out.display(),
            d.display()
        ))),
        None => Ok(()),
    }
}

/// `tactile sweep --merge DIR... --out OUT`.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<(), Error> {
    refuse_out_among(dirs, out)?;
    let first = slices_of_one_sweep(dirs)?;
    let axes = parse_axes(&first.sets)?;
    let (results, missing) = gather(dirs, &first)?;
    let holder = format!("tactile sweep --merge (pid {})", std::process::id());
    let _held = tactile_report::out::take(out, &holder)?;
    write_spec(
        out,
        &Spec {
            shard: None,
            ..first.clone()
        },
    )?;
    write_tables(out, &axes, first.seeds, &results)?;
    // Each run once, from the folder that holds it whole (none: its trace is dropped).
    let runs: Vec<PathBuf> = (0..first.combinations)
        .flat_map(|k| (0..first.seeds).map(move |s| (k, s)))
        .map(|(k, s)| {
            dirs.iter()
                .map(|d| run_dir(d, k, s, first.seeds))
                .find(|r| super::exec::finished(r).is_some())
                .unwrap_or_else(|| run_dir(out, k, s, first.seeds))
        })
        .collect();
    super::traces::gather(out, runs.iter().map(PathBuf::as_path))?;
    if !missing.is_empty() {
        let shown: Vec<_> = missing.iter().take(5).cloned().collect();
        return Err(Error::Failed(format!(
            "{} runs are whole in none of the folders ({}{}); sweep.csv holds the rest",
            missing.len(),
            shown.join("; "),
            if missing.len() > 5 { "; ..." } else { "" }
        )));
    }
    crate::outln!(
        "tactile sweep: merged {} runs from {} folders into {}",
        results.len(),
        dirs.len(),
        out.display()
    );
    Ok(())
}
