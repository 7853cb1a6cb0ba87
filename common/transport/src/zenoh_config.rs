//! A node's Zenoh configuration: where its session listens and connects, scouting,
//! the transport measured for latency, mutual TLS, and the runtimes Zenoh's work runs
//! on. Kept apart from the transport itself ([`crate::zenoh_link`]), which only uses it.

use crate::LinkError;

fn err(context: &str, e: impl std::fmt::Display) -> LinkError {
    LinkError::new(context, e)
}

/// Where a node's Zenoh session listens and which peers it connects to.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ZenohOptions {
    /// Endpoints to listen on, e.g. `tcp/198.18.0.1:7447`.
    pub listen: Vec<String>,
    /// Endpoints of peers to connect to.
    pub connect: Vec<String>,
    /// Discover peers by multicast scouting too.
    pub scout: bool,
    /// Mutually authenticated TLS: the run's CA, this node's certificate and key.
    pub tls: Option<TlsFiles>,
}

/// The files of a node's TLS identity (PEM).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The run's certificate authority: a peer must present a certificate it signed.
    pub ca: std::path::PathBuf,
    /// This node's certificate.
    pub cert: std::path::PathBuf,
    /// This node's private key.
    pub key: std::path::PathBuf,
}

impl ZenohOptions {
    /// The Zenoh configuration: peer mode, these endpoints, scouting as asked.
    pub fn config(&self) -> Result<zenoh::Config, LinkError> {
        let mut c = zenoh::Config::default();
        let json = |v: &[String]| {
            let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
            format!("[{}]", quoted.join(","))
        };
        let set = |c: &mut zenoh::Config, key: &str, value: &str| {
            c.insert_json5(key, value)
                .map_err(|e| err(&format!("Zenoh setting {key} = {value}"), e))
        };
        set(&mut c, "mode", "\"peer\"")?;
        set(&mut c, "listen/endpoints", &json(&self.listen))?;
        set(&mut c, "connect/endpoints", &json(&self.connect))?;
        // Without --scout a node meets exactly the peers named: no multicast scouting,
        // and no gossip either. Gossip lets peers learn of each other through a common
        // peer and connect on their own; a connection made in the middle of a run
        // re-routes the streams, and samples in flight were measured lost (8 to 16 of
        // 2500 here) each time it happened.
        let scout = if self.scout { "true" } else { "false" };
        set(&mut c, "scouting/multicast/enabled", scout)?;
        set(&mut c, "scouting/gossip/enabled", scout)?;
        // The low-latency transport (no QoS priorities, no batching pipeline) halved
        // the round trip across two hosts here; every peer of a run must use it. Not
        // over TLS: there it lost samples (1 to 13 of 4,000 in each of 4 runs of
        // tests/hosts.rs's TLS loop across two namespaces, the emitting side counting
        // them sent), where Zenoh's default transport lost none in 4.
        if !tuning().contains(&"qos") && self.tls.is_none() {
            set(&mut c, "transport/unicast/qos/enabled", "false")?;
            set(&mut c, "transport/unicast/lowlatency", "true")?;
        }
        // Keep trying to reach a peer that is not up yet (nodes start in any order).
        set(&mut c, "connect/timeout_ms", "-1")?;
        set(&mut c, "connect/exit_on_failure", "false")?;
        if let Some(t) = &self.tls {
            t.apply(&mut c)?;
        }
        Ok(c)
    }
}

impl TlsFiles {
    /// Puts this identity into a Zenoh configuration as mutual TLS: both sides present
    /// a certificate of the CA (a listener refuses a peer without one at the
    /// handshake), the server's name is checked against the address connected to, and
    /// no other protocol is accepted, so nobody joins over plain TCP. The loop's link
    /// and the ROS 2 session (`[ros.tls]`) both take it from here.
    pub fn apply(&self, c: &mut zenoh::Config) -> Result<(), LinkError> {
        let mut set = |key: &str, value: &str| {
            c.insert_json5(key, value)
                .map_err(|e| err(&format!("Zenoh setting {key} = {value}"), e))
        };
        let path = |p: &std::path::Path| format!("{:?}", p.display().to_string());
        let tls = "transport/link/tls";
        set(&format!("{tls}/root_ca_certificate"), &path(&self.ca))?;
        for side in ["listen", "connect"] {
            set(&format!("{tls}/{side}_certificate"), &path(&self.cert))?;
            set(&format!("{tls}/{side}_private_key"), &path(&self.key))?;
        }
        set(&format!("{tls}/enable_mtls"), "true")?;
        set(&format!("{tls}/verify_name_on_connect"), "true")?;
        set("transport/link/protocols", "[\"tls\"]")
    }
}

/// Settings to measure the alternatives with, from `TACTILE_ZENOH_TUNING` (a comma
/// list of `qos` (Zenoh's default transport with QoS priorities instead of the
/// low-latency one), `batched` (express off), `data` (priority Data instead of
/// RealTime, with `qos`), `drop` (congestion control Drop instead of Block)). Unset in
/// normal use: the defaults are the measured choice (docs/03-across-hosts.md); every
/// node of a run must have the same.
pub(crate) fn tuning() -> Vec<&'static str> {
    static TUNING: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    TUNING
        .get_or_init(|| {
            let text = std::env::var("TACTILE_ZENOH_TUNING").unwrap_or_default();
            let leaked: &'static str = Box::leak(text.into_boxed_str());
            leaked.split(',').filter(|s| !s.is_empty()).collect()
        })
        .clone()
}

/// Zenoh's runtimes for a node, unless the user sets `ZENOH_RUNTIME`: the receive,
/// transmit, network and acceptor work handed over to the application runtime, one
/// worker thread. By default Zenoh runs five runtimes (two receive workers); a frame
/// that lands then wakes one of several threads, which the node's own thread waits on.
/// With one runtime thread the Zenoh loop across two namespaces measured 80.6 and
/// 83.4 us at p50 against 114.0 with the default (interleaved 5,000-sample benches;
/// docs/03-across-hosts.md).
pub const RUNTIME: &str =
    "(rx: (handover: app), tx: (handover: app), net: (handover: app), acc: (handover: app))";

/// Sets `ZENOH_RUNTIME` to [`RUNTIME`] unless the user set it. Zenoh reads it when it
/// first starts a runtime; call it while the process has one thread (the nodes do it
/// before parsing their arguments), since changing the environment races with other
/// threads reading it.
pub fn default_runtime() {
    if std::env::var_os("ZENOH_RUNTIME").is_none() {
        std::env::set_var("ZENOH_RUNTIME", RUNTIME);
    }
}
