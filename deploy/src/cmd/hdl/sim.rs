//! The open tools that hold the RTL against the model: Icarus Verilog runs the
//! testbench over the vectors, Yosys synthesizes each function for Virtex-6 (the
//! paper's family). Each run works in a fresh folder of its own.

use super::Bench as _;
use super::{block_vectors, latency, model, write_rtl, Block, Pipeline, PipelineArg, MODULES};
use crate::cmd::datapath::DatapathArgs;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::Command;
use tactile_launch::error::Error;
use tactile_launch::stop::ToolError;

/// The most vectors a function may be asked for: every input class is covered far
/// below it, and the vectors, held in memory before they are written, stay in tens of
/// megabytes (a count past it is refused, exit 2, before anything is allocated).
pub const MAX_COUNT: u64 = 10_000_000;

/// `--count`: 1 to [`MAX_COUNT`].
pub fn count_parser() -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_COUNT)
}

/// Arguments of `tactile hdl cosim`.
#[derive(Debug, Args)]
pub struct CosimArgs {
    /// Blocks to run (default: all: the TFB's three functions, the f32 units, the
    /// paper's modules).
    #[arg(long, value_parser = super::block_parser(), value_delimiter = ',')]
    pub function: Vec<Block>,
    /// Samples beyond the edge cases, per block (1 to 10^7).
    #[arg(long, default_value_t = 20_000, value_parser = count_parser())]
    pub count: usize,
    /// Seed of the random inputs.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Pipeline configurations to run, each over the same vectors (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub pipeline: Vec<PipelineArg>,
    /// A Verilog macro to define when compiling the RTL (repeatable): the RTL's
    /// deliberately wrong variants are TFB_MUTANT_SHIFT (one iteration shifts one bit
    /// too far), TFB_MUTANT_ROUND (shifts truncate where they must round) and one per
    /// module, KIN_MUTANT_FK, KIN_MUTANT_KFF, KIN_MUTANT_FBF and KIN_MUTANT_IK.
    #[arg(long = "define", value_name = "MACRO")]
    pub defines: Vec<String>,
    /// Keep the work folder (RTL, vectors, simulator) here instead of a temporary one.
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// Fixed-point format and the arm's geometry.
    #[command(flatten)]
    pub datapath: DatapathArgs,
}

/// `dir` if `--keep` may write into it: missing, empty, or an earlier work folder of
/// ours (its `pipe.vh`, which every one holds); the tools write their files there by
/// name, so a folder of other files (`--keep /`) is refused, nothing touched.
fn kept_folder(dir: &Path) -> Result<PathBuf, Error> {
    let holds_others = std::fs::read_dir(dir).is_ok_and(|mut e| e.next().is_some());
    if holds_others && !dir.join("pipe.vh").is_file() {
        return Err(Error::BadInput(format!(
            "--keep {}: holds files and is no earlier work folder of tactile hdl's (no pipe.vh): the tools write theirs there by name; give an empty or new folder",
            dir.display()
        )));
    }
    Ok(dir.to_path_buf())
}

/// A work folder, removed on drop unless the user asked to keep it.
pub(super) struct Work {
    pub(super) dir: PathBuf,
    keep: bool,
}

impl Work {
    /// A relative `keep` is taken from the current folder, now: the tools run inside
    /// the folder, and a path relative to where `tactile` started means nothing there.
    pub(super) fn new(keep: Option<&Path>) -> Result<Work, Error> {
        let (dir, kept) = match keep {
            Some(d) => (
                kept_folder(
                    &std::path::absolute(d)
                        .map_err(Error::io(format!("resolving --keep {}", d.display())))?,
                )?,
                true,
            ),
            None => {
                let nanos = std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.subsec_nanos());
                let name = format!("tactile-hdl-{}-{nanos}", std::process::id());
                (std::env::temp_dir().join(name), false)
            }
        };
        std::fs::create_dir_all(&dir).map_err(Error::io(format!("creating {}", dir.display())))?;
        Ok(Work { dir, keep: kept })
    }
}

