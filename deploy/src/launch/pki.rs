//! A throwaway public-key infrastructure for runs across hosts over mutual TLS: a
//! certificate authority and one node certificate for the hosts' addresses, made with
//! the `openssl` program (EC P-256, X.509 v3, for server and client use, as rustls
//! requires). The bench's TLS loop and the tests use it; docs/03-across-hosts.md shows
//! the same commands for a real deployment.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `openssl ARGS` in `dir`; its stderr is the error.
fn openssl(dir: &Path, args: &[&str]) -> Result<(), String> {
    let o = Command::new("openssl")
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| format!("running openssl: {e}"))?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!(
            "openssl {}: {}",
            args.first().unwrap_or(&""),
            String::from_utf8_lossy(&o.stderr).trim()
        ))
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
fn make_ca(dir: &Path, name: &str) -> Result<(), String> {
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
fn make_node(dir: &Path, ips: &[String]) -> Result<(), String> {
    let sans: Vec<String> = ips.iter().map(|ip| format!("IP:{ip}")).collect();
    let ext = format!(
        "basicConstraints=critical,CA:FALSE\nkeyUsage=critical,digitalSignature\n\
         extendedKeyUsage=serverAuth,clientAuth\nsubjectAltName={}\n",
        sans.join(",")
    );
    std::fs::write(dir.join("node.ext"), ext).map_err(|e| format!("writing node.ext: {e}"))?;
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
pub fn make(dir: &Path, name: &str, ips: &[String]) -> Result<[PathBuf; 3], String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
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
