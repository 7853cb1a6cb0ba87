//! Shared helpers of the integration tests: each test gets its own temporary folder and
//! its own iceoryx2 prefix, so tests run in parallel without seeing each other, and
//! every test checks that no process of its run is left behind.

#![allow(dead_code)]

pub mod ports;
pub mod procs;

#[cfg(feature = "zenoh")]
pub use ports::free_port;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicU32, Ordering};

static COUNTER: AtomicU32 = AtomicU32::new(0);

/// The longest any command of a test may take: past it the command is killed and the
/// test fails, so a hung process never hangs CI.
pub const LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

/// Runs `cmd` to its end and returns its output; kills it and fails the test if it
/// takes longer than `limit`.
pub fn output_within(mut cmd: Command, limit: std::time::Duration) -> Output {
    let child = cmd
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start");
    wait_within(child, limit)
}

/// Waits for `child` and returns its output; kills it and fails the test if it takes
/// longer than `limit`.
pub fn wait_within(child: std::process::Child, limit: std::time::Duration) -> Output {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let pid = rustix::process::Pid::from_raw(child.id() as i32).expect("pid");
    let done = Arc::new(AtomicBool::new(false));
    let timed_out = Arc::new(AtomicBool::new(false));
    let watchdog = {
        let (done, timed_out) = (Arc::clone(&done), Arc::clone(&timed_out));
        std::thread::spawn(move || {
            let start = std::time::Instant::now();
            while !done.load(Ordering::SeqCst) {
                if start.elapsed() > limit {
                    timed_out.store(true, Ordering::SeqCst);
                    let _ = rustix::process::kill_process(pid, rustix::process::Signal::KILL);
                    return;
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
        })
    };
    let out = child.wait_with_output().expect("wait");
    done.store(true, Ordering::SeqCst);
    let _ = watchdog.join();
    assert!(
        !timed_out.load(Ordering::SeqCst),
        "a command ran past {limit:?} and was killed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// One test's sandbox.
pub struct Sandbox {
    /// Temporary folder, removed on drop.
    pub dir: tempfile::TempDir,
    /// iceoryx2 prefix unique to this test.
    pub prefix: String,
}

impl Sandbox {
    /// A fresh sandbox named after the test.
    pub fn new(name: &str) -> Sandbox {
        let n = COUNTER.fetch_add(1, Ordering::SeqCst);
        let prefix = format!("tt{}x{n}{}", std::process::id(), &name[..name.len().min(8)]);
        Sandbox {
            dir: tempfile::Builder::new()
                .prefix(&format!("tactile-{name}-"))
                .tempdir()
                .expect("temp dir"),
            prefix,
        }
    }

    /// Path inside the sandbox.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Writes a file into the sandbox and returns its path.
    pub fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, text).expect("write file");
        p
    }

    /// `tactile` with `args`, in the sandbox, finding the node programs beside it.
    pub fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new(env!("CARGO_BIN_EXE_tactile"));
        c.args(args)
            .current_dir(self.dir.path())
            .env("TACTILE_NODE_DIR", node_dir());
        c
    }

    /// A node program (`tactile-master`, ...) with `args`, in the sandbox.
    pub fn node(&self, program: &str, args: &[&str]) -> Command {
        let mut c = Command::new(node_dir().join(program));
        c.args(args).current_dir(self.dir.path());
        c
    }

    /// Runs `tactile` with `args`, within [`LIMIT`].
    pub fn tactile(&self, args: &[&str]) -> Output {
        output_within(self.command(args), LIMIT)
    }

    /// `tactile run SCENARIO --out OUT --prefix PREFIX -q` (OUT relative to the
    /// sandbox), whatever its outcome.
    pub fn try_run(&self, scenario: &Path, out: &str) -> Output {
        let out_dir = self.path(out);
        self.tactile(&[
            "run",
            scenario.to_str().expect("utf-8 path"),
            "--out",
            out_dir.to_str().expect("utf-8 path"),
            "--prefix",
            &self.prefix,
            "-q",
        ])
    }

    /// `tactile run SCENARIO --out OUT --prefix PREFIX -q EXTRA...` started, not waited
    /// for (OUT relative to the sandbox), its output piped: for the tests that act on a
    /// run while it goes (signals, kills, a second run beside it).
    pub fn spawn_run(
        &self,
        scenario: &Path,
        out: impl AsRef<Path>,
        extra: &[&str],
    ) -> std::process::Child {
        self.command(&["run", scenario.to_str().expect("utf-8 path"), "--out"])
            .arg(self.dir.path().join(out))
            .args(["--prefix", &self.prefix, "-q"])
            .args(extra)
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start tactile run")
    }

    /// [`Sandbox::try_run`]; asserts success and that no process of the run survives.
    pub fn run(&self, scenario: &Path, out: &str) -> Output {
        let o = self.try_run(scenario, out);
        assert!(
            o.status.success(),
            "tactile run failed: {}\nstdout:\n{}\nstderr:\n{}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        self.assert_no_leftover_processes();
        o
    }

    /// `tactile run SCENARIO --in-process --out OUT`: the reference the process runs are
    /// compared against; asserts success.
    pub fn simulate(&self, scenario: &Path, out: &str) {
        let o = self.tactile(&[
            "run",
            scenario.to_str().expect("utf-8 path"),
            "--in-process",
            "--out",
            self.path(out).to_str().expect("utf-8 path"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }

    /// `tactile run` of the scenario `text` (written as `bad{k}.toml`) must exit 2
    /// with `want` in its error, and start nothing (no record written).
    pub fn assert_refused(&self, k: usize, text: &str, want: &str) {
        let s = self.write(&format!("bad{k}.toml"), text);
        let out = format!("out{k}");
        let o = self.tactile(&["run", s.to_str().expect("utf-8"), "--out", &out, "-q"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {k}: {err}");
        assert!(err.contains(want), "case {k}: want {want:?} in {err}");
        assert!(
            !self.path(&out).join("slave.rec").exists(),
            "case {k}: started"
        );
    }

    /// Fails if any process started with this sandbox's prefix is still alive.
    pub fn assert_no_leftover_processes(&self) {
        // Bench runs use the prefix as a stem (prefix + run name).
        let needle = format!("--prefix\0{}", self.prefix);
        let mut alive = Vec::new();
        for entry in std::fs::read_dir("/proc").expect("/proc").flatten() {
            let Ok(cmd) = std::fs::read(entry.path().join("cmdline")) else {
                continue;
            };
            let cmd = String::from_utf8_lossy(&cmd).to_string();
            if cmd.contains(&needle) && cmd.contains("tactile-") {
                // A zombie has an empty cmdline, so anything here is really running.
                alive.push(cmd.replace('\0', " "));
            }
        }
        assert!(alive.is_empty(), "processes left behind: {alive:?}");
    }

    /// Reads a JSON file of a run.
    pub fn json(&self, out: &str, file: &str) -> serde_json::Value {
        let text = std::fs::read_to_string(self.path(out).join(file)).expect("read json");
        serde_json::from_str(&text).expect("parse json")
    }

    /// `tactile run SCENARIO --in-process --set SET` must be refused as bad input:
    /// exit status 2, one line on stderr containing `needle`, nothing written.
    pub fn assert_bad_set(&self, scenario: &str, set: &str, needle: &str) {
        let out = format!("bad-{}", set.len());
        let o = self.tactile(&["run", scenario, "--in-process", "--out", &out, "--set", set]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(
            err.contains(needle) && err.lines().count() == 1,
            "{set}: {err}"
        );
        assert!(!self.path(&out).exists(), "{set}: nothing is written");
    }

    /// Reads a run's trace.
    pub fn trace(&self, out: &str) -> String {
        std::fs::read_to_string(self.path(out).join("trace.csv")).expect("read trace")
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        tactile_transport::ipc::remove_run_files(&self.prefix);
    }
}

/// The folder of the node programs: beside the `tactile` binary Cargo built for the
/// tests (`cargo test --workspace` builds them: each node package has tests of its own).
pub fn node_dir() -> PathBuf {
    Path::new(env!("CARGO_BIN_EXE_tactile"))
        .parent()
        .expect("bin folder")
        .to_path_buf()
}

/// PID of the running node `role` (`master`, `emulator`, `slave`) of run `prefix`.
pub fn pid_of(prefix: &str, role: &str) -> Option<i32> {
    let program = format!("tactile-{role}\0");
    let prefix = format!("--prefix\0{prefix}\0");
    std::fs::read_dir("/proc").ok()?.flatten().find_map(|e| {
        let pid: i32 = e.file_name().to_str()?.parse().ok()?;
        let cmd =
            String::from_utf8_lossy(&std::fs::read(e.path().join("cmdline")).ok()?).to_string();
        (cmd.contains(&program) && cmd.contains(&prefix)).then_some(pid)
    })
}

/// A trace's tracking, sample by sample: the distance from the slave's tool to the
/// position it received (`tool` against `v`, m) and the contact force along z (`h_3`,
/// N; zero in free space).
pub fn tracking(trace: &str) -> Vec<(f64, f64)> {
    let t = [1, 2, 3].map(|i| column(trace, &format!("tool_{i}")));
    let v = [1, 2, 3].map(|i| column(trace, &format!("v_{i}")));
    let h = column(trace, "h_3");
    (0..h.len())
        .map(|k| {
            let e = (0..3).map(|i| (t[i][k] - v[i][k]).powi(2)).sum::<f64>();
            (e.sqrt(), h[k])
        })
        .collect()
}

/// The largest tracking error among samples `from..` in free space, and how many.
pub fn free_space_error(trace: &str, from: usize) -> (f64, usize) {
    let free: Vec<f64> = tracking(trace)
        .into_iter()
        .skip(from)
        .filter(|(_, h)| *h == 0.0)
        .map(|(e, _)| e)
        .collect();
    (free.iter().copied().fold(0.0, f64::max), free.len())
}

/// The minimum-jerk profile at `s` (0 to 1, clamped): 0 to 1 with no velocity or
/// acceleration at either end, as the operators' strokes are.
pub fn min_jerk(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

/// The trace's signal columns (everything before the first timing column): what
/// repeats bit for bit between an in-process run and one as processes.
pub fn signals(trace: &str) -> String {
    let header = trace.lines().next().expect("header");
    let cut = header
        .split(',')
        .position(|c| c == "round_trip_ns")
        .expect("timing columns");
    trace
        .lines()
        .map(|l| l.split(',').take(cut).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Column `name` of a CSV text as numbers.
pub fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).expect("cell").parse().expect("number"))
        .collect()
}

/// Sample standard deviation.
pub fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The shipped wall-delay scenario (a 600 N/m wall, round trip 50 ms at 1 kHz).
pub fn wall_delay() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/wall-delay.toml");
    std::fs::read_to_string(path).expect("deploy/scenarios/wall-delay.toml")
}

/// `deploy/scenarios/wall-change.toml`: wall-delay at 200 ms in a world that changes.
pub fn wall_change() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/wall-change.toml");
    std::fs::read_to_string(path).expect("deploy/scenarios/wall-change.toml")
}

/// The scenario `text` (written as `s.toml` in the sandbox) run twice in-process,
/// into `a` and `b`: the same trace byte for byte, returned.
pub fn run_twice(sb: &Sandbox, text: &str) -> String {
    let s = sb.write("s.toml", text);
    let s = s.to_str().expect("utf-8");
    for out in ["a", "b"] {
        let o = sb.tactile(&["run", s, "--in-process", "--out", out, "-q"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let trace = sb.trace("a");
    assert_eq!(trace, sb.trace("b"), "the same scenario twice, one run");
    trace
}

/// The paper scenario at 1 kHz in real time, `samples` samples.
pub fn paper_1khz(samples: u64) -> String {
    tactile_launch::PAPER_SCENARIO
        .replace("rate_hz = 100.0", "rate_hz = 1000.0")
        .replace("samples = 1200", &format!("samples = {samples}"))
}

/// Starts node `role` by hand with its own output folder `dir` (relative to the
/// sandbox), under the sandbox's prefix.
pub fn start_node(
    sb: &Sandbox,
    role: &str,
    scenario: &Path,
    dir: &str,
    extra: &[&str],
) -> std::process::Child {
    let mut args = vec![
        "--scenario",
        scenario.to_str().expect("utf-8"),
        "--out",
        dir,
    ];
    args.extend(["--prefix", &sb.prefix]);
    args.extend_from_slice(extra);
    sb.node(&format!("tactile-{role}"), &args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start node")
}

/// Waits for a node to end: its exit status and its stderr.
pub fn finish(child: std::process::Child) -> (Option<i32>, String) {
    let o = wait_within(child, LIMIT);
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Waits for a node that must complete: fails the test naming it and with its stderr
/// if it exits otherwise.
pub fn finish_ok(child: std::process::Child, name: &str) {
    let (code, err) = finish(child);
    assert_eq!(code, Some(0), "{name}: {err}");
}

/// True if python3 can import `modules` (a comma-separated list, as `import` takes
/// it): the tests with independent readers and stand-ins skip without them.
pub fn python_has(modules: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Kills `node` with SIGKILL (no chance to flush anything) once its record `rec` holds
/// `rows`, and waits for it.
pub fn kill_once_recorded(node: std::process::Child, rec: &Path, rows: u64) {
    wait_for_rows(rec, rows, std::time::Duration::from_secs(20));
    let pid = rustix::process::Pid::from_raw(node.id() as i32).expect("pid");
    let _ = rustix::process::kill_process(pid, rustix::process::Signal::KILL);
    let (code, _) = finish(node);
    assert_eq!(code, None, "killed by a signal");
}

/// Waits until `ready` holds, failing the test with `what` after `limit`: tests wait
/// for a signal (a lock held, a file grown, a log line), never a fixed sleep.
pub fn wait_for(what: &str, limit: std::time::Duration, mut ready: impl FnMut() -> bool) {
    let start = std::time::Instant::now();
    while !ready() {
        assert!(start.elapsed() < limit, "{what}: not within {limit:?}");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Rows the master records a sample: c(n) sent, then q(n) come back or missed (the
/// slave records one).
pub const MASTER_ROWS: u64 = 2;

/// Waits until the record `rec` holds `n` sample rows in whole blocks, failing the
/// test after `limit`: a run's progress read from its record's content (the records
/// crate's count), not its size, which moves with the record's format, compression
/// and block length.
pub fn wait_for_rows(rec: &Path, n: u64, limit: std::time::Duration) {
    let what = format!("{} holds {n} sample rows", rec.display());
    wait_for(&what, limit, || tactile_records::rows_in(rec) >= n);
}

/// True once process `pid` has a handler of its own for `signal` (the kernel's
/// `SigCgt` mask in /proc): the moment a stop request is something it answers, which
/// a test waits for instead of sleeping.
pub fn catches(pid: u32, signal: rustix::process::Signal) -> bool {
    let Ok(status) = std::fs::read_to_string(format!("/proc/{pid}/status")) else {
        return false;
    };
    let caught = status
        .lines()
        .find_map(|l| l.strip_prefix("SigCgt:"))
        .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        .unwrap_or(0);
    (caught >> (signal.as_raw() - 1)) & 1 == 1
}

/// A test that cannot check what it must here (no root for namespaces, SCHED_FIFO
/// refused): under CI (`CI=true`) it fails naming what it lacks, since CI must prove
/// it; elsewhere it says so past cargo's output capture, and the caller returns.
pub fn cannot(what: &str) {
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("this test cannot do what it must check: {what} (CI=true, so it fails instead of skipping)");
    }
    use std::io::Write as _;
    // Straight to the file, not through eprintln!, which the test harness captures.
    let _ = writeln!(std::io::stderr(), "SKIPPED: {what}");
}

/// True if this process may use SCHED_FIFO, decided by trying it on a thread of its
/// own (root without CAP_SYS_NICE may not, a user with the limit raised may).
pub fn fifo_permitted() -> bool {
    std::thread::spawn(|| tactile_runtime::sched::set_thread_fifo(1).is_ok())
        .join()
        .unwrap_or(false)
}

/// A number of a JSON summary, or a failure naming what is missing (an assertion on a
/// missing key must fail, not compare `None`).
pub fn num(v: &serde_json::Value) -> f64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("expected a number, found {v}"))
}

/// The largest distance of the points `p` (three columns) over samples `from..to` from
/// where they were at `from`.
pub fn largest_move(p: &[Vec<f64>; 3], from: usize, to: usize) -> f64 {
    (from..to)
        .map(|n| {
            (0..3)
                .map(|k| (p[k][n] - p[k][from]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

/// How far the robot's tool (`tool_*`) is from the path the reference (`v_*`) drew, at
/// each sample of `range`: the distance to the nearest of the reference's last
/// `max_lag + 1` samples. A robot simulated by a stand-in that the rest of a test
/// suite starves on two cores follows the same path late; this measures the path,
/// not the stand-in's timing.
pub fn path_error(trace: &str, range: std::ops::Range<usize>, max_lag: usize) -> Vec<f64> {
    let t = [1, 2, 3].map(|i| column(trace, &format!("tool_{i}")));
    let v = [1, 2, 3].map(|i| column(trace, &format!("v_{i}")));
    range
        .map(|n| {
            (n.saturating_sub(max_lag)..=n)
                .map(|m| {
                    (0..3)
                        .map(|i| (t[i][n] - v[i][m]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// Runs `cmd` to its end, its output discarded, and returns how it ended and its peak
/// resident memory in kB (the kernel's VmHWM, read every 5 ms while it runs: a
/// process's peak is only readable while it lives, and the last reading before it
/// ends is its peak but for what it grew in its last 5 ms).
pub fn run_measured(mut cmd: Command) -> (std::process::ExitStatus, u64) {
    use std::process::Stdio;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start");
    let status = format!("/proc/{}/status", child.id());
    let started = std::time::Instant::now();
    let mut peak = 0;
    loop {
        let text = std::fs::read_to_string(&status).unwrap_or_default();
        let hwm = text
            .lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok());
        peak = peak.max(hwm.unwrap_or(0));
        if let Some(s) = child.try_wait().expect("wait") {
            return (s, peak);
        }
        if started.elapsed() > LIMIT {
            let _ = child.kill();
            panic!("a command ran past {LIMIT:?} and was killed");
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}
