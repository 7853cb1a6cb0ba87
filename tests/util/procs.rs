//! Processes and stand-in tools for the tests that stop a command: which processes
//! run (from /proc), stopping one with a signal and timing its end, a temporary
//! folder of its own, and shell scripts that stand in for a tool on PATH.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How soon a stopped command must have ended: the issue asks for a second; the
/// bound leaves room for a loaded CI machine, as the other signal tests do.
pub const STOPPED_WITHIN: Duration = Duration::from_secs(3);

/// The fields of `/proc/PID/stat` after the command name: state, parent, group.
fn stat(pid: i32) -> Option<(char, i32, i32)> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &text[text.rfind(')')? + 1..];
    let mut f = rest.split_whitespace();
    let state = f.next()?.chars().next()?;
    let parent = f.next()?.parse().ok()?;
    let group = f.next()?.parse().ok()?;
    Some((state, parent, group))
}

/// True while process `pid` runs (a zombie, which init may not have reaped yet in a
/// container, has ended).
pub fn alive(pid: i32) -> bool {
    stat(pid).is_some_and(|(state, _, _)| state != 'Z')
}

/// Every running process, with its parent and process group.
fn all() -> Vec<(i32, i32, i32)> {
    std::fs::read_dir("/proc")
        .expect("/proc")
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse::<i32>().ok())
        .filter_map(|pid| {
            stat(pid)
                .filter(|(s, _, _)| *s != 'Z')
                .map(|(_, parent, group)| (pid, parent, group))
        })
        .collect()
}

/// The running children of `pid` that `keep` keeps.
fn children(pid: i32, keep: impl Fn(i32) -> bool) -> Vec<i32> {
    all()
        .into_iter()
        .filter(|&(child, parent, _)| parent == pid && keep(child))
        .map(|(child, _, _)| child)
        .collect()
}

/// The running children of `pid` named `name` (their `comm`).
pub fn children_named(pid: i32, name: &str) -> Vec<i32> {
    children(pid, |child| {
        std::fs::read_to_string(format!("/proc/{child}/comm")).is_ok_and(|c| c.trim() == name)
    })
}

/// The running children of `pid` whose command line holds the argument `arg` (a
/// child between its fork and its exec has its parent's command line, and name).
pub fn children_running(pid: i32, arg: &str) -> Vec<i32> {
    children(pid, |child| {
        std::fs::read(format!("/proc/{child}/cmdline"))
            .is_ok_and(|c| c.split(|b| *b == 0).any(|a| a == arg.as_bytes()))
    })
}

/// The running processes of process group `group`.
pub fn in_group(group: i32) -> Vec<i32> {
    all()
        .into_iter()
        .filter(|&(_, _, g)| g == group)
        .map(|(pid, _, _)| pid)
        .collect()
}

/// Starts `cmd` with its stdin, stdout and stderr piped to the test.
pub fn spawn(cmd: &mut Command) -> Child {
    cmd.stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start")
}

/// Sends `sig` to `child`, waits for its end: its exit status, its stderr, and how
/// long it took after the signal.
pub fn stop(child: Child, sig: rustix::process::Signal) -> (Option<i32>, String, Duration) {
    let pid = rustix::process::Pid::from_raw(child.id() as i32).expect("pid");
    let asked = Instant::now();
    let _ = rustix::process::kill_process(pid, sig);
    let (code, err) = super::finish(child);
    (code, err, asked.elapsed())
}

/// Stops `child` with `sig` and checks that it ended as a stop does: exit 130 within
/// [`STOPPED_WITHIN`]. Its stderr.
pub fn stopped(child: Child, sig: rustix::process::Signal) -> String {
    let (code, err, took) = stop(child, sig);
    assert_eq!(code, Some(130), "{sig:?}: {err}");
    assert!(
        took < STOPPED_WITHIN,
        "stopped {took:?} after {sig:?}: {err}"
    );
    err
}

/// Waits until `pid` answers SIGINT and SIGTERM itself (its handlers installed): from
/// then a signal is a stop request, not its end.
pub fn wait_until_it_catches(pid: u32) {
    use rustix::process::Signal;
    super::wait_for(
        "the command catches SIGINT and SIGTERM",
        super::LIMIT,
        || super::catches(pid, Signal::INT) && super::catches(pid, Signal::TERM),
    );
}

/// An empty folder for a command's temporary files (its TMPDIR), to check that it
/// left none.
pub fn tmp(sb: &super::Sandbox) -> PathBuf {
    let t = sb.path("tmp");
    std::fs::create_dir_all(&t).expect("tmp");
    t
}

/// Fails if the folder `tmp` holds anything.
pub fn assert_empty(tmp: &Path) {
    let left: Vec<_> = std::fs::read_dir(tmp)
        .expect("tmp")
        .flatten()
        .map(|e| e.path())
        .collect();
    assert!(left.is_empty(), "temporary files left behind: {left:?}");
}

/// Writes an executable shell script `name` into `dir` with `body` (the script sees
/// PATH=/usr/bin:/bin whatever PATH found it).
pub fn script(dir: &Path, name: &str, body: &str) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    std::fs::create_dir_all(dir).expect("bin");
    let p = dir.join(name);
    std::fs::write(&p, format!("#!/bin/sh\nPATH=/usr/bin:/bin\n{body}\n")).expect("script");
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    p
}

/// A stand-in tool's body that writes its PID to `LOG/NAME.pid` and its child's to
/// `LOG/NAME.child`, then waits for that child (a minute's sleep), as a tool busy
/// with its own helper process.
pub fn busy(log: &Path, name: &str) -> String {
    let at = log.display();
    format!("echo $$ > {at}/{name}.pid\nsleep 60 &\necho $! > {at}/{name}.child\nwait")
}

/// The PID a stand-in wrote into `path`, once it has.
pub fn pid_in(path: &Path) -> i32 {
    let mut pid = None;
    super::wait_for(&format!("{} written", path.display()), super::LIMIT, || {
        pid = std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.trim().parse().ok());
        pid.is_some()
    });
    pid.unwrap_or_default()
}

/// `cmd` with PATH set to `bin` alone (no real tool found) and TMPDIR to `tmp`.
pub fn with_only(mut cmd: Command, bin: &Path, tmp: &Path) -> Command {
    cmd.env("PATH", bin).env("TMPDIR", tmp);
    cmd
}
