//! The `tactile-slave` program's refusals: missing arguments and unusable files.

use std::process::Command;

fn slave(args: &[&str], cwd: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tactile-slave"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("start tactile-slave")
}

#[test]
fn missing_arguments_and_unusable_files_exit_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = slave(&["--out", "out"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--scenario"));
    for (scenario, want) in [
        (".", "is a folder"),
        ("/dev/zero", "not a regular file"),
        ("nowhere.toml", "nowhere.toml"),
    ] {
        let o = slave(&["--scenario", scenario, "--out", "out"], dir.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{scenario}: {err}");
        assert!(err.contains(want), "{scenario}: {err}");
        assert!(!dir.path().join("out").exists());
    }
}
