//! The `tactile-master` program's own command line: help, exit statuses, and refusals
//! before anything starts. (The loop itself is tested with all three programs in the
//! workspace's `tests/`.)

use std::process::Command;

fn master(args: &[&str], cwd: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactile-master"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("start tactile-master")
}

#[test]
fn help_names_the_options_and_the_exit_statuses() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = master(&["--help"], dir.path());
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for want in [
        "--scenario",
        "--out",
        "--prefix",
        "--link",
        "--startup-timeout-s",
        "Exit status",
        "130",
    ] {
        assert!(help.contains(want), "{want} missing from:\n{help}");
    }
}

#[test]
fn a_bad_prefix_or_timeout_is_refused_before_anything_starts() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("s.toml"), "name = \"x\"\n").expect("write");
    for (args, want) in [
        (vec!["--prefix", "a/b"], "character '/'"),
        (vec!["--prefix", ""], "1 to 24"),
        (vec!["--startup-timeout-s", "0"], "--startup-timeout-s"),
        (vec!["--startup-timeout-s", "NaN"], "--startup-timeout-s"),
    ] {
        let mut all = vec!["--scenario", "s.toml", "--out", "out"];
        all.extend(args);
        let o = master(&all, dir.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(want), "{all:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            !dir.path().join("out").exists(),
            "{all:?} created the output folder"
        );
    }
}
