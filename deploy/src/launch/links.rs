//! What carries the samples between the nodes of a run, and each node's command line.

use super::Supervision;
use crate::error::Error;
use std::path::Path;
use std::process::Command;
use tactile_messages::Role;
use tactile_runtime::args::LinkKind;

/// The link of a run on one host, with the options each node needs for it.
#[derive(Debug, Clone)]
pub struct Links {
    /// The link.
    pub kind: LinkKind,
    /// Options of the master, the emulator and the slave.
    pub args: [Vec<String>; 3],
}

impl Links {
    /// Every node on `kind`, on this host: UDP on three free ports; Zenoh with the
    /// emulator listening on a free loopback TCP port and the others connecting to it.
    pub fn on_this_host(kind: LinkKind) -> Result<Links, Error> {
        if kind == LinkKind::Zenoh && !cfg!(feature = "zenoh") {
            return Err(Error::BadInput(tactile_transport::options::NO_ZENOH.into()));
        }
        let failed = |e: std::io::Error| Error::Failed(format!("picking a free port: {e}"));
        let args = match kind {
            LinkKind::Iceoryx2 => Default::default(),
            LinkKind::Udp => {
                let p = tactile_transport::udp::UdpPorts::free()
                    .map_err(|e| Error::Failed(e.to_string()))?
                    .arg();
                let a = vec!["--udp-ports".to_string(), p];
                [a.clone(), a.clone(), a]
            }
            LinkKind::Zenoh => {
                let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(failed)?;
                let port = l.local_addr().map_err(failed)?.port();
                let at = format!("tcp/127.0.0.1:{port}");
                let connect = vec!["--connect".to_string(), at.clone()];
                [connect.clone(), vec!["--listen".to_string(), at], connect]
            }
        };
        Ok(Links { kind, args })
    }

    /// The link options of `role`.
    pub fn args(&self, role: Role) -> &[String] {
        &self.args[role.index()]
    }

    /// [`Links::across`] over Zenoh with mutual TLS: every node with the identity
    /// `tls` (its `--tls-*` options), every endpoint `tls/`.
    pub fn across_tls(hosts: &super::netns::Pair, tls: &[String]) -> Links {
        let mut l = Links::across(LinkKind::Zenoh, hosts);
        for args in &mut l.args {
            for a in args.iter_mut() {
                if let Some(rest) = a.strip_prefix("tcp/") {
                    *a = format!("tls/{rest}");
                }
            }
            args.extend(tls.iter().cloned());
        }
        l
    }

    /// Master on host 0 of `hosts`, emulator and slave on host 1, every hop on
    /// `kind` (Zenoh or UDP) across the veth pair.
    pub fn across(kind: LinkKind, hosts: &super::netns::Pair) -> Links {
        let [a, b] = &hosts.addrs;
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let args = match kind {
            LinkKind::Zenoh => {
                let (la, lb) = (format!("tcp/{a}:7447"), format!("tcp/{b}:7448"));
                [
                    s(&["--listen", &la]),
                    s(&["--connect", &la, "--listen", &lb]),
                    s(&["--connect", &lb]),
                ]
            }
            _ => {
                let u = s(&[
                    "--udp-ports",
                    "47501,47502,47503",
                    "--udp-hosts",
                    &format!("{a},{b},{b}"),
                ]);
                [u.clone(), u.clone(), u]
            }
        };
        Links { kind, args }
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
    let mut argv: Vec<String> = sup.wrap[role.index()].clone();
    argv.push(exe.display().to_string());
    let mut cmd = Command::new(&argv[0]);
    cmd.args(&argv[1..]);
    cmd.arg("--scenario")
        .arg(scenario_file)
        .arg("--out")
        .arg(out)
        .args(["--prefix", &sup.prefix])
        .args(["--sched", sup.sched.name()])
        .args(["--idle", sup.idle.name()])
        .args(["--supervised", &std::process::id().to_string()]);
    if let Some(spin) = sup.spin {
        cmd.args(["--spin-us", &spin.as_micros().to_string()]);
    }
    if let Some(early) = sup.wake_early {
        cmd.args(["--wake-early-us", &early.as_micros().to_string()]);
    }
    cmd.args(["--link", sup.link.kind.name()]);
    cmd.args(sup.link.args(role));
    if sup.pin {
        cmd.args(["--cpu", if role == Role::Master { "0" } else { "1" }]);
    }
    if role == Role::Master {
        cmd.args(["--startup-timeout-s", "10"]);
    }
    if append {
        cmd.arg("--append");
    }
    cmd
}