impl Drop for Work {
    fn drop(&mut self) {
        if !self.keep {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// Runs a tool, naming it and the package to install when it is missing. In a process
/// group of its own: a stop request (SIGINT, SIGTERM) kills it and its children, and
/// the work folder goes as the error unwinds. The tool's own temporary files (Yosys's
/// ABC folders) go into the folder it runs in, inside the work folder, so a tool killed
/// before it could remove them leaves none behind.
pub(super) fn tool(cmd: &mut Command, name: &str, package: &str) -> Result<String, Error> {
    if let Some(dir) = cmd.get_current_dir().map(Path::to_path_buf) {
        cmd.env("TMPDIR", dir);
    }
    let out = tactile_launch::stop::run_tool(cmd).map_err(|e| match e {
        ToolError::Start(e) => Error::Failed(format!(
            "cannot run {name} ({e}): install it (Debian: apt-get install {package})"
        )),
        ToolError::Stopped => Error::Stopped(format!(
            "{name} killed, the work folder removed (unless kept with --keep)"
        )),
        ToolError::Wait(e) => Error::Failed(format!("running {name}: {e}")),
    })?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        return Err(Error::Failed(format!(
            "{name} failed ({}):\n{}{}",
            out.status,
            tail(&text, 20),
            tail(&err, 20)
        )));
    }
    Ok(text)
}

fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    let mut s = all[all.len().saturating_sub(lines)..].join("\n");
    if !s.is_empty() {
        s.push('\n');
    }
    s
}

pub(super) fn chosen(functions: &[Block], default: &[Block]) -> Vec<Block> {
    if functions.is_empty() {
        default.to_vec()
    } else {
        functions.to_vec()
    }
}

/// Writes a vector file through a buffer, as `make` writes it; returns its samples.
fn write_hex(
    path: &Path,
    make: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<usize>,
) -> Result<usize, Error> {
    use std::io::Write as _;
    let file =
        std::fs::File::create(path).map_err(Error::io(format!("writing {}", path.display())))?;
    let mut buf = std::io::BufWriter::with_capacity(1 << 16, tactile_launch::stop::Checked(file));
    make(&mut buf)
        .and_then(|n| buf.flush().map(|()| n))
        .map_err(tactile_launch::stop::or_io(
            format!("writing {}", path.display()),
            "the work folder removed (unless kept with --keep)",
        ))
}

/// What a testbench's last line says.
struct Outcome {
    vectors: usize,
    mismatches: usize,
    /// Clocks from the first input to the first output, as measured (the f32 units'
    /// testbench reads its outputs at the latency f32_lat.vh gives, and measures none).
    latency: Option<u32>,
}

/// Co-simulation of one function, from the testbench's last line.
fn cosim_one(
    work: &Path,
    function: Block,
    vec_path: &Path,
    n: usize,
    defines: &[String],
) -> Result<Outcome, Error> {
    let name = function.name();
    let sim = work.join(format!("{name}.vvp"));
    let (bench, prefix) = function.testbench();
    let words = function.fields().split_whitespace().count();
    let mut cc = Command::new("iverilog");
    cc.current_dir(work)
        .args(["-g2005", "-I", ".", "-o"])
        .arg(&sim)
        .arg(format!("-D{}", function.define()))
        .arg(format!("-DMAXWORDS={}", (n * words).next_power_of_two()));
    for d in defines {
        cc.arg(format!("-D{d}"));
    }
    cc.arg(bench).args(MODULES);
    tool(&mut cc, "iverilog", "iverilog")?;
    let mut run = Command::new("vvp");
    run.current_dir(work)
        .args(["-n"])
        .arg(&sim)
        // The vectors sit beside the pipelines' folders: given from the simulator's,
        // since the testbench holds the path in a register of bounded width, and a
        // long absolute one was cut.
        .arg(format!(
            "+vectors={}",
            Path::new("..")
                .join(vec_path.file_name().unwrap_or_default())
                .display()
        ))
        .arg(format!("+count={n}"));
    let out = tool(&mut run, "vvp", "iverilog")?;
    let last = out
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix(&format!("{prefix}: {name} ")))
        .ok_or_else(|| {
            Error::Failed(format!("the testbench gave no result:\n{}", tail(&out, 20)))
        })?;
    let field = |key: &str| -> Option<usize> {
        last.split_whitespace()
            .find_map(|f| f.strip_prefix(key))
            .and_then(|v| v.parse().ok())
    };
    match (field("vectors="), field("mismatches=")) {
        (Some(vectors), Some(mismatches)) => {
            for l in out.lines().filter(|l| l.contains("mismatch at")) {
                tactile_launch::noteln!("{l}");
            }
            let latency = field("latency=").and_then(|l| u32::try_from(l).ok());
            Ok(Outcome {
                vectors,
                mismatches,
                latency,
            })
        }
        _ => Err(Error::Failed(format!(
            "unreadable testbench result: {last}"
        ))),
    }
}

