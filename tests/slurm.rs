//! The job-array recipe of docs/01-the-loop.md under a real Slurm (Debian's 22.05, a
//! one-node cluster on this machine: deploy/slurm/local-cluster.sh, which .ci/run
//! starts): deploy/slurm/sweep-array.sbatch submitted as an array of shards, the merge
//! (deploy/slurm/merge.sbatch) with `--dependency=afterok`, the merged `sweep.csv`
//! byte for byte the unsharded one; a task requeued mid-run keeps the runs it finished.

use crate::util::{self, cannot, Sandbox};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

const SETS: [&str; 4] = [
    "--set",
    "control.kind=none,tdpa",
    "--set",
    "network.forward.delay=[0,0,0],[10,10,10],[30,30,30]",
];

/// True if a Slurm cluster answers and has a node up.
fn cluster_up() -> bool {
    Command::new("sinfo")
        .args(["-h", "-o", "%T"])
        .output()
        .is_ok_and(|o| {
            let s = String::from_utf8_lossy(&o.stdout);
            o.status.success() && ["idle", "mixed", "alloc"].iter().any(|t| s.contains(t))
        })
}

fn script(name: &str) -> String {
    format!("{}/slurm/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// `sbatch --parsable ARGS`, from the sandbox, with the test's `tactile`: the job id.
fn sbatch(sb: &Sandbox, args: &[&str]) -> String {
    let o = Command::new("sbatch")
        .arg("--parsable")
        .arg(format!(
            "--export=ALL,TACTILE={}",
            env!("CARGO_BIN_EXE_tactile")
        ))
        .args(args)
        .current_dir(sb.path("."))
        .output()
        .expect("sbatch");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "sbatch {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    out.trim().split(';').next().unwrap_or("").to_string()
}

/// A job's (or array task's) state, as `scontrol show job` says it.
fn state(job: &str) -> String {
    let o = Command::new("scontrol")
        .args(["show", "job", job])
        .output()
        .expect("scontrol");
    let text = String::from_utf8_lossy(&o.stdout);
    text.split_whitespace()
        .find_map(|w| w.strip_prefix("JobState="))
        .unwrap_or("UNKNOWN")
        .to_string()
}

/// Waits for `job` to complete; fails with the sandbox's Slurm logs if it ends
/// otherwise.
fn wait_done(sb: &Sandbox, job: &str, limit: Duration) {
    let start = Instant::now();
    loop {
        let s = state(job);
        if s == "COMPLETED" {
            return;
        }
        let ended = [
            "FAILED",
            "CANCELLED",
            "TIMEOUT",
            "NODE_FAIL",
            "OUT_OF_MEMORY",
        ];
        if ended.contains(&s.as_str()) || start.elapsed() > limit {
            panic!("job {job}: {s} after {:?}\n{}", start.elapsed(), logs(sb));
        }
        std::thread::sleep(Duration::from_millis(300));
    }
}

fn logs(sb: &Sandbox) -> String {
    let mut all = String::new();
    for e in std::fs::read_dir(sb.path(".")).expect("sandbox").flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with("slurm-") {
            all += &format!(
                "== {name}\n{}\n",
                std::fs::read_to_string(e.path()).unwrap_or_default()
            );
        }
    }
    all
}

fn finished_runs(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path().join("summary.json")).collect())
        .unwrap_or_default();
    v.retain(|p: &std::path::PathBuf| p.is_file());
    v.sort();
    v
}

