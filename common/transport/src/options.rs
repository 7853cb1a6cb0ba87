//! Which transport carries each stream, and the options a node takes for them: every
//! option checked before anything starts, so a bad one is bad input (exit 2), never a
//! failure in the middle of a run.

use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;

/// What carries the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LinkKind {
    /// iceoryx2 zero-copy shared memory (one host).
    Iceoryx2,
    /// UDP datagrams (the reference most stacks use).
    // No option is named in these comments: clap prints them as the values' help in
    // `tactile run`, which has none of the nodes' --udp-hosts, --listen, --connect.
    Udp,
    /// Zenoh (a build with the zenoh feature), on one host or across hosts.
    Zenoh,
}

impl LinkKind {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LinkKind::Iceoryx2 => "iceoryx2",
            LinkKind::Udp => "udp",
            LinkKind::Zenoh => "zenoh",
        }
    }
}

/// The options of a node's links, on every node's command line.
#[derive(Debug, Clone, PartialEq, Eq, Args)]
pub struct LinkArgs {
    /// Name of the run: nodes with the same prefix find each other (iceoryx2's shared
    /// memory, Zenoh's keys, the run's locks). 1 to 24 characters from A-Z a-z 0-9 _ -.
    #[arg(long, default_value = "tactile")]
    pub prefix: String,
    /// Transport between the nodes.
    #[arg(long, value_enum, default_value_t = LinkKind::Iceoryx2)]
    pub link: LinkKind,
    /// UDP ports of master, emulator and slave, as `m,e,s` (with --link udp).
    #[arg(long, default_value = "47501,47502,47503")]
    pub udp_ports: String,
    /// Addresses of the master's, emulator's and slave's hosts, as `a,b,c` (with --link
    /// udp).
    #[arg(long, default_value = "127.0.0.1,127.0.0.1,127.0.0.1")]
    pub udp_hosts: String,
    /// Zenoh endpoint to listen on, e.g. `tcp/198.18.0.1:7447` (repeatable).
    #[arg(long)]
    pub listen: Vec<String>,
    /// Zenoh endpoint of a peer to connect to, e.g. `tcp/198.18.0.1:7447` (repeatable).
    #[arg(long)]
    pub connect: Vec<String>,
    /// Let Zenoh find peers by multicast scouting too (off: only the endpoints given).
    #[arg(long)]
    pub scout: bool,
    /// Zenoh over TLS with mutual authentication: the run's certificate authority
    /// (PEM). Every peer must present a certificate it signed, or is refused at the
    /// handshake. With --tls-cert and --tls-key; every endpoint is then `tls/...`.
    #[arg(long, requires_all = ["tls_cert", "tls_key"])]
    pub tls_ca: Option<PathBuf>,
    /// This node's certificate (PEM, signed by --tls-ca; its SubjectAltName holds the
    /// addresses peers reach it by).
    #[arg(long, requires_all = ["tls_ca", "tls_key"])]
    pub tls_cert: Option<PathBuf>,
    /// This node's private key (PEM, unencrypted).
    #[arg(long, requires_all = ["tls_ca", "tls_cert"])]
    pub tls_key: Option<PathBuf>,
}

impl Default for LinkArgs {
    /// The options of a command line that gives none (clap's defaults).
    fn default() -> Self {
        #[derive(clap::Parser)]
        struct Only {
            #[command(flatten)]
            link: LinkArgs,
        }
        <Only as clap::Parser>::parse_from(["node"]).link
    }
}

/// An option that cannot work, in words that name it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BadOption(pub String);

/// What a build without the `zenoh` feature answers to `--link zenoh`.
pub const NO_ZENOH: &str = "--link zenoh: this build has no Zenoh link; build with \
`cargo build --release --workspace --features zenoh` (docs/03-across-hosts.md)";

