//! The Python package (`deploy/python`, issue 53) against the command: the module is
//! built as `pip install ./deploy/python` builds it (the `tactile-py` crate's cdylib
//! beside the package's Python half), then tests/python_api.py checks it against the
//! `tactile` binary: the same errors for the same bad input, the same resolved
//! scenario, a run's summary and trace equal to `tactile run --in-process`'s, a run
//! kept in memory, an arm's joints, the GIL released while a run computes, and a
//! SIGINT ending a run with its report kept while the next run runs whole.

use crate::util::{self, cannot, Sandbox};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Builds the module in this test's profile and target folder (a no-op when it is up
/// to date; the features the test binary was built with, so nothing else compiles
/// again) and returns the shared library.
fn build_module() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let bin = Path::new(env!("CARGO_BIN_EXE_tactile"));
    let profile_dir = bin.parent().expect("profile folder");
    let target = profile_dir.parent().expect("target folder");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut c = Command::new(cargo);
    // What Cargo set for this test (its package's name, manifest, binaries) would reach
    // build scripts that watch it (ring's) and make Cargo build them, and all that
    // depends on them, again: the build runs with the environment the test's own
    // build had.
    for (k, _) in std::env::vars_os() {
        let k = k.to_string_lossy();
        let set_for_the_test = [
            "PKG_",
            "MANIFEST_",
            "CRATE_",
            "BIN_",
            "PRIMARY_",
            "TARGET_TMPDIR",
        ]
        .iter()
        .any(|p| k.strip_prefix("CARGO_").is_some_and(|r| r.starts_with(p)));
        if set_for_the_test || k == "OUT_DIR" {
            c.env_remove(k.as_ref());
        }
    }
    c.args(["build", "--quiet", "-p", "tactile-py", "--manifest-path"])
        .arg(root.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(target);
    match profile_dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") | None => {}
        Some("release") => {
            c.arg("--release");
        }
        Some(other) => {
            c.args(["--profile", other]);
        }
    }
    for (on, feature) in [
        (cfg!(feature = "zenoh"), "tactile-py/zenoh"),
        (cfg!(feature = "rtl"), "tactile-py/rtl"),
    ] {
        if on {
            c.args(["--features", feature]);
        }
    }
    let o = util::output_within(c, util::LIMIT);
    assert!(
        o.status.success(),
        "building tactile-py: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    profile_dir.join("lib_native.so")
}

/// The package as maturin lays it out: the Python half, the module as `_native`.
fn package(sb: &Sandbox, module: &Path) -> PathBuf {
    let site = sb.path("site");
    let pkg = site.join("tactile");
    std::fs::create_dir_all(&pkg).expect("package folder");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("python/python/tactile");
    for f in ["__init__.py", "_native.pyi", "py.typed"] {
        std::fs::copy(src.join(f), pkg.join(f)).expect("copy the Python half");
    }
    std::fs::copy(module, pkg.join("_native.abi3.so")).expect("copy the module");
    site
}

#[test]
fn the_python_package_runs_what_the_command_runs() {
    if !util::python_has("pyarrow") {
        return cannot("python3 lacks pyarrow");
    }
    let sb = Sandbox::new("python");
    let site = package(&sb, &build_module());
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let work = sb.path("work");
    std::fs::create_dir_all(&work).expect("work folder");
    let mut c = Command::new("python3");
    c.arg(root.join("tests/python_api.py"))
        .arg(env!("CARGO_BIN_EXE_tactile"))
        .arg(&work)
        .arg(&root)
        .env("PYTHONPATH", &site);
    let o = util::output_within(c, util::LIMIT);
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "python_api.py: {text}");
    assert!(
        text.contains("ok ctrl_c_stops_a_run_keeps_its_report_and_the_next_runs"),
        "{text}"
    );
}
