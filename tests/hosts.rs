//! Master and slave on different hosts, over Zenoh. Two Linux network namespaces
//! joined by a veth pair are the two hosts, with addresses from 198.18.0.0/15 (the
//! block reserved for benchmarking); each test creates its own and removes them, also
//! when it fails. Where namespaces cannot be made (not root, no `ip`), a test fails
//! under CI (`CI=true`) naming what it lacks, and elsewhere says why and skips. The tests without namespaces (lockstep over Zenoh, bad payloads) run on
//! loopback. They need the Zenoh link: the README's test command builds with
//! `--all-features`.
#![cfg(feature = "zenoh")]

use crate::util;

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tactile_messages::samples::{Flags, Forward};
use tactile_report::trace::signal_columns;
use util::{column, finish_ok, free_port, node_dir, Sandbox};

/// Two hosts: network namespaces made for the test, removed on drop.
struct Hosts {
    pair: tactile_launch::netns::Pair,
    addrs: [String; 2],
}

impl Hosts {
    /// Creates the pair, or says why it cannot and returns None (the test skips).
    fn new(tag: &str) -> Option<Hosts> {
        match tactile_launch::netns::Pair::new(&format!("{}{tag}", std::process::id() % 100_000)) {
            Ok(pair) => Some(Hosts {
                addrs: pair.addrs.clone(),
                pair,
            }),
            Err(e) => {
                util::cannot(&format!(
                    "cannot make network namespaces ({e}); run as root to test across hosts"
                ));
                None
            }
        }
    }

    /// `program args...` on host `k`, with its own clock domain so the report treats
    /// the two hosts as two clocks.
    fn on(&self, k: usize, program: &str, args: &[&str]) -> Command {
        let exec = self.pair.exec(k);
        let mut c = Command::new(&exec[0]);
        c.args(&exec[1..])
            .arg(node_dir().join(program))
            .args(args)
            .env("TACTILE_CLOCK_DOMAIN", format!("host-{k}"))
            // The nodes' own choice of Zenoh runtimes, whatever the caller's shell has.
            .env_remove("ZENOH_RUNTIME");
        c
    }
}

