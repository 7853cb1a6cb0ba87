//! Zenoh endpoints as a scenario names them (`[ros]` `connect`, `listen`): checked
//! before anything connects, and told apart by whether they leave this host in clear.

/// What is wrong with a Zenoh endpoint.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EndpointError {
    /// No `PROTOCOL/`.
    #[error("no protocol (tcp/, udp/, tls/, quic/)")]
    NoProtocol,
    /// A protocol Zenoh does not have.
    #[error("protocol {0:?} is not tcp, udp, tls or quic")]
    Protocol(String),
    /// Port 0 to connect to.
    #[error("port 0 is outside 1..=65535 (it connects nowhere)")]
    ConnectToZero,
    /// No `:PORT`.
    #[error("no :PORT")]
    NoPort,
    /// The port is not a number.
    #[error("port {port:?} is not a number")]
    PortNotNumber {
        /// The port as written.
        port: String,
        /// Why it is no number.
        source: std::num::ParseIntError,
    },
    /// The port is out of range.
    #[error("port {0} is outside 1..=65535")]
    PortRange(u32),
    /// An IP address (IPv6 in brackets, or one that parsed without its port) that
    /// did not parse with its port.
    #[error("{0} is not an IP address with a port")]
    IpWithPort(String),
    /// Digits and dots that are no IPv4 address.
    #[error("{0} is not an IP address")]
    NotIp(String),
    /// Not a host name either.
    #[error("{0:?} is neither an IP address nor a host name")]
    NotHost(String),
}

/// Checks a Zenoh endpoint `PROTOCOL/HOST:PORT` as far as it can be without the
/// network: a known protocol, a port in 1..=65535, an IP address that parses (a dotted
/// quad like 999.1.1.1 does not) or a host name of letters, digits, `-` and `.`.
/// Anything after `#` (Zenoh's endpoint options) is left to Zenoh. Port 0 listens on
/// any free port, and connects nowhere.
pub fn check(e: &str, connect: bool) -> Result<(), EndpointError> {
    let locator = e.split('#').next().unwrap_or(e);
    let (proto, addr) = locator.split_once('/').ok_or(EndpointError::NoProtocol)?;
    if !matches!(proto, "tcp" | "udp" | "tls" | "quic") {
        return Err(EndpointError::Protocol(proto.to_string()));
    }
    if let Ok(a) = addr.parse::<std::net::SocketAddr>() {
        if connect && a.port() == 0 {
            return Err(EndpointError::ConnectToZero);
        }
        return Ok(());
    }
    let (host, port) = addr.rsplit_once(':').ok_or(EndpointError::NoPort)?;
    let port: u32 = port
        .parse()
        .map_err(|source| EndpointError::PortNotNumber {
            port: port.to_string(),
            source,
        })?;
    if !(1..=65535).contains(&port) {
        return Err(EndpointError::PortRange(port));
    }
    if host.starts_with('[') || host.parse::<std::net::IpAddr>().is_ok() {
        return Err(EndpointError::IpWithPort(host.to_string()));
    }
    if host
        .split('.')
        .all(|p| p.chars().all(|c| c.is_ascii_digit()))
    {
        return Err(EndpointError::NotIp(host.to_string()));
    }
    let name_ok = !host.is_empty()
        && host.len() <= 253
        && host.split('.').all(|l| {
            !l.is_empty()
                && l.len() <= 63
                && l.chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
                && !l.starts_with('-')
        });
    if !name_ok {
        return Err(EndpointError::NotHost(host.to_string()));
    }
    Ok(())
}

/// True if endpoint `e` reaches beyond this host without TLS: anything but `tls/` to
/// a loopback address or `localhost` (a host name may be anywhere).
pub fn in_clear_to_another_host(e: &str) -> bool {
    let locator = e.split('#').next().unwrap_or(e);
    let Some((proto, addr)) = locator.split_once('/') else {
        return false;
    };
    let local = addr
        .parse::<std::net::SocketAddr>()
        .is_ok_and(|a| a.ip().is_loopback())
        || addr.starts_with("localhost:");
    proto != "tls" && !local
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_are_checked_before_anything_connects() {
        for good in [
            "tcp/127.0.0.1:7447",
            "tls/198.18.0.1:7447",
            "udp/[::1]:7447",
            "tcp/router.lab-1.example:7447",
            "tcp/localhost:7447#iface=lo",
        ] {
            assert_eq!(check(good, true), Ok(()), "{good}");
        }
        for (bad, why) in [
            ("tcp/127.0.0.1:99999", "port 99999 is outside 1..=65535"),
            ("tcp/999.1.1.1:7447", "999.1.1.1 is not an IP address"),
            ("tcp/127.0.0.1:0", "port 0 is outside"),
            ("tcp/127.0.0.1", "no :PORT"),
            ("ws/127.0.0.1:7447", "protocol \"ws\""),
            ("127.0.0.1:7447", "no protocol"),
            ("tcp/a b:7447", "neither an IP address nor a host name"),
            ("tcp/host:port", "port \"port\" is not a number"),
        ] {
            let e = check(bad, true).expect_err(bad).to_string();
            assert!(e.contains(why), "{bad}: {e}");
        }
        assert_eq!(check("tcp/0.0.0.0:0", false), Ok(()), "listen on any port");
        let cfg = crate::RosConfig {
            connect: vec!["tcp/127.0.0.1:99999".into()],
            ..crate::RosConfig::default()
        };
        let e = cfg.validate(1000.0).expect_err("bad port").to_string();
        assert!(e.contains("ros.connect[0]") && e.contains("99999"), "{e}");
    }

    #[test]
    fn a_port_that_is_no_number_keeps_the_parsers_reason() {
        use std::error::Error as _;
        let e = check("tcp/host:port", true).expect_err("no number");
        let cause = e.source().expect("the integer's reason");
        assert!(cause.is::<std::num::ParseIntError>(), "{cause:?}");
    }
}
