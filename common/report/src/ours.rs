//! Which folders a command may write its output into: a missing or empty one, or
//! one that holds an earlier output of ours. A run removes and writes files by name
//! in its folder, so `tactile run --out /` wrote twelve files into `/`, and a
//! `--no-trace` run removed a `trace.csv` that was someone else's. Every command that
//! writes a folder asks here first (`out::take` does, for runs, reports
//! and sweeps), and refuses a folder that holds anything but ours.
//!
//! An earlier output of ours is known by a file only Tactile writes, read far enough
//! to tell: a node's record (`master.rec`, `emulator.rec`, `slave.rec`) beginning
//! with the records' magic (any format version), a `summary.json`, `sweep.json` or
//! `bench.json` holding the keys ours always hold, or the lock a run, report or
//! sweep holds while it writes (left behind by one that was killed). A folder whose
//! only entries are other things is not ours, however they are named.

use crate::Error;
use std::io::Read;
use std::path::Path;
use tactile_messages::Role;

/// The lock file in an output folder (`out::take`).
pub const LOCK_FILE: &str = ".tactile.lock";

/// The JSON files a command of ours writes, with keys each always holds.
const JSON_MARKS: [(&str, [&str; 2]); 3] = [
    ("summary.json", ["scenario", "runner"]),
    ("sweep.json", ["scenario_hash", "combinations"]),
    ("bench.json", ["rates", "lockstep_samples_per_s"]),
];

/// The longest JSON mark read (a summary is a few kB).
const MAX_MARK_BYTES: u64 = 16 << 20;

/// Entries a refusal names before it says how many more there are.
const NAMED: usize = 3;

/// Refuses (bad input, nothing touched) an existing folder `out` that holds files
/// or folders and no earlier output of ours.
pub fn refuse_foreign(out: &Path) -> Result<(), Error> {
    if out.as_os_str().is_empty() {
        // It would be the working folder, whatever that holds.
        return Err(Error::BadInput(
            "--out \"\": an empty path names no folder; give one".into(),
        ));
    }
    let Ok(entries) = std::fs::read_dir(out) else {
        // Missing (made later), or not a folder (refused by whoever makes it).
        return Ok(());
    };
    let names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if names.is_empty() || ours(out) {
        return Ok(());
    }
    let mut shown: Vec<&str> = names.iter().map(String::as_str).collect();
    shown.sort_unstable();
    let more = shown.len().saturating_sub(NAMED);
    shown.truncate(NAMED);
    let more = if more > 0 {
        format!(" and {more} more")
    } else {
        String::new()
    };
    Err(Error::BadInput(format!(
        "--out {}: holds {}{more} and no earlier output of tactile's (a summary.json, a node's record, a sweep.json or a bench.json): its files are written and removed by name, so only an empty folder, a new one or one of our earlier outputs is taken; choose another --out",
        out.display(),
        shown.join(", ")
    )))
}

/// True if `dir` holds a file only an output of ours has.
pub fn ours(dir: &Path) -> bool {
    dir.join(LOCK_FILE).is_file()
        || Role::ALL
            .iter()
            .any(|r| record(&dir.join(format!("{r}.rec"))))
        || JSON_MARKS
            .iter()
            .any(|(file, keys)| json_with(&dir.join(file), keys))
}

/// True if `path` begins as every record file does (its magic, any version).
fn record(path: &Path) -> bool {
    let magic = &tactile_records::MAGIC[..tactile_records::MAGIC.len() - 1];
    let mut head = vec![0; magic.len()];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == magic)
}

/// True if `path` is a JSON object holding every one of `keys`.
fn json_with(path: &Path, keys: &[&str]) -> bool {
    let small = std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() <= MAX_MARK_BYTES);
    if !small {
        return false;
    }
    let Ok(text) = std::fs::read_to_string(path) else {
        return false;
    };
    match serde_json::from_str::<serde_json::Value>(&text) {
        Ok(serde_json::Value::Object(o)) => keys.iter().all(|k| o.contains_key(*k)),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `tactile run --out /` wrote into `/`, and a `--no-trace` run removed a
    /// `trace.csv` that was not ours: a folder with anything but ours is refused, one
    /// that holds an earlier output of ours (or nothing) is taken.
    #[test]
    fn only_a_missing_an_empty_or_our_own_folder_is_taken() {
        let dir = tempfile::tempdir().expect("tempdir");
        let at = |name: &str| {
            let d = dir.path().join(name);
            std::fs::create_dir_all(&d).expect("dir");
            d
        };
        refuse_foreign(&dir.path().join("missing")).expect("missing");
        refuse_foreign(Path::new("")).expect_err("the working folder, unnamed");
        refuse_foreign(&at("empty")).expect("empty");
        let theirs = at("theirs");
        std::fs::write(theirs.join("trace.csv"), "their data").expect("write");
        std::fs::write(theirs.join("summary.json"), "{\"a\": 1}").expect("write");
        std::fs::write(theirs.join("master.rec"), "not a record").expect("write");
        let e = refuse_foreign(&theirs).expect_err("their files");
        assert!(matches!(e, Error::BadInput(_)), "{e}");
        let e = e.to_string();
        assert!(
            e.contains("holds master.rec, summary.json, trace.csv and no earlier output"),
            "{e}"
        );
        refuse_foreign(Path::new("/")).expect_err("the root");
        let run = at("run");
        std::fs::write(run.join("trace.csv"), "old").expect("write");
        std::fs::write(run.join("master.rec"), tactile_records::MAGIC).expect("write");
        refuse_foreign(&run).expect("a run's record (one that failed at its start)");
        for (file, text) in [
            (
                "summary.json",
                "{\"scenario\": \"paper\", \"runner\": \"in-process\"}",
            ),
            (
                "sweep.json",
                "{\"scenario_hash\": \"0\", \"combinations\": 2}",
            ),
            (
                "bench.json",
                "{\"rates\": [], \"lockstep_samples_per_s\": 1}",
            ),
            (LOCK_FILE, ""),
        ] {
            let d = at(&format!("ours-{file}"));
            std::fs::write(d.join("notes.txt"), "x").expect("write");
            std::fs::write(d.join(file), text).expect("write");
            refuse_foreign(&d).unwrap_or_else(|e| panic!("{file}: {e}"));
        }
    }
}
