//! The join from records written directly: three hosts' folders with two clock
//! domains, answers and steps recorded out of order within the look-ahead window, a
//! record past it, one past the run, and records of another run.

use super::*;
use tactile_messages::samples::Signal;
use tactile_records::emulator::Fate;
use tactile_records::{RecordWriter, Start};

const N: u64 = 3000;
const RUN: u64 = 7;

fn start(role: &str, clock: &str) -> Start {
    Start {
        role: role.into(),
        version: "test".into(),
        pid: 1,
        host: clock.into(),
        clock: clock.into(),
        prefix: "t".into(),
        link: "zenoh".into(),
        scenario: "t".into(),
        scenario_toml: "name = \"t\"\n".into(),
        samples: N,
        rate_hz: 1000.0,
        sched: tactile_records::Sched::default(),
        unix_ms: 0,
        mono_ns: 0,
    }
}

fn signal(v: f64) -> Signal {
    Signal {
        value: [v, 2.0 * v, 3.0 * v],
        ..Signal::default()
    }
}

fn writer<S: serde::Serialize, C: serde::Serialize>(
    dir: &Path,
    role: Role,
    clock: &str,
    run: u64,
) -> RecordWriter<Record<S, C>> {
    std::fs::create_dir_all(dir).expect("folder");
    let path = tactile_records::record_path(dir, role);
    let mut w = RecordWriter::create(&path, false).expect("record");
    w.write(&Record::Start(start(role.name(), clock)))
        .expect("write");
    w.write(&Record::Run(run)).expect("write");
    w
}

/// Master on host A; emulator and slave on host B. Answers lag their samples by 50,
/// backward passages by 20, and the slave's steps come in reversed blocks of 100; one
/// step belongs to no sample the master sent.
fn write_run(root: &Path, slave_run: u64) -> [PathBuf; 3] {
    let dirs = [root.join("m"), root.join("e"), root.join("s")];
    let mut m = writer::<MasterSample, MasterTotals>(&dirs[0], Role::Master, "host-a", RUN);
    let mut e = writer::<Passage, EmulatorTotals>(&dirs[1], Role::Emulator, "host-b", RUN);
    let mut s = writer::<SlaveSample, SlaveTotals>(&dirs[2], Role::Slave, "host-b", slave_run);
    let answer = |n: u64| {
        MasterSample::Answer(Answer {
            n,
            q: signal(n as f64 + 0.25),
            round_trip_ns: 1000 + n,
            ..Answer::default()
        })
    };
    let passage = |n: u64, dir: Direction| Passage {
        dir,
        n,
        input: [0.0; 3],
        out: Signal {
            delay_samples: [1, 2, 3],
            ..signal(n as f64)
        },
        rotational: None,
        noise: [n as f64 * 1e-3; 3],
        jitter: 0.0,
        lost: false,
        fate: Fate::Deliver,
    };
    for n in 0..N {
        let sent = Sent {
            n,
            c: [n as f64; 3],
            tick_ns: 1_000_000 * n,
            ..Sent::default()
        };
        m.write(&Record::Sample(MasterSample::Sent(sent)))
            .expect("write");
        if n >= 50 {
            m.write(&Record::Sample(answer(n - 50))).expect("write");
        }
        e.write(&Record::Sample(passage(n, Direction::Forward)))
            .expect("write");
        if n >= 20 {
            e.write(&Record::Sample(passage(n - 20, Direction::Backward)))
                .expect("write");
        }
    }
    for n in N - 50..N {
        m.write(&Record::Sample(answer(n))).expect("write");
    }
    for n in N - 20..N {
        e.write(&Record::Sample(passage(n, Direction::Backward)))
            .expect("write");
    }
    for block in (0..N).collect::<Vec<_>>().chunks(100) {
        for &n in block.iter().rev() {
            let step = Step {
                n,
                received: signal(n as f64 + 0.5),
                ..Step::default()
            };
            s.write(&Record::Sample(SlaveSample::Step(
                step,
                Default::default(),
                None,
            )))
            .expect("write");
        }
    }
    // One step numbered past the run, one of a sample joined long before.
    for n in [N + 5000, 10] {
        let stray = Step {
            n,
            ..Step::default()
        };
        s.write(&Record::Sample(SlaveSample::Step(
            stray,
            Default::default(),
            None,
        )))
        .expect("write");
    }
    dirs
}

#[test]
fn records_of_two_clock_domains_join_sample_by_sample_within_the_window() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dirs = write_run(dir.path(), RUN);
    let starts = starts(&locate(&dirs).expect("located"), &|| false).expect("starts");
    let clocks: Vec<String> = starts.iter().flatten().map(|s| s.clock.clone()).collect();
    assert_eq!(clocks, ["host-a", "host-b", "host-b"]);
    let mut rows = Vec::new();
    let logs = join(&dirs, Arm::Paper, |r, _| {
        rows.push(*r);
        Ok(ControlFlow::Continue(()))
    })
    .expect("joined");
    assert_eq!(rows.len() as u64, N);
    for (k, r) in rows.iter().enumerate() {
        let n = k as u64;
        let x = n as f64;
        assert_eq!(r.n, n);
        assert_eq!(r.c, [x; 3], "c of {n}");
        assert!(r.received && r.stepped, "{n}");
        assert_eq!(
            r.q,
            [x + 0.25, 2.0 * (x + 0.25), 3.0 * (x + 0.25)],
            "q of {n}"
        );
        assert_eq!(r.v, [x + 0.5, 2.0 * (x + 0.5), 3.0 * (x + 0.5)], "v of {n}");
        assert_eq!(r.noise_f, [x * 1e-3; 3], "forward noise of {n}");
        assert_eq!(r.noise_b, [x * 1e-3; 3], "backward noise of {n}");
        assert_eq!(r.round_trip_ns, 1000 + n);
    }
    assert_eq!(
        logs.slave.unjoined, 1,
        "the step of a sample joined before joins nothing"
    );
    assert_eq!(logs.slave.invalid, 1, "the step past the run is no sample");
    assert_eq!(logs.master.left_out() + logs.emulator.left_out(), 0);
    assert_eq!(logs.slave.last_sample, Some(N - 1));
}

#[test]
fn records_of_another_run_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dirs = write_run(dir.path(), RUN + 1);
    let e = join(&dirs, Arm::Paper, |_, _| Ok(ControlFlow::Continue(()))).expect_err("two runs");
    assert!(e.to_string().contains("not one run"), "{e}");
}

#[test]
fn a_stop_ends_the_join_with_what_it_has() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dirs = write_run(dir.path(), RUN);
    let mut seen = 0;
    let logs = join(&dirs, Arm::Paper, |r, _| {
        seen += 1;
        Ok(if r.n == 99 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        })
    })
    .expect("joined");
    assert_eq!(seen, 100);
    assert_eq!(logs.master.starts.len(), 1);
}
