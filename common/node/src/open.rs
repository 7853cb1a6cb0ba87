//! Opening the links a node's arguments choose: iceoryx2, UDP or Zenoh per side, each
//! option checked before anything starts.

use crate::args::{LinkKind, NodeArgs, NodeError};
use std::time::Duration;

fn udp_ports(a: &NodeArgs) -> Result<crate::udp::UdpPorts, NodeError> {
    let ports = crate::udp::UdpPorts::parse(&a.udp_ports).ok_or_else(|| {
        NodeError::BadInput(format!(
            "--udp-ports {:?}: expected three ports m,e,s",
            a.udp_ports
        ))
    })?;
    ports.on_hosts(&a.udp_hosts).ok_or_else(|| {
        NodeError::BadInput(format!(
            "--udp-hosts {:?}: expected three IP addresses a,b,c",
            a.udp_hosts
        ))
    })
}

/// What a build without the `zenoh` feature answers to `--link zenoh`.
pub const NO_ZENOH: &str = "--link zenoh: this build has no Zenoh link; build with \
`cargo build --release --workspace --features zenoh` (docs/03-across-hosts.md)";

/// The Zenoh endpoints of the arguments.
#[cfg(feature = "zenoh")]
pub fn zenoh_options(a: &NodeArgs) -> crate::zlink::ZenohOptions {
    let tls = match (&a.tls_ca, &a.tls_cert, &a.tls_key) {
        (Some(ca), Some(cert), Some(key)) => Some(crate::zlink::TlsFiles {
            ca: ca.clone(),
            cert: cert.clone(),
            key: key.clone(),
        }),
        _ => None,
    };
    crate::zlink::ZenohOptions {
        listen: a.listen.clone(),
        connect: a.connect.clone(),
        scout: a.scout,
        tls,
    }
}

/// Checks the TLS options: the three files readable, every endpoint `tls/` with
/// them and none without.
fn check_tls(a: &NodeArgs) -> Result<(), NodeError> {
    let tls = a.tls_ca.is_some();
    for (what, file) in [
        ("--tls-ca", &a.tls_ca),
        ("--tls-cert", &a.tls_cert),
        ("--tls-key", &a.tls_key),
    ] {
        if let Some(f) = file {
            crate::files::read_text(f, what, 1 << 20).map_err(NodeError::BadInput)?;
        }
    }
    for e in a.listen.iter().chain(&a.connect) {
        let is_tls = e.starts_with("tls/");
        if tls && !is_tls {
            return Err(NodeError::BadInput(format!(
                "Zenoh endpoint {e:?}: with --tls-ca every endpoint is tls/ADDRESS:PORT (nothing joins in clear)"
            )));
        }
        if is_tls && !tls {
            return Err(NodeError::BadInput(format!(
                "Zenoh endpoint {e:?}: a tls/ endpoint needs --tls-ca, --tls-cert and --tls-key"
            )));
        }
    }
    Ok(())
}

/// True if every Zenoh endpoint stays on this host (loopback): plain TCP there is
/// only as open as the host.
pub fn loopback_only(a: &NodeArgs) -> bool {
    !a.scout
        && a.listen.iter().chain(&a.connect).all(|e| {
            e.split_once('/')
                .and_then(|(_, addr)| addr.parse::<std::net::SocketAddr>().ok())
                .is_some_and(|s| s.ip().is_loopback())
        })
}

/// Checks the options of the links in use, before anything starts.
pub fn check_link_args(a: &NodeArgs, links: &[LinkKind]) -> Result<(), NodeError> {
    if links.contains(&LinkKind::Udp) {
        udp_ports(a)?;
    }
    if links.contains(&LinkKind::Zenoh) {
        if !cfg!(feature = "zenoh") {
            return Err(NodeError::BadInput(NO_ZENOH.into()));
        }
        if a.listen.is_empty() && a.connect.is_empty() && !a.scout {
            return Err(NodeError::BadInput(
                "--link zenoh: give --listen ENDPOINT and/or --connect ENDPOINT (or --scout) so the nodes can meet".into(),
            ));
        }
        for e in a.listen.iter().chain(&a.connect) {
            let ok = e.split_once('/').is_some_and(|(proto, addr)| {
                matches!(proto, "tcp" | "udp" | "tls")
                    && addr.parse::<std::net::SocketAddr>().is_ok()
            });
            if !ok {
                return Err(NodeError::BadInput(format!(
                    "Zenoh endpoint {e:?}: expected tcp/ADDRESS:PORT, udp/ADDRESS:PORT or tls/ADDRESS:PORT"
                )));
            }
        }
        check_tls(a)?;
        #[cfg(feature = "zenoh")]
        zenoh_options(a)
            .config()
            .map_err(|e| NodeError::BadInput(e.to_string()))?;
    }
    Ok(())
}

fn opened<T>(r: Result<T, crate::link::LinkError>) -> Result<T, NodeError> {
    r.map_err(|e| NodeError::Failed(e.to_string()))
}

/// The master's link as the arguments choose it; `direct`: no emulator, the slave
/// is the master's peer (Zenoh only).
pub fn master_link(
    a: &NodeArgs,
    spin: Duration,
    direct: bool,
) -> Result<Box<dyn crate::link::MasterLink>, NodeError> {
    let wait = crate::link::WaitPolicy { spin };
    if direct && a.link != LinkKind::Zenoh {
        return Err(NodeError::BadInput(
            "--direct (no emulator) needs --link zenoh".into(),
        ));
    }
    Ok(match a.link {
        LinkKind::Iceoryx2 => Box::new(opened(crate::ipc::IoxMaster::open(&a.prefix, wait))?),
        LinkKind::Udp => Box::new(opened(crate::udp::UdpMaster::open(udp_ports(a)?, wait))?),
        LinkKind::Zenoh => zenoh_open::master(a, direct, wait)?,
    })
}

