//! A TLS file as the options and the identity check both take it: a regular file, small
//! enough to read whole, that this process can open. One place, so `options` (which
//! checks the TLS options) and `tls_files` (which parses them) both call it without
//! importing each other.

use std::path::Path;

/// Largest TLS file read, bytes.
pub const MAX_PEM: u64 = 1 << 20;

/// A TLS file that can be read: a regular file of at most [`MAX_PEM`] bytes; the error
/// names `what` (an option or a scenario's field) and the file.
pub fn readable(f: &Path, what: &str) -> Result<(), String> {
    let meta =
        std::fs::metadata(f).map_err(|e| format!("cannot read {what} {}: {e}", f.display()))?;
    if !meta.is_file() || meta.len() > MAX_PEM {
        return Err(format!(
            "{what} {}: not a regular file of at most {MAX_PEM} bytes",
            f.display()
        ));
    }
    std::fs::File::open(f)
        .map(|_| ())
        .map_err(|e| format!("cannot read {what} {}: {e}", f.display()))
}
