//! The nodes' logs as files: plain text whoever started the nodes, so a log reads the
//! same in an editor, a grep or a bug report as on the terminal.

use crate::util::{self, Sandbox};

use std::path::Path;
use std::process::Stdio;

/// The `*.log` files in `dir` (at least one), each with whether it holds an ESC byte,
/// the start of every colour code.
fn logs(dir: &Path) -> Vec<(String, bool)> {
    let found: Vec<(String, bool)> = std::fs::read_dir(dir)
        .expect("folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "log"))
        .map(|p| {
            let bytes = std::fs::read(&p).expect("log");
            assert!(!bytes.is_empty(), "{} is empty", p.display());
            (p.display().to_string(), bytes.contains(&0x1b))
        })
        .collect();
    assert!(!found.is_empty(), "no log in {}", dir.display());
    found
}

#[test]
fn logs_written_to_files_carry_no_colour_codes() {
    let sb = Sandbox::new("plainlogs");
    let scenario = sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 300"),
    );
    // Under `tactile run`: each node's log, into which the launcher sends its stderr.
    sb.run(&scenario, "run");
    let mut checked = logs(&sb.path("run"));
    assert_eq!(checked.len(), 3, "{checked:?}");
    // Started by hand with stderr sent to a file (a script, ssh, a service): the
    // node's copy of its log on stderr, beside its own log file.
    let errs = sb.path("stderr");
    std::fs::create_dir_all(&errs).expect("folder");
    let nodes: Vec<_> = ["master", "emulator", "slave"]
        .into_iter()
        .map(|role| {
            let err = std::fs::File::create(errs.join(format!("{role}.log"))).expect("file");
            let node = sb
                .node(
                    &format!("tactile-{role}"),
                    &[
                        "--scenario",
                        scenario.to_str().expect("utf-8"),
                        "--out",
                        "hand",
                        "--prefix",
                        &sb.prefix,
                    ],
                )
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(err)
                .spawn()
                .expect("start node");
            (role, node)
        })
        .collect();
    for (role, node) in nodes {
        let (code, _) = util::finish(node);
        assert_eq!(code, Some(0), "{role}");
    }
    for dir in ["hand", "stderr"] {
        checked.extend(logs(&sb.path(dir)));
    }
    assert_eq!(checked.len(), 9, "{checked:?}");
    let coloured: Vec<&String> = checked.iter().filter(|l| l.1).map(|l| &l.0).collect();
    assert!(coloured.is_empty(), "colour codes in {coloured:?}");
}
