//! The scenario a run starts from: read, changed by `--set`, validated with its
//! inputs (trajectory, recorded networks), and the output folder made ready for it.
//! Everything here can refuse a run, so it all happens before any process starts.

use crate::error::{Error, InputError};
use std::path::{Path, PathBuf};
use tactile_master::operator::OperatorSource;
use tactile_messages::Role;
use tactile_report::write::REPORT_FILES;
use tactile_runtime::files::{self, same_file};
use tactile_scenario::overrides::Set;
use tactile_scenario::Scenario;

/// The paper scenario, built into the executable so `tactile run` works from any folder.
pub const PAPER_SCENARIO: &str = include_str!("../../scenarios/paper.toml");

/// A scenario ready to run: validated, its trajectory checked, and where it came from.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The scenario.
    pub scenario: Scenario,
    /// Folder its relative paths are resolved against.
    pub base_dir: PathBuf,
    /// The files it was read from (the scenario, a trajectory), which a run must never
    /// overwrite.
    pub inputs: Vec<PathBuf>,
    /// What loads but deserves a word before the run: the scenario's own warnings and
    /// its inputs' (a trajectory file shorter than the run).
    pub warnings: Vec<String>,
}

/// Reads and validates a scenario; `None` is the built-in paper scenario. A trajectory
/// file is read too, so a bad one stops the run before anything starts.
pub fn load_scenario(path: Option<&Path>, sets: &[Set]) -> Result<Loaded, Error> {
    let source = match path {
        None => Source::paper(),
        Some(p) => Source::file(p)?,
    };
    load_source(&source, sets)
}

/// A scenario's text and where it came from, before `--set`s and validation.
#[derive(Debug, Clone)]
pub struct Source {
    /// The TOML.
    pub text: String,
    /// Folder its relative paths are resolved against.
    pub base_dir: PathBuf,
    /// How errors name it (its path, or what it is).
    pub name: String,
    /// Its file, if it has one (a run must never overwrite it).
    pub path: Option<PathBuf>,
}

impl Source {
    /// The built-in paper scenario, its relative paths read from the working folder.
    pub fn paper() -> Self {
        Source {
            text: PAPER_SCENARIO.to_string(),
            base_dir: std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
            name: "deploy/scenarios/paper.toml (built in)".to_string(),
            path: None,
        }
    }

    /// The scenario file `path`, read as every command reads it (UTF-8, at most
    /// [`files::MAX_SCENARIO_BYTES`]); its relative paths are read beside it.
    pub fn file(path: &Path) -> Result<Self, Error> {
        Ok(Source {
            text: files::read_text(path, "scenario", files::MAX_SCENARIO_BYTES)?,
            base_dir: files::base_dir(path),
            name: path.display().to_string(),
            path: Some(path.to_path_buf()),
        })
    }
}

/// [`load_scenario`] for a scenario's text from anywhere (a file, the Python API).
pub fn load_source(source: &Source, sets: &[Set]) -> Result<Loaded, Error> {
    let (base_dir, name, path) = (
        source.base_dir.clone(),
        &source.name,
        source.path.as_deref(),
    );
    let input = |source: InputError| Error::Input {
        name: name.clone(),
        source: Box::new(source),
    };
    let text =
        tactile_scenario::overrides::apply(&source.text, sets).map_err(|e| input(e.into()))?;
    let with = if sets.is_empty() {
        String::new()
    } else {
        let s: Vec<&str> = sets.iter().map(|s| s.text.as_str()).collect();
        format!(" with --set {}", s.join(" --set "))
    };
    let scenario = Scenario::from_toml_str(&text).map_err(|e| {
        let msg = e.to_string();
        // A line and column would point into the changed text, not the user's file.
        let msg = match msg.strip_prefix("line ").and_then(|r| r.split_once(": ")) {
            Some((_, rest)) if !sets.is_empty() => rest.to_string(),
            _ => msg,
        };
        Error::BadInput(format!("{name}{with}: {}", msg.trim_end()))
    })?;
    super::recordable::check(&scenario, &base_dir).map_err(|e| match e {
        Error::BadInput(m) => Error::BadInput(format!("{name}{with}: {m}")),
        other => other,
    })?;
    if scenario.arithmetic == tactile_math::arith::ArithKind::Rtl {
        // A build without the RTL, or with the RTL of another format or geometry, is
        // refused before anything starts.
        let cordic = scenario
            .cordic
            .config()
            .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
        let geometry = scenario
            .device
            .geometry()
            .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
        tactile_rtl::check(cordic, geometry)
            .map_err(|e| Error::BadInput(format!("{name}: {}: {e}", e.field())))?;
    }
    if tactile_runtime::outside::ros_in_run(&scenario) && !cfg!(feature = "zenoh") {
        return Err(Error::BadInput(format!(
            "{name}: {}",
            tactile_runtime::outside::NO_ROS
        )));
    }
    files::inputs_present(&scenario, &base_dir).map_err(|e| input(e.into()))?;
    let source = OperatorSource::load(&scenario.operator, &base_dir)
        .map_err(|e| Error::BadInput(format!("{name}: operator: {e}")))?;
    source
        .check_six_dof(&scenario)
        .map_err(|e| Error::BadInput(format!("{name}{with}: {e}")))?;
    let mut warnings = scenario.warnings();
    warnings.extend(source.warnings(scenario.samples, scenario.t_s()));
    tactile_network_emulator::replay::load(&scenario, &base_dir).map_err(|e| input(e.into()))?;
    tactile_network_emulator::histogram::load(&scenario, &base_dir).map_err(|e| input(e.into()))?;
    tactile_slave::urdf_arm::UrdfArm::of_scenario(&scenario, &base_dir)
        .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
    // A physics world is built once here: its meshes read and checked, its bodies'
    // overlap at the start, its coupling and joints' stability at the substep.
    tactile_slave::world::SlaveWorld::of_scenario(&scenario, &base_dir)
        .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
    if scenario.master.backend == tactile_scenario::Backend::Ros2 {
        tactile_master::peripherals::gimbal(&scenario, &base_dir).map_err(|e| input(e.into()))?;
    }
    if tactile_runtime::outside::ros_in_run(&scenario) {
        tactile_devices::ros_side::check_tls(&scenario.ros, &base_dir)
            .map_err(|e| Error::BadInput(format!("{name}: {e}")))?;
    }
    let mut inputs: Vec<PathBuf> = path.map(Path::to_path_buf).into_iter().collect();
    inputs.extend(scenario.input_paths().iter().map(|p| base_dir.join(p)));
    Ok(Loaded {
        scenario,
        base_dir,
        inputs,
        warnings,
    })
}