fn spawn(mut c: Command, sb: &Sandbox) -> Child {
    c.current_dir(sb.dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start node")
}

/// Waits for the master, emulator and slave (each must complete) and returns the
/// summary of `tactile report` over their folders (a-master, b-emulator, b-slave).
fn report_of(sb: &Sandbox, nodes: [Child; 3]) -> serde_json::Value {
    for (child, name) in nodes.into_iter().zip(["master", "emulator", "slave"]) {
        finish_ok(child, name);
    }
    let dirs = ["a-master", "b-emulator", "b-slave"];
    let o = sb.tactile(&["report", dirs[0], dirs[1], dirs[2], "--out", "report"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.json("report", "summary.json")
}

/// Master on host A; emulator and slave on host B, the emulator joined to the master
/// over Zenoh and to the slave over iceoryx2 (`all_zenoh`: over Zenoh too).
fn master_here_slave_there(all_zenoh: bool) {
    let tag = if all_zenoh { "z" } else { "m" };
    let Some(hosts) = Hosts::new(tag) else {
        return;
    };
    let sb = Sandbox::new(&format!("hosts{tag}"));
    let scenario = sb.write("s.toml", &util::paper_1khz(3000));
    let s = scenario.to_str().expect("utf-8");
    let a = format!("tcp/{}:7447", hosts.addrs[0]);
    let b = format!("tcp/{}:7448", hosts.addrs[1]);
    let p = sb.prefix.clone();
    let common = |dir: &'static str| vec!["--scenario", s, "--out", dir, "--prefix", &p];
    let mut m = common("a-master");
    m.extend(["--link", "zenoh", "--listen", &a]);
    let mut e = common("b-emulator");
    e.extend(["--master-link", "zenoh", "--connect", &a]);
    let mut sl = common("b-slave");
    if all_zenoh {
        e.extend(["--slave-link", "zenoh", "--listen", &b]);
        sl.extend(["--link", "zenoh", "--connect", &b]);
    } else {
        e.extend(["--slave-link", "iceoryx2"]);
    }
    let slave = spawn(hosts.on(1, "tactile-slave", &sl), &sb);
    let emulator = spawn(hosts.on(1, "tactile-emulator", &e), &sb);
    let master = spawn(hosts.on(0, "tactile-master", &m), &sb);
    let s = report_of(&sb, [master, emulator, slave]);
    let received = column(&sb.trace("report"), "received");
    let lost: Vec<usize> = (0..received.len())
        .filter(|&n| received[n] == 0.0)
        .collect();
    assert_eq!(s["samples_lost"], 0, "lost {lost:?}; {}", s["channels"]);
    for stream in ["c", "v", "h", "q"] {
        assert_eq!(s["channels"][stream]["received"], 3000, "{stream}");
    }
    assert!(util::num(&s["round_trip_ns"]["p50"]) > 0.0);
    assert!(util::num(&s["overhead_ns"]["p99"]) > 0.0);
    // Two clocks: the hops across hosts are not reported as times; the stages on one
    // host are; the offset between the hosts is an estimate, and since the two
    // namespaces in fact share one kernel clock, the truth is 0: the estimate must be
    // within its own uncertainty of it.
    let clocks = &s["clocks"];
    assert_eq!(clocks["shared"], false, "{clocks}");
    let stages = &s["stages_ns"];
    assert!(stages["hop_master_to_emulator"].is_null(), "{stages}");
    assert!(
        util::num(&stages["emulator_forward"]["count"]) > 2000.0,
        "{stages}"
    );
    assert!(
        util::num(&stages["slave_compute"]["count"]) > 2000.0,
        "{stages}"
    );
    let offsets = clocks["offsets"].as_array().expect("offsets");
    let me = offsets
        .iter()
        .find(|o| o["between"] == "master-emulator")
        .expect("a master-emulator estimate");
    let off = me["offset_ns_estimate"].as_i64().expect("offset");
    let unc = me["uncertainty_ns"].as_i64().expect("uncertainty");
    assert!(
        off.abs() <= unc,
        "offset {off} ns beyond its uncertainty {unc} ns"
    );
    assert_eq!(
        s["nodes"]["emulator"]["link"]
            .as_str()
            .map(|l| l.contains("zenoh")),
        Some(true)
    );
    // Each node hands Zenoh's work to one runtime thread unless the user says
    // otherwise (ZENOH_RUNTIME), and its log says which runtimes it ran.
    for (dir, role) in [("a-master", "master"), ("b-emulator", "emulator")] {
        let log = std::fs::read_to_string(sb.path(dir).join(format!("{role}.log"))).expect("log");
        let want = format!("Zenoh runtimes: {}", tactile_transport::zenoh_link::RUNTIME);
        assert!(log.contains(&want), "{role}: {log}");
    }
}

#[test]
fn master_on_one_host_emulator_and_slave_on_the_other() {
    master_here_slave_there(false);
}

#[test]
fn all_three_nodes_over_zenoh_across_hosts() {
    master_here_slave_there(true);
}

#[test]
fn the_slave_host_node_killed_breaks_the_loop_and_it_resumes_after_restart() {
    let Some(hosts) = Hosts::new("k") else {
        return;
    };
    let sb = Sandbox::new("hostkill");
    let scenario = sb.write("s.toml", &util::paper_1khz(4000));
    let s = scenario.to_str().expect("utf-8");
    let a = format!("tcp/{}:7447", hosts.addrs[0]);
    let p = sb.prefix.clone();
    // No emulator: the master talks to the slave across the network directly.
    let master = spawn(
        hosts.on(
            0,
            "tactile-master",
            &[
                "--scenario",
                s,
                "--out",
                "m",
                "--prefix",
                &p,
                "--link",
                "zenoh",
                "--listen",
                &a,
                "--direct",
            ],
        ),
        &sb,
    );
    let slave_args = [
        "--scenario",
        s,
        "--out",
        "s",
        "--prefix",
        &p,
        "--link",
        "zenoh",
        "--connect",
        &a,
    ];
    let mut slave = spawn(hosts.on(1, "tactile-slave", &slave_args), &sb);
    let rec = sb.path("s").join("slave.rec");
    util::wait_for_rows(&rec, 2_000, Duration::from_secs(30));
    slave.kill().expect("SIGKILL the slave");
    let _ = slave.wait();
    // The master notices: the loop breaks before the slave is back.
    let log = sb.path("m").join("master.log");
    util::wait_for("the loop broke", Duration::from_secs(10), || {
        std::fs::read_to_string(&log).is_ok_and(|l| l.contains("loop broken"))
    });
    let mut again = slave_args.to_vec();
    again.push("--append");
    let slave = spawn(hosts.on(1, "tactile-slave", &again), &sb);
    finish_ok(master, "master");
    finish_ok(slave, "slave");
    let o = sb.tactile(&["report", "m", "s", "--out", "report"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sum = sb.json("report", "summary.json");
    let m = &sum["master"]["counters"];
    assert!(util::num(&m["loop_breaks"]) >= 1.0, "{m}");
    assert!(util::num(&m["resumes"]) >= 1.0, "{m}");
    assert_eq!(
        sum["nodes"]["slave"]["pids"].as_array().map(Vec::len),
        Some(2)
    );
    // The break came exactly at the peer timeout (10 samples after the last answer),
    // and answers came back after the restart.
    let trace = sb.trace("report");
    let flags = column(&trace, "flags_m");
    let received = column(&trace, "received");
    let first = (0..flags.len())
        .find(|&n| Flags::from_bits(flags[n] as u32).intersects(Flags::PEER_LOST))
        .expect("a break");
    assert_eq!(received[first - 10], 1.0);
    assert!(received[first - 9..=first].iter().all(|r| *r == 0.0));
    assert!(received[first..].iter().filter(|r| **r == 1.0).count() > 500);
}

#[test]
fn lockstep_over_zenoh_equals_the_in_process_simulation() {
    let sb = Sandbox::new("zlock");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace(
            "[network.forward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
            "[network.forward]\ndelay = [2, 3, 1]\nnoise_std = [0.0005, 0.001, 0.0]",
        );
    let scenario = sb.write("s.toml", &text);
    let out = sb.path("z");
    let o = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--link",
        "zenoh",
        "-q",
        "--prefix",
        &sb.prefix,
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.simulate(&scenario, "sim");
    assert_eq!(
        signal_columns(&sb.trace("z")),
        signal_columns(&sb.trace("sim"))
    );
    assert_eq!(sb.json("z", "summary.json")["samples_lost"], 0);
    sb.assert_no_leftover_processes();
}

/// Frames a stranger, a truncating network and another build would send.
fn bad_payloads() -> Vec<Vec<u8>> {
    let mut good = Vec::new();
    let f = Forward {
        run: 1,
        ..Forward::default()
    };
    tactile_transport::wire::encode(&f, &mut good).expect("encode");
    let mut other_version = good.clone();
    other_version[4] = other_version[4].wrapping_add(1);
    vec![
        b"GET / HTTP/1.1\r\n\r\n".to_vec(),
        vec![0xff; 300],
        good[..good.len() / 2].to_vec(),
        good[..5].to_vec(),
        other_version,
    ]
}

#[test]
fn garbage_truncated_and_other_version_payloads_are_counted_and_dropped() {
    let sb = Sandbox::new("garbage");
    let scenario = sb.write("s.toml", &util::paper_1khz(2500));
    let s = scenario.to_str().expect("utf-8");
    let at: Vec<String> = (0..3)
        .map(|_| format!("tcp/127.0.0.1:{}", free_port()))
        .collect();
    let p = sb.prefix.clone();
    // Each node listens on its own port; master and slave connect to the emulator.
    let args = |dir: &'static str, listen: &str| {
        let mut a: Vec<String> = [
            "--scenario",
            s,
            "--out",
            dir,
            "--prefix",
            &p,
            "--link",
            "zenoh",
        ]
        .map(String::from)
        .to_vec();
        a.extend(["--listen".to_string(), listen.to_string()]);
        if dir != "e" {
            a.extend(["--connect".to_string(), at[1].clone()]);
        }
        a
    };
    let node = |program: &str, a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        spawn(sb.node(program, &a), &sb)
    };
    let emulator = node("tactile-emulator", args("e", &at[1]));
    let slave = node("tactile-slave", args("s", &at[2]));
    let master = node("tactile-master", args("m", &at[0]));
    // Once the run is going, a stranger on the same Zenoh network sends junk at every
    // stream of the run, one session per node (peers do not route for each other).
    let rec = sb.path("m").join("master.rec");
    util::wait_for_rows(&rec, util::MASTER_ROWS * 300, Duration::from_secs(30));
    let sessions: Vec<tactile_transport::zenoh_link::zenoh::Session> = at
        .iter()
        .map(|e| {
            tactile_transport::zenoh_link::open_session(
                &tactile_transport::zenoh_link::ZenohOptions {
                    connect: vec![e.clone()],
                    ..Default::default()
                },
            )
            .expect("session")
        })
        .collect();
    // Each stranger's session has met its node before the junk goes out.
    for (session, node) in sessions.iter().zip(["master", "emulator", "slave"]) {
        util::wait_for(
            &format!("a session met the {node}"),
            Duration::from_secs(10),
            || {
                let info = session.info();
                tactile_transport::zenoh_link::zenoh::Wait::wait(info.peers_zid())
                    .next()
                    .is_some()
            },
        );
    }
    let bad = bad_payloads();
    for round in 0..40 {
        for stream in ["c", "v", "h", "q"] {
            let key = format!("tactile/{p}/{stream}");
            for session in &sessions {
                for b in &bad {
                    tactile_transport::zenoh_link::zenoh::Wait::wait(
                        session.put(key.as_str(), b.clone()),
                    )
                    .expect("put");
                }
            }
        }
        std::thread::sleep(Duration::from_millis(5 + round % 3));
    }
    finish_ok(master, "master");
    finish_ok(emulator, "emulator");
    finish_ok(slave, "slave");
    let o = sb.tactile(&["report", "m", "e", "s", "--out", "report"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sum = sb.json("report", "summary.json");
    assert_eq!(sum["samples_lost"], 0, "the run went on untouched");
    for (who, inbox) in [
        (&sum["slave"]["v_in"], "slave v"),
        (&sum["emulator"]["links"]["c_in"], "emulator c"),
        (&sum["master"]["q_in"], "master q"),
    ] {
        assert!(
            util::num(&who["malformed"]) >= (4 * 40) as f64,
            "{inbox}: {who}"
        );
        assert!(util::num(&who["wrong_version"]) >= 40.0, "{inbox}: {who}");
    }
    let log = std::fs::read_to_string(sb.path("s").join("slave.log")).expect("log");
    assert!(log.contains("wire format version"), "{log}");
}

#[test]
fn garbage_datagrams_at_a_udp_node_are_counted_and_dropped() {
    let sb = Sandbox::new("udpjunk");
    let scenario = sb.write("s.toml", &util::paper_1khz(2000));
    let s = scenario.to_str().expect("utf-8");
    let ports = tactile_transport::udp::UdpPorts::free().expect("ports");
    let arg = ports.arg();
    let p = sb.prefix.clone();
    let args = |dir: &'static str| {
        vec![
            "--scenario",
            s,
            "--out",
            dir,
            "--prefix",
            &p,
            "--link",
            "udp",
            "--udp-ports",
            &arg,
        ]
    };
    let emulator = spawn(sb.node("tactile-emulator", &args("e")), &sb);
    let slave = spawn(sb.node("tactile-slave", &args("s")), &sb);
    let master = spawn(sb.node("tactile-master", &args("m")), &sb);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").expect("bind");
    // The run is going (the slave answers) before the junk goes out.
    let rec = sb.path("m").join("master.rec");
    util::wait_for_rows(&rec, util::MASTER_ROWS * 300, Duration::from_secs(30));
    for _ in 0..50 {
        for b in bad_payloads() {
            let _ = socket.send_to(&b, ("127.0.0.1", ports.ports[2]));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    finish_ok(master, "master");
    finish_ok(emulator, "emulator");
    finish_ok(slave, "slave");
    let o = sb.tactile(&["report", "m", "e", "s", "--out", "report"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sum = sb.json("report", "summary.json");
    assert_eq!(sum["samples_lost"], 0);
    let v = &sum["slave"]["v_in"];
    assert_eq!(v["malformed"], 4 * 50, "{v}");
    assert_eq!(v["wrong_version"], 50, "{v}");
}

/// A PKI for the hosts' addresses, or None (after saying why) without openssl.
fn pki(dir: &std::path::Path, name: &str, ips: &[String]) -> Option<[std::path::PathBuf; 3]> {
    match tactile_launch::pki::make(dir, name, ips) {
        Ok(files) => Some(files),
        Err(e @ tactile_launch::pki::PkiError::Start(_)) => {
            util::cannot(&format!(
                "openssl is needed to make the test certificates ({e})"
            ));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Master on host A and emulator on host B over mutually authenticated TLS: the loop
/// completes with nothing lost while a peer with a certificate of another CA, and one
/// without any (plain TCP), try the master's port and are refused at the handshake.
#[test]
fn mutual_tls_admits_the_run_and_refuses_strangers() {
    let Some(hosts) = Hosts::new("t") else {
        return;
    };
    let sb = Sandbox::new("hoststls");
    let Some(run_pki) = pki(&sb.path("pki"), "run", &hosts.addrs) else {
        return;
    };
    let mut rogue_pki = pki(&sb.path("rogue"), "rogue", &hosts.addrs).expect("rogue pki");
    // The stranger trusts the run's CA (so it would accept the master) but holds a
    // certificate of its own CA: the master must refuse it.
    let both = sb.path("rogue").join("both.pem");
    let cas = [&run_pki[0], &rogue_pki[0]].map(|f| std::fs::read_to_string(f).expect("ca"));
    std::fs::write(&both, cas.concat()).expect("both CAs");
    rogue_pki[0] = both;
    let scenario = sb.write("s.toml", &util::paper_1khz(4000));
    let s = scenario.to_str().expect("utf-8");
    let a = format!("tls/{}:7447", hosts.addrs[0]);
    let p = sb.prefix.clone();
    let tls = tactile_launch::pki::args(&run_pki);
    let tls: Vec<&str> = tls.iter().map(String::as_str).collect();
    let common = |dir: &'static str| vec!["--scenario", s, "--out", dir, "--prefix", &p];
    let mut m = common("a-master");
    m.extend(["--link", "zenoh", "--listen", &a]);
    m.extend(&tls);
    let mut e = common("b-emulator");
    e.extend([
        "--master-link",
        "zenoh",
        "--connect",
        &a,
        "--slave-link",
        "iceoryx2",
    ]);
    e.extend(&tls);
    let slave = spawn(hosts.on(1, "tactile-slave", &common("b-slave")), &sb);
    let emulator = spawn(hosts.on(1, "tactile-emulator", &e), &sb);
    let master = spawn(hosts.on(0, "tactile-master", &m), &sb);
    let rec = sb.path("a-master").join("master.rec");
    util::wait_for_rows(&rec, util::MASTER_ROWS * 3_000, Duration::from_secs(30));
    // Strangers on host B, under other prefixes (the run's are locked): one with a
    // certificate of another CA, one in clear.
    let rogue = tactile_launch::pki::args(&rogue_pki);
    let (p1, p2) = (format!("{p}r"), format!("{p}s"));
    let mut r1 = vec!["--scenario", s, "--out", "rogue1", "--prefix", &p1];
    r1.extend(["--link", "zenoh", "--connect", &a]);
    r1.extend(rogue.iter().map(String::as_str));
    let clear = format!("tcp/{}:7447", hosts.addrs[0]);
    let r2 = vec![
        "--scenario",
        s,
        "--out",
        "rogue2",
        "--prefix",
        &p2,
        "--link",
        "zenoh",
        "--connect",
        &clear,
    ];
    // Killed however the test ends: a stranger never finds its master and would wait.
    let rogues = Killed(vec![
        spawn(hosts.on(1, "tactile-slave", &r1), &sb),
        spawn(hosts.on(1, "tactile-slave", &r2), &sb),
    ]);
    let log = sb.path("a-master").join("master.log");
    // rustls at the master: a certificate of an unknown CA, and TLS records that are
    // not TLS (the stranger in clear). Which of the two record errors rustls names
    // depends on the clear stranger's first bytes: a bad content type, or a bad
    // protocol version behind a content type that happened to be valid.
    let not_tls =
        |l: &str| l.contains("InvalidContentType") || l.contains("UnknownProtocolVersion");
    let refused = |l: &str| l.contains("UnknownIssuer") && not_tls(l);
    let start = Instant::now();
    while !std::fs::read_to_string(&log).is_ok_and(|l| refused(&l)) {
        if start.elapsed() > Duration::from_secs(20) {
            let read = |p: std::path::PathBuf| std::fs::read_to_string(p).unwrap_or_default();
            panic!(
                "the master did not refuse both strangers:\nmaster:\n{}\nrogue1:\n{}\nrogue2:\n{}",
                read(log.clone()),
                read(sb.path("rogue1").join("slave.log")),
                read(sb.path("rogue2").join("slave.log"))
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let sum = report_of(&sb, [master, emulator, slave]);
    drop(rogues);
    assert_eq!(sum["samples_lost"], 0, "{}", sum["channels"]);
    for stream in ["c", "v", "h", "q"] {
        assert_eq!(sum["channels"][stream]["received"], 4000, "{stream}");
    }
    let link = sum["nodes"]["master"]["link"].as_str().expect("link");
    assert!(link.contains("mutual TLS"), "{link}");
    for r in ["rogue1", "rogue2"] {
        let (log, _) = (sb.path(r).join("slave.log"), ());
        let text = std::fs::read_to_string(log).unwrap_or_default();
        assert!(!text.contains("joined run"), "{r} joined:\n{text}");
        // The connecting side says its attempt failed, and to where.
        assert!(
            text.contains("Unable to connect to configured peer") && text.contains(&a[4..]),
            "{r} says nothing of its failed attempts:\n{text}"
        );
    }
}

/// Child processes killed (and reaped) when dropped, also when a test panics.
struct Killed(Vec<Child>);

impl Drop for Killed {
    fn drop(&mut self) {
        // SIGTERM first, so each closes its record and releases its lock.
        for c in &self.0 {
            if let Some(pid) = rustix::process::Pid::from_raw(c.id() as i32) {
                let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
            }
        }
        let until = Instant::now() + Duration::from_secs(3);
        for c in &mut self.0 {
            while Instant::now() < until && matches!(c.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(10));
            }
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}
