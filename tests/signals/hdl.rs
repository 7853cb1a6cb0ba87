//! `tactile hdl` stops on SIGINT and SIGTERM within a second, with exit 130, its tools
//! killed with their own children and its work folder removed (issue 65: nextpnr
//! started after a SIGINT, and a SIGTERM left Yosys, nextpnr or vvp running under init
//! and `/tmp/tactile-hdl-PID-N` behind). With the real tools where they are installed
//! (skipped where not, a failure under CI=true), and with stand-ins for Yosys and
//! nextpnr for the place and route's steps.

use crate::hdl::have;
use crate::util::procs;
use crate::util::{cannot, Sandbox};
use rustix::process::Signal;
use std::path::Path;
use std::process::Child;

/// Starts `tactile hdl ARGS` with its temporary files in `tmp`.
fn start(sb: &Sandbox, args: &[&str], tmp: &Path) -> Child {
    let mut all = vec!["hdl"];
    all.extend_from_slice(args);
    procs::spawn(sb.command(&all).env("TMPDIR", tmp))
}

/// Waits until `tactile` (`parent`) runs the tool `name`; its PID.
fn tool_of(parent: u32, name: &str) -> i32 {
    let mut pid = None;
    crate::util::wait_for(&format!("{name} runs"), crate::util::LIMIT, || {
        pid = procs::children_named(parent as i32, name).first().copied();
        pid.is_some()
    });
    pid.unwrap_or_default()
}

/// Stops `child` with `sig` once its tool `name` runs: exit 130 within a second, the
/// tool's whole process group gone, `tmp` empty.
fn stopped_while_it_runs(child: Child, name: &str, sig: Signal, tmp: &Path) {
    let tool = tool_of(child.id(), name);
    // A moment into its work (Yosys makes its temporary folders as it goes).
    std::thread::sleep(std::time::Duration::from_millis(500));
    let err = procs::stopped(child, sig);
    assert!(err.contains(&format!("{name} killed")), "{err}");
    let left = procs::in_group(tool);
    assert!(left.is_empty(), "{name}'s processes left: {left:?}");
    procs::assert_empty(tmp);
}

/// `hdl cosim` over IK's pipeline for long: SIGINT while vvp simulates, then SIGTERM.
#[test]
fn cosim_stops_on_either_signal_with_vvp_and_its_work_folder() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    for sig in [Signal::INT, Signal::TERM] {
        let sb = Sandbox::new("sighdlcosim");
        let tmp = procs::tmp(&sb);
        let args = [
            "cosim",
            "--function",
            "ik",
            "--pipeline",
            "sample",
            "--count",
        ];
        let child = start(&sb, &[&args[..], &["200000"]].concat(), &tmp);
        stopped_while_it_runs(child, "vvp", sig, &tmp);
    }
}

/// `hdl synth` of IK for Virtex-6 (18 minutes): SIGTERM while Yosys runs.
#[test]
fn synth_stops_on_sigterm_with_yosys_and_its_work_folder() {
    if !have("yosys") {
        return cannot("yosys is not installed");
    }
    let sb = Sandbox::new("sighdlsynth");
    let tmp = procs::tmp(&sb);
    let child = start(&sb, &["synth", "--function", "ik"], &tmp);
    stopped_while_it_runs(child, "yosys", Signal::TERM, &tmp);
}

/// The stand-ins of `hdl timing`'s tools in `bin`, logging to `log`: Yosys busy
/// (`yosys_busy`) or done at once, nextpnr busy, answering `--version` for the probe.
fn stand_ins(bin: &Path, log: &Path, yosys_busy: bool) {
    std::fs::create_dir_all(log).expect("log");
    let yosys = if yosys_busy {
        procs::busy(log, "yosys")
    } else {
        "exit 0".into()
    };
    procs::script(bin, "yosys", &yosys);
    let pnr = format!(
        "if [ \"$1\" = --version ]; then echo nextpnr-0.11.1; exit 0; fi\n{}",
        procs::busy(log, "nextpnr")
    );
    procs::script(bin, "nextpnr-ecp5", &pnr);
}

/// `hdl timing`: SIGINT while Yosys synthesizes never starts nextpnr; SIGTERM while
/// nextpnr places kills it and its child. Stand-ins, so no minute of synthesis.
#[test]
fn timing_stops_on_either_signal_before_or_inside_nextpnr() {
    for (sig, in_yosys) in [(Signal::INT, true), (Signal::TERM, false)] {
        let sb = Sandbox::new("sighdltiming");
        let (tmp, bin, log) = (procs::tmp(&sb), sb.path("bin"), sb.path("log"));
        stand_ins(&bin, &log, in_yosys);
        let cmd = sb.command(&["hdl", "timing", "--function", "fbf"]);
        let child = procs::spawn(&mut procs::with_only(cmd, &bin, &tmp));
        let name = if in_yosys { "yosys" } else { "nextpnr" };
        let (tool, helper) = (
            procs::pid_in(&log.join(format!("{name}.pid"))),
            procs::pid_in(&log.join(format!("{name}.child"))),
        );
        let err = procs::stopped(child, sig);
        assert!(
            !procs::alive(tool) && !procs::alive(helper),
            "{name} runs on: {err}"
        );
        if in_yosys {
            assert!(!log.join("nextpnr.pid").exists(), "nextpnr started: {err}");
        }
        procs::assert_empty(&tmp);
    }
}

/// `hdl vectors` to a stdout nobody reads (its writes block): SIGINT ends it.
#[test]
fn vectors_stop_on_sigint_while_their_reader_does_not_read() {
    let sb = Sandbox::new("sighdlvec");
    let tmp = procs::tmp(&sb);
    let child = start(
        &sb,
        &["vectors", "--function", "ik", "--count", "1000000"],
        &tmp,
    );
    procs::wait_until_it_catches(child.id());
    // Until the pipe is full and the writes wait.
    std::thread::sleep(std::time::Duration::from_millis(500));
    let err = procs::stopped(child, Signal::INT);
    assert!(err.contains("vectors written so far"), "{err}");
}
