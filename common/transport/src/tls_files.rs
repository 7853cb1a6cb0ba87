//! A node's own TLS identity, checked before its session opens: the certificate and
//! the key parse, the key is the certificate's, and the run's CA signed it.
//!
//! Zenoh reads these files only when a link is made, and a listener whose certificate
//! is garbled, or a connecting node whose key does not match its certificate, waited
//! for ever with nothing in the log: so each file is named here, as bad input (exit 2),
//! before anything starts.

use rustls::pki_types::pem::PemObject;
use rustls::pki_types::{CertificateDer, PrivateKeyDer, UnixTime};
use std::path::Path;

/// Checks `ca`, `cert` and `key` (PEM) as a node's mutual-TLS identity given by
/// `--tls-ca`, `--tls-cert` and `--tls-key`; the error names the file and what is
/// wrong with it.
pub fn check(ca: &Path, cert: &Path, key: &Path) -> Result<(), String> {
    check_as(ca, cert, key, ["--tls-ca", "--tls-cert", "--tls-key"])
}

/// [`check`], the files named in errors as `names` (the CA's, the certificate's, the
/// key's: options or a scenario's fields); each file first readable, a regular file
/// of at most 1 MiB.
pub fn check_as(ca: &Path, cert: &Path, key: &Path, names: [&str; 3]) -> Result<(), String> {
    let [ca_name, cert_name, key_name] = names;
    for (f, what) in [(ca, ca_name), (cert, cert_name), (key, key_name)] {
        crate::pem_file::readable(f, what)?;
    }
    let cas = certificates(ca, ca_name)?;
    let chain = certificates(cert, cert_name)?;
    let private = PrivateKeyDer::from_pem_file(key).map_err(|e| {
        format!(
            "{key_name} {}: no private key in it ({e}): give the PEM key of {cert_name}",
            key.display()
        )
    })?;
    // Parsed before the key is matched against it: a v1 certificate fails both,
    // and was reported as a key of another pair.
    let leaf =
        webpki::EndEntityCert::try_from(&chain[0]).map_err(|e| not_usable(cert_name, cert, &e))?;
    let provider = rustls::crypto::ring::default_provider();
    let signer = provider
        .key_provider
        .load_private_key(private)
        .map_err(|e| {
            format!(
                "{key_name} {}: not a key TLS can sign with ({e})",
                key.display()
            )
        })?;
    rustls::sign::CertifiedKey::new(chain.clone(), signer)
        .keys_match()
        .map_err(|e| {
            format!(
                "{key_name} {} is not the key of {cert_name} {} ({e}): give the pair made together",
                key.display(),
                cert.display()
            )
        })?;
    let anchors: Vec<_> = cas
        .iter()
        .map(|c| webpki::anchor_from_trusted_cert(c).map(|a| a.to_owned()))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{ca_name} {}: not a CA certificate ({e})", ca.display()))?;
    leaf.verify_for_usage(
        provider.signature_verification_algorithms.all,
        &anchors,
        &chain[1..],
        UnixTime::now(),
        webpki::KeyUsage::client_auth(),
        None,
        None,
    )
    .map_err(|e| match e {
        webpki::Error::UnsupportedCertVersion => format!(
            "{cert_name} {}: a certificate of its chain is X.509 v1, {V1}",
            cert.display()
        ),
        e => format!(
            "{cert_name} {} is not valid under {ca_name} {} ({e:?}): a certificate of another CA, expired, or not for client authentication",
            cert.display(),
            ca.display()
        ),
    })?;
    Ok(())
}

/// What to do about an X.509 v1 certificate.
const V1: &str = "which TLS does not accept (only a CA's may be v1): make a v3 certificate, with its extensions (openssl x509 -req ... -extfile, as docs/03-across-hosts.md shows)";

/// Why `cert` cannot be a node's certificate.
fn not_usable(name: &str, cert: &Path, e: &webpki::Error) -> String {
    match e {
        webpki::Error::UnsupportedCertVersion => {
            format!("{name} {}: an X.509 v1 certificate, {V1}", cert.display())
        }
        e => format!("{name} {}: not a certificate ({e})", cert.display()),
    }
}

/// The certificates of a PEM file: at least one, each parsed.
fn certificates(path: &Path, what: &str) -> Result<Vec<CertificateDer<'static>>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("{what} {}: {e}", path.display());
    let certs: Vec<CertificateDer<'static>> = CertificateDer::pem_file_iter(path)
        .map_err(|e| bad(&e))?
        .collect::<Result<_, _>>()
        .map_err(|e| bad(&format!("not PEM certificates ({e})")))?;
    if certs.is_empty() {
        return Err(bad(&"no certificate in it"));
    }
    Ok(certs)
}

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::process::Command;

    /// Runs `openssl ARGS` in `dir`; false if it is not there to run.
    fn openssl(dir: &Path, args: &str) -> bool {
        Command::new("openssl")
            .args(args.split_whitespace())
            .current_dir(dir)
            .output()
            .is_ok_and(|o| o.status.success())
    }

    /// An X.509 v1 certificate with its own key was reported as "not the key of ...:
    /// give the pair made together"; it is said to be v1, which TLS does not take.
    #[test]
    fn a_v1_certificate_is_named_as_such() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        let key = "-newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -noenc";
        let made = openssl(d, &format!("req -x509 {key} -keyout ca.key -out ca.pem -days 2 -subj /CN=ca -addext basicConstraints=critical,CA:TRUE -addext keyUsage=critical,keyCertSign"))
            && openssl(d, &format!("req -new {key} -keyout node.key -out node.csr -subj /CN=node"))
            // No -extfile: openssl makes a v1 certificate.
            && openssl(d, "x509 -req -in node.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out node.pem -days 2");
        if !made {
            assert!(
                std::env::var("CI").is_ok_and(|v| v != "true") || std::env::var("CI").is_err(),
                "openssl is needed under CI"
            );
            println!("SKIPPED: openssl is not installed");
            return;
        }
        let e = super::check(&d.join("ca.pem"), &d.join("node.pem"), &d.join("node.key"))
            .expect_err("v1");
        assert!(
            e.starts_with("--tls-cert ") && e.contains("an X.509 v1 certificate"),
            "{e}"
        );
        assert!(!e.contains("not the key of"), "{e}");
    }
}