/// The emulator's link: `towards_master` and `towards_slave` chosen on their own, so
/// the emulator can sit on either host (Zenoh on one side, iceoryx2 on the other).
pub fn emulator_link(
    a: &NodeArgs,
    spin: Duration,
    towards_master: LinkKind,
    towards_slave: LinkKind,
) -> Result<Box<dyn crate::link::EmulatorLink>, NodeError> {
    use LinkKind::{Iceoryx2, Udp, Zenoh};
    let wait = crate::link::WaitPolicy { spin };
    Ok(match (towards_master, towards_slave) {
        (Iceoryx2, Iceoryx2) => Box::new(opened(crate::ipc::IoxEmulator::open(&a.prefix, wait))?),
        (Udp, Udp) => Box::new(opened(crate::udp::UdpEmulator::open(udp_ports(a)?, wait))?),
        (Zenoh, Zenoh) | (Zenoh, Iceoryx2) | (Iceoryx2, Zenoh) => zenoh_open::emulator(
            a,
            towards_master == Iceoryx2,
            towards_slave == Iceoryx2,
            wait,
        )?,
        (m, s) => {
            return Err(NodeError::BadInput(format!(
                "--master-link {} with --slave-link {}: UDP cannot be mixed with another link (Zenoh and iceoryx2 can)",
                m.name(),
                s.name()
            )))
        }
    })
}

/// The slave's link as the arguments choose it.
pub fn slave_link(
    a: &NodeArgs,
    spin: Duration,
) -> Result<Box<dyn crate::link::SlaveLink>, NodeError> {
    let wait = crate::link::WaitPolicy { spin };
    Ok(match a.link {
        LinkKind::Iceoryx2 => Box::new(opened(crate::ipc::IoxSlave::open(&a.prefix, wait))?),
        LinkKind::Udp => Box::new(opened(crate::udp::UdpSlave::open(udp_ports(a)?, wait))?),
        LinkKind::Zenoh => zenoh_open::slave(a, wait)?,
    })
}

/// Opening the Zenoh links, in a build with the `zenoh` feature.
#[cfg(feature = "zenoh")]
mod zenoh_open {
    use super::{loopback_only, opened, NodeArgs, NodeError};
    use crate::link::WaitPolicy;
    use crate::link::{EmulatorLink, MasterLink, SlaveLink};
    use crate::zlink::{ZenohEmulator, ZenohMaster, ZenohOptions, ZenohSlave};

    /// The options, with a warning when the run is open to anyone on the path.
    fn options_warned(a: &NodeArgs) -> ZenohOptions {
        if a.tls_ca.is_none() && !loopback_only(a) {
            tracing::warn!(
                "Zenoh in clear across hosts: any peer that reaches {:?} can read this run and inject samples into it; on a network you do not trust give --tls-ca, --tls-cert and --tls-key (docs/03-across-hosts.md)",
                a.listen.iter().chain(&a.connect).collect::<Vec<_>>()
            );
        }
        super::zenoh_options(a)
    }

    pub fn master(
        a: &NodeArgs,
        direct: bool,
        wait: WaitPolicy,
    ) -> Result<Box<dyn MasterLink>, NodeError> {
        let o = options_warned(a);
        Ok(Box::new(opened(ZenohMaster::open(
            &o, &a.prefix, direct, wait,
        ))?))
    }

    pub fn emulator(
        a: &NodeArgs,
        master_on_iceoryx2: bool,
        slave_on_iceoryx2: bool,
        wait: WaitPolicy,
    ) -> Result<Box<dyn EmulatorLink>, NodeError> {
        let o = options_warned(a);
        Ok(Box::new(opened(ZenohEmulator::open(
            &o,
            &a.prefix,
            master_on_iceoryx2,
            slave_on_iceoryx2,
            wait,
        ))?))
    }

    pub fn slave(a: &NodeArgs, wait: WaitPolicy) -> Result<Box<dyn SlaveLink>, NodeError> {
        let o = options_warned(a);
        Ok(Box::new(opened(ZenohSlave::open(&o, &a.prefix, wait))?))
    }
}

/// In a build without the `zenoh` feature every Zenoh link is a configuration error
/// that says how to build with it.
#[cfg(not(feature = "zenoh"))]
mod zenoh_open {
    use super::{NodeArgs, NodeError, NO_ZENOH};
    use crate::link::WaitPolicy;
    use crate::link::{EmulatorLink, MasterLink, SlaveLink};

    pub fn master(_: &NodeArgs, _: bool, _: WaitPolicy) -> Result<Box<dyn MasterLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }

    pub fn emulator(
        _: &NodeArgs,
        _: bool,
        _: bool,
        _: WaitPolicy,
    ) -> Result<Box<dyn EmulatorLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }

    pub fn slave(_: &NodeArgs, _: WaitPolicy) -> Result<Box<dyn SlaveLink>, NodeError> {
        Err(NodeError::BadInput(NO_ZENOH.into()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::testing::args;

    #[test]
    fn the_zenoh_link_is_checked_or_refused_by_the_build() {
        let a = args(&["--link", "zenoh", "--connect", "tcp/127.0.0.1:7447"]);
        let r = check_link_args(&a, &[LinkKind::Zenoh]);
        if cfg!(feature = "zenoh") {
            assert!(r.is_ok(), "{:?}", r.err());
        } else {
            let e = r.expect_err("no Zenoh in this build").to_string();
            assert!(e.contains("--workspace --features zenoh"), "{e}");
        }
    }
}
