//! A throwaway public-key infrastructure for runs across hosts over mutual TLS: a
//! certificate authority and one node certificate for the hosts' addresses, made with
//! the `openssl` program (EC P-256, X.509 v3, for server and client use, as rustls
//! requires). The bench's TLS loop and the tests use it; docs/03-across-hosts.md shows
//! the same commands for a real deployment.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Why the certificates could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PkiError {
    /// `openssl` could not be run (not installed).
    #[error("running openssl: {0}")]
    Start(#[source] std::io::Error),
    /// `openssl` ran and refused; its stderr says why.
    #[error("openssl {command}: {stderr}")]
    Openssl {
        /// Its subcommand (`req`, `x509`).
        command: String,
        /// What it said.
        stderr: String,
    },
    /// The folder or a file in it could not be written.
    #[error("{doing} {}: {source}", path.display())]
    Io {
        /// `creating`, `writing`.
        doing: &'static str,
        /// The folder or file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
}

/// Runs `openssl ARGS` in `dir`; its stderr is the error.
fn openssl(dir: &Path, args: &[&str]) -> Result<(), PkiError> {
    let o = Command::new("openssl")
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(PkiError::Start)?;
    if o.status.success() {
        Ok(())
    } else {
        Err(PkiError::Openssl {
            command: args.first().unwrap_or(&"").to_string(),
            stderr: String::from_utf8_lossy(&o.stderr).trim().to_string(),
        })
    }
}

/// A new P-256 key, unencrypted.
const EC_KEY: [&str; 5] = [
    "-newkey",
    "ec",
    "-pkeyopt",
    "ec_paramgen_curve:prime256v1",
    "-noenc",
];

/// `ca.pem` and `ca.key`: a CA that signs certificates and nothing else.
fn make_ca(dir: &Path, name: &str) -> Result<(), PkiError> {
    let cn = format!("/CN={name}-ca");
    let mut ca = vec!["req", "-x509"];
    ca.extend(EC_KEY);
    ca.extend([
        "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", &cn,
    ]);
    ca.extend(["-addext", "basicConstraints=critical,CA:TRUE"]);
    ca.extend(["-addext", "keyUsage=critical,keyCertSign,cRLSign"]);
    openssl(dir, &ca)
}

/// `node.pem` and `node.key`: one certificate for server and client use, signed by
/// the CA, its SubjectAltName holding every address in `ips`.
fn make_node(dir: &Path, ips: &[String]) -> Result<(), PkiError> {
    let sans: Vec<String> = ips.iter().map(|ip| format!("IP:{ip}")).collect();
    let ext = format!(
        "basicConstraints=critical,CA:FALSE\nkeyUsage=critical,digitalSignature\n\
         extendedKeyUsage=serverAuth,clientAuth\nsubjectAltName={}\n",
        sans.join(",")
    );
    std::fs::write(dir.join("node.ext"), ext).map_err(|source| PkiError::Io {
        doing: "writing",
        path: "node.ext".into(),
        source,
    })?;
    let mut req = vec!["req", "-new"];
    req.extend(EC_KEY);
    req.extend([
        "-keyout", "node.key", "-out", "node.csr", "-subj", "/CN=node",
    ]);
    openssl(dir, &req)?;
    let sign = "x509 -req -in node.csr -CA ca.pem -CAkey ca.key -CAcreateserial \
                -out node.pem -days 2 -sha256 -extfile node.ext";
    openssl(dir, &sign.split_whitespace().collect::<Vec<_>>())
}

/// Makes `ca.pem`, `node.pem` and `node.key` in `dir` (certificates valid two days,
/// the node's SubjectAltName holding every address in `ips`); returns their paths in
/// that order.
pub fn make(dir: &Path, name: &str, ips: &[String]) -> Result<[PathBuf; 3], PkiError> {
    std::fs::create_dir_all(dir).map_err(|source| PkiError::Io {
        doing: "creating",
        path: dir.to_path_buf(),
        source,
    })?;
    make_ca(dir, name)?;
    make_node(dir, ips)?;
    Ok(["ca.pem", "node.pem", "node.key"].map(|f| dir.join(f)))
}

/// The node options for the identity `files` (`--tls-ca CA --tls-cert CERT --tls-key KEY`).
pub fn args(files: &[PathBuf; 3]) -> Vec<String> {
    let mut v = Vec::new();
    for (opt, f) in ["--tls-ca", "--tls-cert", "--tls-key"].iter().zip(files) {
        v.push(opt.to_string());
        v.push(f.display().to_string());
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A folder that cannot be made names it and keeps the system's reason.
    #[test]
    fn a_folder_that_cannot_be_made_keeps_its_cause() {
        let dir = tempfile::tempdir().expect("tmp");
        let file = dir.path().join("a-file");
        std::fs::write(&file, "").expect("write");
        let e = make(&file.join("pki"), "t", &[]).expect_err("under a file");
        assert!(e.to_string().starts_with("creating "), "{e}");
        assert!(e.source().is_some_and(|c| c.is::<std::io::Error>()));
    }
}
