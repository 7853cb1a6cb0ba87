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
    let leaf = webpki::EndEntityCert::try_from(&chain[0])
        .map_err(|e| format!("{cert_name} {}: not a certificate ({e})", cert.display()))?;
    leaf.verify_for_usage(
        provider.signature_verification_algorithms.all,
        &anchors,
        &chain[1..],
        UnixTime::now(),
        webpki::KeyUsage::client_auth(),
        None,
        None,
    )
    .map_err(|e| {
        format!(
            "{cert_name} {} is not valid under {ca_name} {} ({e:?}): a certificate of another CA, expired, or not for client authentication",
            cert.display(),
            ca.display()
        )
    })?;
    Ok(())
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
