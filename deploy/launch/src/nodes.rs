//! Finding the node programs (`tactile-master`, `tactile-emulator`, `tactile-slave`).
//!
//! `cargo run` builds only the `tactile` package, so on a fresh clone the node programs
//! do not exist yet. When the launcher runs from a Cargo target folder of its source
//! tree, it asks Cargo to build them in the same profile (a no-op when they are up to
//! date, so they never lag behind the launcher). Otherwise it takes them from beside
//! its own executable or from `PATH`, and says what to do when they are in neither.
//! `TACTILE_NODE_DIR` names their folder outright (the tests use it).

use crate::error::Error;
use crate::stop::ToolError;
use std::path::{Path, PathBuf};
use std::process::Command;
use tactile_messages::Role;

/// The executable of `role` in `dir`.
pub fn exe(dir: &Path, role: Role) -> PathBuf {
    dir.join(role.program())
}

fn all_in(dir: &Path) -> bool {
    Role::ALL.iter().all(|r| exe(dir, *r).is_file())
}

/// The Cargo profile a target folder holds (`debug` is the dev profile).
fn profile_args(dir: &Path) -> Option<Vec<String>> {
    let name = dir.file_name()?.to_str()?;
    Some(match name {
        "debug" => vec![],
        "release" => vec!["--release".into()],
        other => vec!["--profile".into(), other.into()],
    })
}

/// Why the node programs could not be built (the launcher then looks for built ones).
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// The source tree the launcher was built from is not there any more.
    #[error("the source tree {} is gone", .0.display())]
    TreeGone(PathBuf),
    /// The launcher is not in a Cargo target folder's profile folder.
    #[error("no target folder")]
    NoTarget,
    /// The same, its profile folder unnamed.
    #[error("no profile folder")]
    NoProfile,
    /// Cargo could not be started.
    #[error("cannot run cargo: {0}")]
    Start(#[source] std::io::Error),
    /// A stop request ended the build.
    #[error("stopped by a signal")]
    Stopped,
    /// Waiting for Cargo failed.
    #[error("running cargo: {0}")]
    Wait(#[source] std::io::Error),
    /// Cargo failed; the last lines it said.
    #[error("{0}")]
    Failed(String),
}

/// The manifest of the workspace this launcher was built from (this crate is
/// deploy/launch: two folders up), whose node programs it builds.
fn workspace_manifest() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../Cargo.toml")
}

/// Builds the node programs into `dir` (a Cargo target profile folder) from the
/// source tree this launcher was built from.
fn cargo_build(dir: &Path) -> Result<(), BuildError> {
    let manifest = workspace_manifest();
    if !manifest.is_file() {
        return Err(BuildError::TreeGone(manifest));
    }
    let target = dir.parent().ok_or(BuildError::NoTarget)?;
    let profile = profile_args(dir).ok_or(BuildError::NoProfile)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.arg("build")
        .arg("--quiet")
        .arg("--manifest-path")
        .arg(&manifest)
        .arg("--target-dir")
        .arg(target)
        .args(profile)
        // With `tactile` in the set, Cargo resolves the same features as the `cargo
        // run` that built this launcher, so nothing it built is compiled again.
        .args([
            "-p",
            "tactile",
            "-p",
            "tactile-master",
            "-p",
            "tactile-network-emulator",
            "-p",
            "tactile-slave",
            "--bins",
        ])
        // The node programs link Zenoh, and simulate the RTL, when the launcher does.
        .args(
            cfg!(feature = "zenoh")
                .then_some(["--features", "tactile/zenoh"])
                .into_iter()
                .flatten(),
        )
        .args(
            cfg!(feature = "rtl")
                .then_some(["--features", "tactile/rtl"])
                .into_iter()
                .flatten(),
        );
    // Its own process group, killed on a stop request: a launcher stopped while it
    // builds leaves no build running.
    let out = crate::stop::run_tool(&mut cmd).map_err(|e| match e {
        ToolError::Start(e) => BuildError::Start(e),
        ToolError::Stopped => BuildError::Stopped,
        ToolError::Wait(e) => BuildError::Wait(e),
    })?;
    if out.status.success() {
        Ok(())
    } else {
        let err = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = err.lines().rev().take(8).collect();
        Err(BuildError::Failed(
            tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
        ))
    }
}

/// The folder holding all three node programs, built first where that is possible.
pub fn node_dir() -> Result<PathBuf, Error> {
    if let Some(d) = std::env::var_os("TACTILE_NODE_DIR") {
        let d = PathBuf::from(d);
        return if all_in(&d) {
            Ok(d)
        } else {
            Err(Error::Failed(format!(
                "TACTILE_NODE_DIR={} does not hold tactile-master, tactile-emulator and tactile-slave",
                d.display()
            )))
        };
    }
    let me = std::env::current_exe().map_err(Error::io("locating the tactile executable"))?;
    let dir = me
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let in_cargo_target = dir.join(".fingerprint").is_dir();
    let mut why = None;
    if in_cargo_target {
        if !all_in(&dir) {
            crate::noteln!("tactile: building the node programs (once)...");
        }
        // A build takes minutes on a fresh clone: SIGINT and SIGTERM stop it.
        crate::stop::watch()?;
        why = cargo_build(&dir).err();
        crate::stop::check("the node programs' build stopped; nothing was run")?;
    }
    if all_in(&dir) {
        if let Some(w) = &why {
            crate::noteln!(
                "tactile: warning: could not rebuild the node programs, using those in {}: {w}",
                dir.display()
            );
        }
        return Ok(dir);
    }
    if let Some(path) = std::env::var_os("PATH") {
        if let Some(d) = std::env::split_paths(&path).find(|d| all_in(d)) {
            return Ok(d);
        }
    }
    Err(Error::Failed(format!(
        "cannot find tactile-master, tactile-emulator and tactile-slave beside {} or on PATH{}; build them with `cargo build --release --workspace` (or set TACTILE_NODE_DIR to their folder)",
        me.display(),
        why.map_or(String::new(), |w| format!(" (building them failed: {w})"))
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// The build asks the workspace for the node programs, not a package's manifest
    /// (which would not know them).
    #[test]
    fn the_build_names_the_workspaces_manifest() {
        let text = std::fs::read_to_string(workspace_manifest()).expect("the manifest");
        assert!(
            text.contains("[workspace]"),
            "{}",
            workspace_manifest().display()
        );
        assert!(
            text.contains("\"slave\""),
            "the workspace holds the node programs"
        );
    }

    #[test]
    fn a_build_that_cannot_start_keeps_the_systems_reason() {
        let e = BuildError::Start(std::io::Error::from(std::io::ErrorKind::NotFound));
        assert!(e.to_string().starts_with("cannot run cargo: "), "{e}");
        assert!(e.source().is_some_and(|c| c.is::<std::io::Error>()));
    }
}
