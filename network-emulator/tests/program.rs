//! The `tactile-emulator` program's refusals: a bad scenario names the file and the
//! field, exits 2, and starts nothing.

use std::process::Command;

#[test]
fn a_bad_scenario_names_the_field_and_starts_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(
        dir.path().join("s.toml"),
        "[network.forward]\ndelay = [1, -2, 0]\n",
    )
    .expect("write");
    let o = Command::new(env!("CARGO_BIN_EXE_tactile-emulator"))
        .args(["--scenario", "s.toml", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .expect("start tactile-emulator");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("s.toml") && err.contains("network.forward.delay"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
}
