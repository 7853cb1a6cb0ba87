//! What carries the samples between the nodes of a run, and each node's command line
//! (written by the node's own argument types, so a flag is named once).

use super::Supervision;
use crate::error::Error;
use std::path::{Path, PathBuf};
use std::process::Command;
use tactile_messages::Role;
use tactile_runtime::args::{LinkKind, NodeArgs};
use tactile_transport::LinkArgs;

/// The link of a run, with each node's link options.
#[derive(Debug, Clone)]
pub struct Links {
    /// The link.
    pub kind: LinkKind,
    /// Options of the master, the emulator and the slave (the prefix is the run's).
    pub args: [LinkArgs; 3],
}

impl Links {
    /// Every node on `kind` with no options of its own (iceoryx2 needs none).
    pub fn plain(kind: LinkKind) -> Links {
        let one = LinkArgs {
            link: kind,
            ..LinkArgs::default()
        };
        Links {
            kind,
            args: [one.clone(), one.clone(), one],
        }
    }

    /// Every node on `kind`, on this host: UDP on three free ports; Zenoh with the
    /// emulator listening on a free loopback TCP port and the others connecting to it.
    pub fn on_this_host(kind: LinkKind) -> Result<Links, Error> {
        if kind == LinkKind::Zenoh && !cfg!(feature = "zenoh") {
            return Err(Error::BadInput(tactile_transport::options::NO_ZENOH.into()));
        }
        let failed = |e: std::io::Error| Error::Failed(format!("picking a free port: {e}"));
        let mut l = Links::plain(kind);
        match kind {
            LinkKind::Iceoryx2 => {}
            LinkKind::Udp => {
                let p = tactile_transport::udp::UdpPorts::free()
                    .map_err(|e| Error::Failed(e.to_string()))?
                    .arg();
                l.args.iter_mut().for_each(|a| a.udp_ports = p.clone());
            }
            LinkKind::Zenoh => {
                let s = std::net::TcpListener::bind("127.0.0.1:0").map_err(failed)?;
                let at = format!("tcp/127.0.0.1:{}", s.local_addr().map_err(failed)?.port());
                let [m, e, sl] = &mut l.args;
                m.connect = vec![at.clone()];
                e.listen = vec![at.clone()];
                sl.connect = vec![at];
            }
        }
        Ok(l)
    }

    /// The link options of `role`.
    pub fn of(&self, role: Role) -> &LinkArgs {
        &self.args[role.index()]
    }

    /// [`Links::across`] over Zenoh with mutual TLS: every node with the identity
    /// `files` (CA, certificate, key), every endpoint `tls/`.
    pub fn across_tls(hosts: &super::netns::Pair, files: &[PathBuf; 3]) -> Links {
        let mut l = Links::across(LinkKind::Zenoh, hosts);
        for a in &mut l.args {
            for e in a.listen.iter_mut().chain(a.connect.iter_mut()) {
                if let Some(rest) = e.strip_prefix("tcp/") {
                    *e = format!("tls/{rest}");
                }
            }
            let [ca, cert, key] = files.clone().map(Some);
            (a.tls_ca, a.tls_cert, a.tls_key) = (ca, cert, key);
        }
        l
    }

    /// Master on host 0 of `hosts`, emulator and slave on host 1, every hop on
    /// `kind` (Zenoh or UDP) across the veth pair.
    pub fn across(kind: LinkKind, hosts: &super::netns::Pair) -> Links {
        let [a, b] = &hosts.addrs;
        let mut l = Links::plain(kind);
        let [m, e, s] = &mut l.args;
        if kind == LinkKind::Zenoh {
            let (la, lb) = (format!("tcp/{a}:7447"), format!("tcp/{b}:7448"));
            m.listen = vec![la.clone()];
            (e.connect, e.listen) = (vec![la], vec![lb.clone()]);
            s.connect = vec![lb];
        } else {
            for x in [m, e, s] {
                x.udp_ports = "47501,47502,47503".into();
                x.udp_hosts = format!("{a},{b},{b}");
            }
        }
        l
    }
}

/// The command line of one node.
pub fn node_command(
    sup: &Supervision,
    exe: &Path,
    role: Role,
    scenario_file: &Path,
    out: &Path,
    append: bool,
) -> Command {
    let node = NodeArgs {
        scenario: scenario_file.to_path_buf(),
        out: out.to_path_buf(),
        link: LinkArgs {
            prefix: sup.prefix.clone(),
            ..sup.link.of(role).clone()
        },
        spin_us: sup.spin.map(|d| d.as_micros() as u64),
        wake_early_us: sup.wake_early.map(|d| d.as_micros() as u64),
        sched: sup.sched,
        idle: sup.idle,
        priority: tactile_runtime::sched::DEFAULT_PRIORITY,
        cpu: sup.pin.then_some(if role == Role::Master { 0 } else { 1 }),
        append,
        supervised: Some(std::process::id()),
    };
    let mut argv: Vec<String> = sup.wrap[role.index()].clone();
    argv.push(exe.display().to_string());
    let mut cmd = Command::new(&argv[0]);
    cmd.args(&argv[1..]).args(node.argv());
    if role == Role::Master {
        cmd.args(["--startup-timeout-s", "10"]);
    }
    cmd
}
