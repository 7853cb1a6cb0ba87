//! `tactile fuzz`: every decoder of outside bytes (records, ROS 2 CDR, the loop's wire
//! samples, rmw_zenoh attachments, scenario TOML, trajectory CSV, `tactile kernels`
//! input, a URDF arm, `[slave.arm]`'s map, a 6-DoF trajectory) driven with mutated
//! inputs on stable Rust, each input under `catch_unwind`.
//!
//! Guidance without compiler instrumentation: an input is kept in the target's corpus
//! when its outcome has a shape not seen before (the decoder's answer with its numbers
//! blanked, per decoder): the errors a decoder gives are the paths it can take through
//! its checks, and mutating an input that reached a new one explores from there. The
//! count of shapes is what the report calls paths. A panic is written to `--out` as
//! the input that caused it (its message beside it), and the command exits 1. The
//! slowest input's time is reported too: a decoder that is slow on some input (a
//! quadratic loop) shows there long before it hangs.

mod arm;
mod mutate;
mod targets;
mod trajectory6;

use clap::Args;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use tactile_launch::error::Error;

/// Arguments of `tactile fuzz`.
#[derive(Debug, Args)]
pub struct FuzzArgs {
    /// Targets to fuzz (default: all): records, blocks, cdr, wire, attachment,
    /// scenario, trajectory, kernels, urdf, map, trajectory6.
    #[arg(long = "target", value_name = "NAME")]
    pub targets: Vec<String>,
    /// Seconds per target.
    #[arg(long, default_value_t = 5.0, value_parser = seconds)]
    pub seconds: f64,
    /// Seed of the mutations (the same seed and time make the same first inputs).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Inputs per target at most (with a seed, the same inputs on any machine).
    #[arg(long)]
    pub runs: Option<u64>,
    /// Folder for the inputs that made a decoder panic.
    #[arg(long, default_value = "fuzz-crashes")]
    pub out: PathBuf,
}

fn seconds(text: &str) -> Result<f64, String> {
    let s: f64 = text.parse().map_err(|e| format!("{e}"))?;
    if (0.01..=86_400.0).contains(&s) {
        Ok(s)
    } else {
        Err("takes 0.01 to 86400 seconds".into())
    }
}

/// What a target's campaign did.
struct Campaign {
    inputs: u64,
    paths: usize,
    corpus: usize,
    panics: u64,
    /// The slowest input's time.
    slowest: Duration,
    /// The campaign's time.
    elapsed: Duration,
}

/// The message of the last panic, as the hook saw it (where and why).
static LAST_PANIC: std::sync::Mutex<String> = std::sync::Mutex::new(String::new());

fn last_panic() -> String {
    LAST_PANIC.lock().map(|m| m.clone()).unwrap_or_default()
}

/// An outcome's shape: numbers blanked and quoted or bracketed text left out (an error quoting the
/// input would otherwise make every input a path of its own), bounded, so `at byte 17`
/// and `at byte 18`, or `"abc"` and `"abd"`, are one path.
fn shape(outcome: &str) -> String {
    // A parser's excerpt of the input (TOML's `3 | foo = bar` and its caret line) is
    // the input again, not a path.
    let excerpt = |l: &&str| {
        l.trim_start()
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start()
            .starts_with('|')
    };
    let text: Vec<&str> = outcome.lines().filter(|l| !excerpt(l)).collect();
    let outcome = text.join(" ");
    // What a decoder quotes is the input: only the text before the first quote and
    // after the last is the message's own (a quoted value may hold quotes itself).
    let quote = |c: char| matches!(c, '"' | '`' | '\'' | '[' | ']');
    let (head, tail) = match (outcome.find(quote), outcome.rfind(quote)) {
        (Some(a), Some(b)) => (&outcome[..a], &outcome[b + 1..]),
        _ => (outcome.as_str(), ""),
    };
    let blank = |t: &str| -> String {
        let mut out = String::new();
        for c in t.chars().filter(char::is_ascii).take(80) {
            if !c.is_ascii_digit() {
                out.push(c);
            } else if !out.ends_with('#') {
                out.push('#');
            }
        }
        out
    };
    format!("{}_{}", blank(head), blank(tail))
}

/// Paths told apart per target (memory stays bounded however long a campaign runs; a
/// target that reaches this many says so as `>=`).
const MAX_PATHS: usize = 1 << 16;

/// Inputs kept per target: past it, a new path's input replaces a random one.
const MAX_CORPUS: usize = 4096;

/// Every target, seeded; `scratch` is a folder for the record files. Here, not in
/// `targets`, since the arm's and the 6-DoF trajectory's targets use `targets`' types.
fn all_targets(scratch: &Path) -> Result<Vec<targets::Target>, String> {
    Ok(vec![
        targets::records(scratch)?,
        targets::blocks(),
        targets::cdr(),
        targets::wire(),
        targets::attachment(),
        targets::scenario(),
        targets::trajectory(),
        targets::kernels(),
        arm::urdf(),
        arm::map()?,
        trajectory6::trajectory6(),
        targets::Target {
            name: tactile_world::fuzz::NAME,
            seeds: tactile_world::fuzz::seeds(),
            dict: tactile_world::fuzz::DICT,
            run: Box::new(tactile_world::fuzz::run),
        },
    ])
}