/// The `--set KEY=VALUE` arguments, parsed (bad input when one is malformed).
pub fn parse_sets(args: &[String]) -> Result<Vec<Set>, Error> {
    args.iter()
        .map(|a| Set::parse(a).map_err(Error::from))
        .collect()
}

/// Every file a run writes into its output folder.
pub fn output_files(out: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = REPORT_FILES.iter().map(|f| out.join(f)).collect();
    for role in Role::ALL {
        v.push(out.join(format!("{role}.rec")));
        v.push(out.join(format!("{role}.log")));
    }
    v
}

/// Makes `out` ready for a new run: refuses if a file the run would write is one of
/// its inputs, then removes the files of an earlier run, so the folder never mixes
/// two runs' files, and copies the inputs in (see [`bundle`]). Returns the scenario to
/// run (the one that reads the copies) and the folder's lock, held for the run and its
/// report: a second run or report into the folder is refused meanwhile, nothing touched.
pub fn prepare_out(
    out: &Path,
    loaded: &Loaded,
) -> Result<(Loaded, tactile_report::out::OutLock), Error> {
    let holder = format!(
        "tactile run (pid {}, scenario {:?})",
        std::process::id(),
        loaded.scenario.name
    );
    let held = tactile_report::out::take(out, &holder)?;
    let outputs = output_files(out);
    let copies = out.join(INPUTS);
    for i in &loaded.inputs {
        if let Some(o) = outputs.iter().find(|o| same_file(o, i)) {
            return Err(Error::BadInput(format!(
                "--out {}: the run would overwrite its input {} (as {}); choose another output folder",
                out.display(),
                i.display(),
                o.display()
            )));
        }
        if within(i, &copies) {
            return Err(Error::BadInput(format!(
                "--out {}: its {INPUTS}/ holds the input {} this run would replace; choose another output folder",
                out.display(),
                i.display()
            )));
        }
    }
    for o in outputs {
        match std::fs::remove_file(&o) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(format!("removing {}", o.display()))(e)),
        }
    }
    match std::fs::remove_dir_all(&copies) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(Error::io(format!("removing {}", copies.display()))(e)),
    }
    Ok((bundle(out, loaded)?, held))
}

/// The folder of a run's output that holds copies of its input files.
pub const INPUTS: &str = "inputs";

/// True if `path` lies in `dir` (both as the file system resolves them).
fn within(path: &Path, dir: &Path) -> bool {
    match (std::fs::canonicalize(path), std::fs::canonicalize(dir)) {
        (Ok(p), Ok(d)) => p.starts_with(d),
        _ => false,
    }
}

/// Copies the scenario's input files into `out/inputs/` and points the scenario at
/// the copies (absolute paths, which the nodes need; the report's `scenario.toml`
/// makes them relative again), so the output folder holds everything a rerun reads
/// and editing an original input never changes a rerun.
fn bundle(out: &Path, loaded: &Loaded) -> Result<Loaded, Error> {
    let mut scenario = loaded.scenario.resolved(&loaded.base_dir);
    let dir = std::fs::canonicalize(out)
        .map_err(Error::io(format!("resolving {}", out.display())))?
        .join(INPUTS);
    let mut copied: Vec<(PathBuf, PathBuf)> = Vec::new();
    for path in scenario.input_paths_mut() {
        let src = PathBuf::from(path.as_str());
        let target = match copied.iter().find(|(s, _)| *s == src) {
            Some((_, t)) => t.clone(),
            None => {
                let name = src
                    .file_name()
                    .map_or_else(|| "input".into(), |n| n.to_string_lossy().into_owned());
                let mut target = dir.join(&name);
                if copied.iter().any(|(_, t)| *t == target) {
                    target = dir.join(format!("{}-{name}", copied.len()));
                }
                std::fs::create_dir_all(&dir)
                    .map_err(Error::io(format!("creating {}", dir.display())))?;
                std::fs::copy(&src, &target).map_err(Error::io(format!(
                    "copying {} into {}",
                    src.display(),
                    dir.display()
                )))?;
                copied.push((src, target.clone()));
                target
            }
        };
        *path = target.display().to_string();
    }
    Ok(Loaded {
        scenario,
        base_dir: dir
            .parent()
            .map_or_else(|| out.to_path_buf(), Path::to_path_buf),
        inputs: loaded.inputs.clone(),
        warnings: loaded.warnings.clone(),
    })
}