impl LinkArgs {
    /// The options as a command line that parses back to them.
    pub fn argv(&self) -> Vec<String> {
        let mut v = Vec::new();
        let mut put = |flag: &str, value: String| {
            v.push(flag.to_string());
            v.push(value);
        };
        put("--prefix", self.prefix.clone());
        put("--link", self.link.name().into());
        put("--udp-ports", self.udp_ports.clone());
        put("--udp-hosts", self.udp_hosts.clone());
        for e in &self.listen {
            put("--listen", e.clone());
        }
        for e in &self.connect {
            put("--connect", e.clone());
        }
        for (flag, f) in [
            ("--tls-ca", &self.tls_ca),
            ("--tls-cert", &self.tls_cert),
            ("--tls-key", &self.tls_key),
        ] {
            if let Some(f) = f {
                put(flag, f.display().to_string());
            }
        }
        if self.scout {
            v.push("--scout".into());
        }
        v
    }

    /// The UDP ports and hosts.
    pub fn udp(&self) -> Result<crate::udp::UdpPorts, BadOption> {
        let ports = crate::udp::UdpPorts::parse(&self.udp_ports).ok_or_else(|| {
            BadOption(format!(
                "--udp-ports {:?}: expected three ports m,e,s",
                self.udp_ports
            ))
        })?;
        ports.on_hosts(&self.udp_hosts).ok_or_else(|| {
            BadOption(format!(
                "--udp-hosts {:?}: expected three IP addresses a,b,c",
                self.udp_hosts
            ))
        })
    }

    /// True if every Zenoh endpoint stays on this host (loopback): plain TCP there is
    /// only as open as the host.
    pub fn loopback_only(&self) -> bool {
        !self.scout
            && self.listen.iter().chain(&self.connect).all(|e| {
                e.split_once('/')
                    .and_then(|(_, addr)| addr.parse::<std::net::SocketAddr>().ok())
                    .is_some_and(|s| s.ip().is_loopback())
            })
    }

    /// Checks the options of the transports in use, before anything starts.
    pub fn check(&self, links: &[LinkKind]) -> Result<(), BadOption> {
        if links.contains(&LinkKind::Udp) {
            self.udp()?;
        }
        if links.contains(&LinkKind::Zenoh) {
            self.check_zenoh()?;
        } else if self.tls_ca.is_some() || self.tls_cert.is_some() || self.tls_key.is_some() {
            // Asked for encryption on a link that cannot carry it: refused, never a
            // run in clear that looks encrypted.
            let names: Vec<&str> = links.iter().map(|l| l.name()).collect();
            return Err(BadOption(format!(
                "--tls-ca, --tls-cert and --tls-key encrypt the Zenoh link only; this node's link is {}: it would run in clear (use --link zenoh with tls/ endpoints)",
                names.join(" and ")
            )));
        }
        Ok(())
    }

    fn check_zenoh(&self) -> Result<(), BadOption> {
        if !cfg!(feature = "zenoh") {
            return Err(BadOption(NO_ZENOH.into()));
        }
        if self.listen.is_empty() && self.connect.is_empty() && !self.scout {
            return Err(BadOption(
                "--link zenoh: give --listen ENDPOINT and/or --connect ENDPOINT (or --scout) so the nodes can meet".into(),
            ));
        }
        for e in self.listen.iter().chain(&self.connect) {
            let ok = e.split_once('/').is_some_and(|(proto, addr)| {
                matches!(proto, "tcp" | "udp" | "tls")
                    && addr.parse::<std::net::SocketAddr>().is_ok()
            });
            if !ok {
                return Err(BadOption(format!(
                    "Zenoh endpoint {e:?}: expected tcp/ADDRESS:PORT, udp/ADDRESS:PORT or tls/ADDRESS:PORT"
                )));
            }
        }
        self.check_tls()?;
        #[cfg(feature = "zenoh")]
        self.zenoh()
            .config()
            .map_err(|e| BadOption(e.to_string()))?;
        Ok(())
    }