fn campaign(t: &targets::Target, args: &FuzzArgs, k: u64) -> Result<Campaign, Error> {
    let mut rng = mutate::Rng::new(args.seed ^ (k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let mut corpus = t.seeds.clone();
    let mut seen = HashSet::new();
    let mut c = Campaign {
        inputs: 0,
        paths: 0,
        corpus: 0,
        panics: 0,
        slowest: Duration::ZERO,
        elapsed: Duration::ZERO,
    };
    let began = Instant::now();
    let until = began + Duration::from_secs_f64(args.seconds);
    let mut queue: Vec<Vec<u8>> = t.seeds.clone();
    while Instant::now() < until
        && args.runs.is_none_or(|n| c.inputs < n)
        && !tactile_launch::stop::requested()
    {
        let input = queue
            .pop()
            .unwrap_or_else(|| mutate::mutate(&mut rng, &corpus, t.dict));
        c.inputs += 1;
        let start = Instant::now();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (t.run)(&input)));
        c.slowest = c.slowest.max(start.elapsed());
        match result {
            Ok(outcome) => {
                let new = seen.len() < MAX_PATHS && seen.insert(shape(&outcome));
                if new && input.len() <= mutate::MAX_LEN {
                    if corpus.len() < MAX_CORPUS {
                        corpus.push(input);
                    } else {
                        let k = rng.below(corpus.len());
                        corpus[k] = input;
                    }
                }
            }
            Err(_) => {
                c.panics += 1;
                std::fs::create_dir_all(&args.out)
                    .map_err(Error::io(format!("creating {}", args.out.display())))?;
                let path = args.out.join(format!("{}-{}.bin", t.name, c.panics));
                std::fs::write(&path, &input)
                    .map_err(Error::io(format!("writing {}", path.display())))?;
                let why = path.with_extension("txt");
                std::fs::write(&why, last_panic())
                    .map_err(Error::io(format!("writing {}", why.display())))?;
            }
        }
    }
    c.paths = seen.len();
    c.elapsed = began.elapsed();
    c.corpus = corpus.len();
    Ok(c)
}

/// `tactile fuzz`. A stop request (SIGINT, SIGTERM) ends the target in hand after the
/// input in hand: its row says what it did, and the command exits 130.
pub fn main(args: &FuzzArgs) -> Result<(), Error> {
    tactile_launch::stop::watch()?;
    let scratch = tempfile::tempdir().map_err(Error::io("making a scratch folder"))?;
    let all = all_targets(scratch.path()).map_err(Error::Failed)?;
    for name in &args.targets {
        if !all.iter().any(|t| t.name == name) {
            let names: Vec<&str> = all.iter().map(|t| t.name).collect();
            return Err(Error::BadInput(format!(
                "--target {name:?}: not one of {}",
                names.join(", ")
            )));
        }
    }
    // Panics are counted and their inputs kept with their message; the default hook
    // would print each.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut m) = LAST_PANIC.lock() {
            *m = info.to_string();
        }
    }));
    tactile_launch::outln!("target        inputs    inputs/s  paths  corpus  max_ms  panics");
    let mut panics = 0;
    let mut result = Ok(());
    for (k, t) in all.iter().enumerate() {
        if !args.targets.is_empty() && !args.targets.iter().any(|n| n == t.name) {
            continue;
        }
        match campaign(t, args, k as u64) {
            Ok(c) => {
                panics += c.panics;
                let paths = if c.paths >= MAX_PATHS {
                    format!(">={}", c.paths)
                } else {
                    c.paths.to_string()
                };
                tactile_launch::outln!(
                    "{:<11} {:>8} {:>11.0} {:>6} {:>7} {:>7.1} {:>7}",
                    t.name,
                    c.inputs,
                    c.inputs as f64 / c.elapsed.as_secs_f64().max(1e-9),
                    paths,
                    c.corpus,
                    c.slowest.as_secs_f64() * 1e3,
                    c.panics
                );
            }
            Err(e) => {
                result = Err(e);
                break;
            }
        }
        if tactile_launch::stop::requested() {
            result = Err(Error::Stopped(format!(
                "{} stopped before its time, the targets after it not fuzzed",
                t.name
            )));
            break;
        }
    }
    std::panic::set_hook(hook);
    result?;
    if panics > 0 {
        return Err(Error::Failed(format!(
            "{panics} inputs made a decoder panic; each is in {}",
            args.out.display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn shapes_leave_out_numbers_and_quoted_text() {
        assert_eq!(
            super::shape("line 17: \"abc\" is not a number"),
            super::shape("line 18: \"abd\" is not a number")
        );
        assert_eq!(
            super::shape("header is \"a\\\"b\", expected x"),
            super::shape("header is \"c\", expected x")
        );
        assert_eq!(
            super::shape("unknown variant `a`b`, expected `x` or `y`"),
            super::shape("unknown variant `q`, expected `x` or `y`")
        );
        assert_ne!(super::shape("no rows"), super::shape("no header"));
        assert_eq!(
            super::shape(
                "TOML parse error at line 3\n  |\n3 | foo = bar\n  |     ^\ninvalid string"
            ),
            super::shape("TOML parse error at line 9\n  |\n9 | x = \n  |   ^\ninvalid string")
        );
    }
}