/// `tactile hdl cosim`: each block's vectors written once, then run through the RTL
/// of every pipeline configuration asked for, each in a folder of its own.
pub fn cosim_main(args: &CosimArgs) -> Result<(), Error> {
    let cfg = args.datapath.cordic()?;
    let geometry = args.datapath.geometry()?;
    let (cordic, k) = model(cfg)?;
    let work = Work::new(args.keep.as_deref())?;
    let pipelines: Vec<Pipeline> = if args.pipeline.is_empty() {
        Pipeline::ALL.to_vec()
    } else {
        args.pipeline.iter().map(|p| Pipeline::from(*p)).collect()
    };
    for p in &pipelines {
        write_rtl(&work.dir.join(p.name()), &k, &geometry, *p)?;
    }
    let mut failed = 0;
    for f in chosen(&args.function, &Block::ALL) {
        let vec_path = work.dir.join(format!("{}.hex", f.name()));
        let n = write_hex(&vec_path, |out| {
            block_vectors(&cordic, &k, &geometry, (f, args.count, args.seed), out)
        })?;
        for p in &pipelines {
            let got = cosim_one(&work.dir.join(p.name()), f, &vec_path, n, &args.defines)?;
            let (v, m, clocks) = (got.vectors, got.mismatches, latency(f, &cfg, *p));
            tactile_launch::outln!(
                "{:<7} [s{}.{}] {} iterations {:<8} pipeline {:<6} {v} vectors, {m} mismatches \
                 (latency {} clocks)",
                f.name(),
                cfg.word,
                cfg.frac,
                cfg.iterations,
                format!("{:?}", cfg.rounding).to_lowercase(),
                p.name(),
                clocks
            );
            let measured = !matches!(f.family(), super::Family::Unit(_));
            if measured && got.latency != Some(clocks) {
                return Err(Error::Failed(format!(
                    "{} (pipeline {}): the RTL took {:?} clocks where its formula says {clocks}",
                    f.name(),
                    p.name(),
                    got.latency
                )));
            }
            if v != n {
                return Err(Error::Failed(format!(
                    "{} (pipeline {}): the testbench compared {v} of {n} vectors",
                    f.name(),
                    p.name()
                )));
            }
            failed += m;
        }
    }
    if failed > 0 {
        return Err(Error::Failed(format!(
            "co-simulation: {failed} outputs differ from the model"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// `--keep` wrote the tools' files into any folder: one of other files is
    /// refused, an empty, a new or an earlier work folder of ours is taken.
    #[test]
    fn a_kept_folder_must_be_empty_new_or_ours() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        super::kept_folder(&d.join("new")).expect("new");
        super::kept_folder(d).expect("empty");
        std::fs::write(d.join("notes.txt"), "x").expect("write");
        let e = super::kept_folder(d).expect_err("their files");
        assert!(e.to_string().contains("no earlier work folder"), "{e}");
        std::fs::write(d.join("pipe.vh"), "").expect("write");
        super::kept_folder(d).expect("ours");
    }
}