#[test]
fn a_job_array_and_its_merge_give_the_unsharded_sweep() {
    if !cluster_up() {
        return cannot("no Slurm cluster up (deploy/slurm/local-cluster.sh starts one)");
    }
    let sb = Sandbox::new("slurm");
    let s = sb.write(
        "wall.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 600"),
    );
    let s = s.to_str().expect("utf-8");
    let mut whole = vec!["sweep", s];
    whole.extend(SETS);
    whole.extend(["--out", "whole"]);
    let o = sb.tactile(&whole);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let started = Instant::now();
    let array = script("sweep-array.sbatch");
    let mut args = vec!["--array=1-3", array.as_str(), "3", "study", s];
    args.extend(SETS);
    let job = sbatch(&sb, &args);
    let merge = sbatch(
        &sb,
        &[
            &format!("--dependency=afterok:{job}"),
            &script("merge.sbatch"),
            "study",
        ],
    );
    wait_done(&sb, &merge, Duration::from_secs(240));
    eprintln!(
        "Slurm: 3 array tasks and the merge in {:?}",
        started.elapsed()
    );
    let read = |p: &str| std::fs::read(sb.path(p)).expect(p);
    assert!(
        read("study/all/sweep.csv") == read("whole/sweep.csv"),
        "the merged sweep.csv is the unsharded one\n{}",
        logs(&sb)
    );
    for k in 1..=3 {
        assert_eq!(state(&format!("{job}_{k}")), "COMPLETED");
        assert_eq!(
            finished_runs(&sb.path(&format!("study/shard-{k}"))).len(),
            2
        );
    }
}

#[test]
fn a_requeued_task_keeps_the_runs_it_finished() {
    if !cluster_up() {
        return cannot("no Slurm cluster up (deploy/slurm/local-cluster.sh starts one)");
    }
    let sb = Sandbox::new("slurm-requeue");
    // Six runs of 60,000 samples, one at a time: long enough to be caught mid-way.
    let s = sb.write(
        "wall.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 60000"),
    );
    let s = s.to_str().expect("utf-8");
    let array = script("sweep-array.sbatch");
    let mut args = vec!["--array=1-1", array.as_str(), "1", "study", s];
    args.extend(SETS);
    let job = sbatch(&sb, &args);
    let task = format!("{job}_1");
    let started = Instant::now();
    let shard = sb.path("study/shard-1");
    util::wait_for("two runs finished", Duration::from_secs(240), || {
        finished_runs(&shard).len() >= 2
    });
    eprintln!("two runs finished after {:?}", started.elapsed());
    let kept: Vec<_> = finished_runs(&shard)
        .into_iter()
        .map(|p| {
            (
                std::fs::metadata(&p)
                    .and_then(|m| m.modified())
                    .expect("mtime"),
                p,
            )
        })
        .collect();
    assert!(kept.len() < 6, "the task ended before it could be requeued");
    let o = Command::new("scontrol")
        .args(["requeue", &task])
        .output()
        .expect("scontrol");
    assert!(
        o.status.success(),
        "requeue: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Slurm holds a requeued job for two minutes (its BeginTime); the guide says so,
    // and how to start it at once, as here: but not within the second of the requeue,
    // whose credential slurmd revokes by the second (a start then fails at once with
    // "Job credential revoked").
    let asked = Instant::now();
    while state(&task) != "PENDING" {
        assert!(
            asked.elapsed() < Duration::from_secs(60),
            "not pending again: {}",
            state(&task)
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    std::thread::sleep(Duration::from_secs(2).saturating_sub(asked.elapsed()));
    let o = Command::new("scontrol")
        .args(["update", &format!("JobId={task}"), "StartTime=now"])
        .output()
        .expect("scontrol");
    assert!(
        o.status.success(),
        "update: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    wait_done(&sb, &task, Duration::from_secs(300));
    eprintln!("the requeued task ended after {:?}", started.elapsed());
    assert_eq!(finished_runs(&shard).len(), 6, "{}", logs(&sb));
    for (mtime, p) in &kept {
        let now = std::fs::metadata(p)
            .and_then(|m| m.modified())
            .expect("mtime");
        assert_eq!(&now, mtime, "{} was run again", p.display());
    }
    // Both attempts wrote to the one log (--open-mode=append): the second kept runs.
    let log = logs(&sb);
    assert!(log.contains("runs kept from before (--resume)"), "{log}");
    // The requeued slice is the whole grid: its table is the unsharded sweep's.
    let mut whole = vec!["sweep", s];
    whole.extend(SETS);
    whole.extend(["--out", "whole"]);
    let o = sb.tactile(&whole);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |p: &str| std::fs::read(sb.path(p)).expect(p);
    assert!(read("study/shard-1/sweep.csv") == read("whole/sweep.csv"));
}