    /// Checks the TLS options: the three files readable, every endpoint `tls/` with
    /// them and none without.
    fn check_tls(&self) -> Result<(), BadOption> {
        let tls = self.tls_ca.is_some();
        for (what, file) in [
            ("--tls-ca", &self.tls_ca),
            ("--tls-cert", &self.tls_cert),
            ("--tls-key", &self.tls_key),
        ] {
            if let Some(f) = file {
                crate::pem_file::readable(f, what).map_err(BadOption)?;
            }
        }
        #[cfg(feature = "zenoh")]
        if let (Some(ca), Some(cert), Some(key)) = (&self.tls_ca, &self.tls_cert, &self.tls_key) {
            crate::tls_files::check(ca, cert, key).map_err(BadOption)?;
        }
        for e in self.listen.iter().chain(&self.connect) {
            let is_tls = e.starts_with("tls/");
            if tls && !is_tls {
                return Err(BadOption(format!(
                    "Zenoh endpoint {e:?}: with --tls-ca every endpoint is tls/ADDRESS:PORT (nothing joins in clear)"
                )));
            }
            if is_tls && !tls {
                return Err(BadOption(format!(
                    "Zenoh endpoint {e:?}: a tls/ endpoint needs --tls-ca, --tls-cert and --tls-key"
                )));
            }
        }
        Ok(())
    }

    /// The Zenoh endpoints, scouting and TLS identity of the options.
    #[cfg(feature = "zenoh")]
    pub fn zenoh(&self) -> crate::zenoh_link::ZenohOptions {
        let tls = match (&self.tls_ca, &self.tls_cert, &self.tls_key) {
            (Some(ca), Some(cert), Some(key)) => Some(crate::zenoh_link::TlsFiles {
                ca: ca.clone(),
                cert: cert.clone(),
                key: key.clone(),
            }),
            _ => None,
        };
        crate::zenoh_link::ZenohOptions {
            listen: self.listen.clone(),
            connect: self.connect.clone(),
            scout: self.scout,
            tls,
        }
    }

    /// The links in words, for the record and the log.
    pub fn describe(&self) -> String {
        let zenoh_used = !self.listen.is_empty() || !self.connect.is_empty();
        match self.link {
            LinkKind::Iceoryx2 if zenoh_used => format!(
                "iceoryx2 and zenoh (listen {:?}, connect {:?})",
                self.listen, self.connect
            ),
            LinkKind::Iceoryx2 => "iceoryx2".into(),
            LinkKind::Udp => format!("udp ports {} on {}", self.udp_ports, self.udp_hosts),
            LinkKind::Zenoh => format!(
                "zenoh (listen {:?}, connect {:?}{}{})",
                self.listen,
                self.connect,
                if self.scout { ", scouting" } else { "" },
                if self.tls_ca.is_some() {
                    ", mutual TLS"
                } else {
                    ""
                }
            ),
        }
    }
}

/// Link options as the tests write them.
#[cfg(test)]
pub(crate) mod testing {
    use super::LinkArgs;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        link: LinkArgs,
    }

    /// Link options from `extra`.
    pub fn args(extra: &[&str]) -> LinkArgs {
        let mut v = vec!["node"];
        v.extend_from_slice(extra);
        Cli::parse_from(v).link
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_zenoh_link_is_checked_or_refused_by_the_build() {
        let a = testing::args(&["--link", "zenoh", "--connect", "tcp/127.0.0.1:7447"]);
        let r = a.check(&[LinkKind::Zenoh]);
        if cfg!(feature = "zenoh") {
            assert!(r.is_ok(), "{:?}", r.err());
        } else {
            let e = r.expect_err("no Zenoh in this build").to_string();
            assert!(e.contains("--workspace --features zenoh"), "{e}");
        }
    }

    #[test]
    fn bad_udp_ports_and_hosts_are_named() {
        let a = testing::args(&["--udp-ports", "1,2"]);
        let e = a.check(&[LinkKind::Udp]).expect_err("two ports");
        assert!(e.0.contains("--udp-ports"), "{e}");
        let a = testing::args(&["--udp-hosts", "1.2.3.4,x,y"]);
        let e = a.check(&[LinkKind::Udp]).expect_err("bad hosts");
        assert!(e.0.contains("--udp-hosts"), "{e}");
    }

    #[test]
    fn tls_on_a_link_that_cannot_carry_it_is_refused() {
        let a = testing::args(&[
            "--tls-ca",
            "ca.pem",
            "--tls-cert",
            "n.pem",
            "--tls-key",
            "n.key",
        ]);
        for kind in [LinkKind::Udp, LinkKind::Iceoryx2] {
            let e = a.check(&[kind]).expect_err("tls in clear");
            assert!(e.0.contains("would run in clear"), "{e}");
        }
    }
}
