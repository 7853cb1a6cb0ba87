//! Stopping the commands that are not a run on SIGINT and SIGTERM (`fuzz`, `kernels`,
//! `hdl`, the node programs' build): they look at the process's one stop flag
//! ([`tactile_runtime::signals`], the one `tactile run` looks at) between steps, read
//! and write stdin and stdout through waits that wake for it ([`Input`], [`Output`]),
//! and run their tools through [`run_tool`], which kills a tool's whole process group
//! when a stop comes. Within a second they end with exit 130, leaving no process
//! behind, their temporary folders removed as they unwind.

use crate::error::Error;
use rustix::event::{poll, PollFd, PollFlags, Timespec};
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::os::unix::process::CommandExt;
use std::process::{Command, ExitStatus, Stdio};
use std::time::Duration;

/// How often a wait looks at the stop flag.
const LOOK: Duration = Duration::from_millis(20);

/// From here SIGINT and SIGTERM set the stop flag instead of ending the process.
pub fn watch() -> Result<(), Error> {
    tactile_runtime::signals::stop_flag()
        .map(drop)
        .map_err(Error::io("installing signal handlers"))
}

/// True once SIGINT or SIGTERM came (after [`watch`]).
pub fn requested() -> bool {
    tactile_runtime::signals::stop_requested()
}

/// `Err(Error::Stopped(what))` once a stop was requested: `what` says what was left.
pub fn check(what: &str) -> Result<(), Error> {
    if requested() {
        return Err(Error::Stopped(what.into()));
    }
    Ok(())
}

/// An I/O error's context, or the stop request that caused it (a read or write that a
/// stop ended: [`Input`], [`Output`], [`Checked`]).
pub fn or_io(
    context: impl Into<String>,
    left: &'static str,
) -> impl FnOnce(std::io::Error) -> Error {
    let context = context.into();
    move |source| {
        if requested() {
            Error::Stopped(left.into())
        } else {
            Error::Io { context, source }
        }
    }
}

/// The error a read or write ended by a stop request gives (its kind is not
/// `Interrupted`, which readers retry).
fn stopped_io() -> std::io::Error {
    std::io::Error::other("stopped by a signal")
}

/// Waits until `fd` is ready for `events`; false if a stop was requested first.
fn ready(fd: &impl AsFd, events: PollFlags) -> std::io::Result<bool> {
    let timeout = Timespec {
        tv_sec: 0,
        tv_nsec: LOOK.as_nanos() as i64,
    };
    loop {
        if requested() {
            return Ok(false);
        }
        let mut fds = [PollFd::new(fd, events)];
        match poll(&mut fds, Some(&timeout)) {
            Ok(0) | Err(rustix::io::Errno::INTR) => {}
            Ok(_) => return Ok(true),
            Err(e) => return Err(e.into()),
        }
    }
}

/// Standard input read straight from its descriptor, each read waiting for input
/// only as long as no stop is requested (a read blocked on a FIFO or a terminal is
/// otherwise restarted after the signal, and never ends). Nothing else may read
/// stdin through `std::io::stdin()`'s buffer.
#[derive(Debug)]
pub struct Input(std::io::Stdin);

impl Input {
    /// The process's standard input.
    pub fn stdin() -> Input {
        Input(std::io::stdin())
    }
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if !ready(&self.0, PollFlags::IN)? {
            return Err(stopped_io());
        }
        Ok(rustix::io::read(&self.0, buf)?)
    }
}

/// Standard output written straight to its descriptor a pipe's atomic write at a
/// time, each write waiting for room only as long as no stop is requested. Nothing
/// else may have text in `std::io::stdout()`'s buffer.
#[derive(Debug)]
pub struct Output(std::io::Stdout);

impl Output {
    /// The process's standard output.
    pub fn stdout() -> Output {
        Output(std::io::stdout())
    }
}

/// Bytes a pipe takes in one write once it has room (Linux's PIPE_BUF).
const PIPE_BUF: usize = 4096;

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !ready(&self.0, PollFlags::OUT)? {
            return Err(stopped_io());
        }
        let n = buf.len().min(PIPE_BUF);
        Ok(rustix::io::write(&self.0, &buf[..n])?)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A writer that fails once a stop is requested: a long output to a file ends at
/// the next write.
#[derive(Debug)]
pub struct Checked<W>(pub W);

impl<W: Write> Write for Checked<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if requested() {
            return Err(stopped_io());
        }
        self.0.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

/// How a tool run through [`run_tool`] ended other than by itself.
#[derive(Debug)]
pub enum ToolError {
    /// It could not be started (not installed).
    Start(std::io::Error),
    /// A stop was requested: the tool and every process of its group were killed.
    Stopped,
    /// Waiting for it or reading its output failed.
    Wait(std::io::Error),
}

/// What a tool that ran to its end gave: its status and its output.
#[derive(Debug)]
pub struct Ran {
    /// How it exited.
    pub status: ExitStatus,
    /// Its standard output.
    pub stdout: Vec<u8>,
    /// Its standard error.
    pub stderr: Vec<u8>,
}

/// Runs `cmd` to its end, its output collected, as `Command::output` does, but in a
/// process group of its own, looked at every 20 ms: a stop request kills the whole
/// group (the tool's own children too: Yosys's ABC, a WebAssembly runtime's threads)
/// and reaps the tool. Not started at all if a stop was requested before.
pub fn run_tool(cmd: &mut Command) -> Result<Ran, ToolError> {
    if requested() {
        return Err(ToolError::Stopped);
    }
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .map_err(ToolError::Start)?;
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut v);
            }
            v
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let status = loop {
        if let Some(status) = child.try_wait().map_err(ToolError::Wait)? {
            break Some(status);
        }
        if requested() {
            if let Some(group) = rustix::process::Pid::from_raw(child.id() as i32) {
                let _ = rustix::process::kill_process_group(group, rustix::process::Signal::KILL);
            }
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(LOOK);
    };
    let (stdout, stderr) = (out.join(), err.join());
    let Some(status) = status else {
        return Err(ToolError::Stopped);
    };
    let lost = || ToolError::Wait(std::io::Error::other("reading the tool's output failed"));
    Ok(Ran {
        status,
        stdout: stdout.map_err(|_| lost())?,
        stderr: stderr.map_err(|_| lost())?,
    })
}
