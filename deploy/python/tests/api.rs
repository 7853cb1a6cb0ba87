//! The Python package against the command: the module Cargo built for this test (the
//! crate's cdylib, beside this test's executable) laid out as maturin lays it out
//! beside the package's Python half, then pytest runs `tests/` against the
//! `tactile` binary: the same errors for the same bad input, the same resolved
//! scenario, a run's summary and trace equal to `tactile run --in-process`'s, a run
//! kept in memory, an arm's joints, the GIL released while a run computes, and a
//! SIGINT ending a run with its report kept while the next run runs whole.
//!
//! `cargo test` builds the module itself, before any test runs (this test needs the
//! package's library), so no build competes with the suite's timed tests.

use std::path::{Path, PathBuf};
use std::process::Command;

/// True if python3 can import `modules`.
fn python_has(modules: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A check that cannot run here: under CI (`CI=true`) it fails, since CI must prove
/// it; elsewhere it says so and the caller returns.
fn cannot(what: &str) {
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("this test cannot do what it must check: {what} (CI=true, so it fails instead of skipping)");
    }
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "SKIPPED: {what}");
}

/// This test's `deps` folder (the module's) and its profile folder (the binaries').
fn folders() -> (PathBuf, PathBuf) {
    let me = std::env::current_exe().expect("this test's executable");
    let deps = me.parent().expect("deps folder").to_path_buf();
    let profile = deps.parent().expect("profile folder").to_path_buf();
    (deps, profile)
}

/// The package as maturin lays it out: the Python half (its modules, and the shipped
/// scenarios and robots, which are links into `deploy/`: copied as files, as maturin
/// puts them in the wheel), the module as `_native`.
fn package(site: &Path, module: &Path) {
    let pkg = site.join("tactile");
    copy_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("python/tactile"),
        &pkg,
    );
    std::fs::copy(module, pkg.join("_native.abi3.so")).expect("copy the module");
}

/// `from` into `to`, links followed; Python's caches left out.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("package folder");
    for e in std::fs::read_dir(from).expect("the Python half") {
        let path = e.expect("an entry").path();
        if path.file_name().is_some_and(|n| n == "__pycache__") {
            continue;
        }
        let target = to.join(path.file_name().expect("a name"));
        if path.is_dir() {
            copy_tree(&path, &target);
        } else {
            std::fs::copy(&path, &target).expect("copy the Python half");
        }
    }
}

#[test]
fn the_python_package_runs_what_the_command_runs() {
    if !python_has("pyarrow, pandas, pytest") {
        return cannot("python3 lacks pyarrow, pandas or pytest (tests/requirements.txt)");
    }
    let (deps, profile) = folders();
    let module = deps.join("lib_native.so");
    let tactile = profile.join("tactile");
    assert!(module.is_file(), "{} was not built", module.display());
    if !tactile.is_file() {
        // `cargo test --workspace` builds it (the tactile package's tests need it).
        return cannot("no tactile binary beside this test: cargo test --workspace builds it");
    }
    let dir = tempfile::Builder::new()
        .prefix("tactile-python-")
        .tempdir()
        .expect("temp dir");
    let site = dir.path().join("site");
    package(&site, &module);
    let work = dir.path().join("work");
    std::fs::create_dir_all(&work).expect("work folder");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let o = Command::new("python3")
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "--basetemp"])
        .arg(&work)
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests"))
        .env("PYTHONPATH", &site)
        .env("TACTILE_BIN", &tactile)
        .env("TACTILE_ROOT", &root)
        .output()
        .expect("python3");
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "pytest: {text}");
    // Every test ran: none skipped, none deselected.
    assert!(
        text.contains(" passed") && !text.contains("skipped"),
        "{text}"
    );
}
