//! `[ros.tls]`: mutual TLS for the nodes' ROS 2 session, in the shape of the loop's
//! Zenoh link (`--tls-ca`, `--tls-cert`, `--tls-key`): the CA that signed every peer's
//! certificate, this node's certificate and its key, all PEM. With it every endpoint
//! is `tls/` and a router or peer without a certificate of that CA is refused at the
//! handshake; without it a `tls/` endpoint is refused (it would connect with no
//! identity). The files themselves (readable, PEM, the key the certificate's, the
//! certificate the CA's) are checked where TLS is built in, before anything starts
//! (`tactile_devices::rmw_node::check_tls`).

use crate::{invalid, RosConfig, ScenarioError};
use serde::{Deserialize, Serialize};

/// `[ros.tls]`: the session's TLS identity; paths relative to the scenario's folder.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RosTlsConfig {
    /// The certificate authority (PEM): a router or peer must present a certificate it
    /// signed.
    pub ca: String,
    /// This node's certificate (PEM, signed by `ca`; its SubjectAltName holds the
    /// addresses it listens on, as a peer connecting checks them).
    pub cert: String,
    /// This node's private key (PEM).
    pub key: String,
}

impl RosTlsConfig {
    /// The three paths, as written, with their fields' names.
    pub fn files(&self) -> [(&'static str, &str); 3] {
        [
            ("ros.tls.ca", &self.ca),
            ("ros.tls.cert", &self.cert),
            ("ros.tls.key", &self.key),
        ]
    }
}

/// Checks `[ros.tls]` against the endpoints: with it every endpoint is `tls/`
/// (nothing joins in clear), without it none is; and no path is empty.
pub(crate) fn validate(cfg: &RosConfig) -> Result<(), ScenarioError> {
    if let Some(t) = &cfg.tls {
        for (field, path) in t.files() {
            if path.is_empty() {
                return Err(invalid(field, "empty: give the path of a PEM file"));
            }
        }
    }
    for (list, name) in [(&cfg.connect, "connect"), (&cfg.listen, "listen")] {
        for (i, e) in list.iter().enumerate() {
            let why = match (cfg.tls.is_some(), e.starts_with("tls/")) {
                (true, false) => {
                    "with [ros.tls] every endpoint is tls/ADDRESS:PORT (nothing joins in clear)"
                }
                (false, true) => "a tls/ endpoint needs [ros.tls] (ca, cert and key)",
                _ => continue,
            };
            return Err(invalid(format!("ros.{name}[{i}]"), format!("{e:?}: {why}")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::RosConfig;

    fn ros(text: &str) -> Result<RosConfig, String> {
        let cfg: RosConfig = toml::from_str(text).map_err(|e| e.to_string())?;
        cfg.validate(1000.0).map_err(|e| e.to_string())?;
        Ok(cfg)
    }

    #[test]
    fn tls_takes_all_three_files_and_tls_endpoints_only() {
        let tls = "[tls]\nca = \"ca.pem\"\ncert = \"node.pem\"\nkey = \"node.key\"\n";
        let ok = ros(&format!("connect = [\"tls/127.0.0.1:7447\"]\n{tls}")).expect("tls");
        assert_eq!(ok.tls.map(|t| t.key), Some("node.key".into()));
        let e = ros(&format!("connect = [\"tcp/198.18.0.1:7447\"]\n{tls}")).expect_err("clear");
        assert!(
            e.contains("ros.connect[0]") && e.contains("every endpoint is tls/"),
            "{e}"
        );
        let e = ros(&format!(
            "connect = []\nlisten = [\"tcp/0.0.0.0:7447\"]\n{tls}"
        ))
        .expect_err("listens in clear");
        assert!(e.contains("ros.listen[0]"), "{e}");
        let e = ros("connect = [\"tls/127.0.0.1:7447\"]").expect_err("no identity");
        assert!(
            e.contains("ros.connect[0]") && e.contains("needs [ros.tls]"),
            "{e}"
        );
        let e =
            ros("connect = [\"tls/127.0.0.1:7447\"]\n[tls]\nca = \"ca.pem\"\ncert = \"n.pem\"\n")
                .expect_err("no key");
        assert!(e.contains("key"), "{e}");
        let e = ros(
            "connect = [\"tls/127.0.0.1:7447\"]\n[tls]\nca = \"\"\ncert = \"n\"\nkey = \"k\"\n",
        )
        .expect_err("empty");
        assert!(e.contains("ros.tls.ca"), "{e}");
        let e = ros(&tls.replace("key =", "pin = \"x\"\nkey =")).expect_err("unknown");
        assert!(e.contains("pin"), "{e}");
    }
}
