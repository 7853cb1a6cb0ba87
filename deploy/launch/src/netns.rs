//! Two hosts on one machine: two Linux network namespaces joined by a veth pair, with
//! addresses from 198.18.0.0/15 (the block reserved for benchmarking). Made for a
//! bench or a test and removed when dropped, also when the run fails. Needs root (and
//! `ip` from iproute2); without it, [`Pair::new`] says why.

use std::process::Command;

/// The two namespaces; index 0 is the master's host, 1 the slave's.
#[derive(Debug)]
pub struct Pair {
    /// Namespace names.
    pub names: [String; 2],
    /// Each host's address on the veth pair.
    pub addrs: [String; 2],
}

/// Why the namespaces could not be made.
#[derive(Debug, thiserror::Error)]
pub enum NetnsError {
    /// No `ip` program.
    #[error("no `ip` command ({0}): install iproute2")]
    NoIp(#[source] std::io::Error),
    /// `ip` ran and refused (without root, for one); its stderr says why.
    #[error("ip {args}: {stderr}")]
    Ip {
        /// Its arguments.
        args: String,
        /// What it said.
        stderr: String,
    },
}

fn ip(args: &[&str]) -> Result<(), NetnsError> {
    let out = Command::new("ip")
        .args(args)
        .output()
        .map_err(NetnsError::NoIp)?;
    if out.status.success() {
        Ok(())
    } else {
        Err(NetnsError::Ip {
            args: args.join(" "),
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        })
    }
}

impl Pair {
    /// Creates the namespaces `tta<tag>` and `ttb<tag>` (tag: a few letters or digits,
    /// unique among the pairs alive at once), joined by a veth pair with addresses
    /// 198.18.7.1 and 198.18.7.2.
    pub fn new(tag: &str) -> Result<Pair, NetnsError> {
        let pair = Pair {
            names: [format!("tta{tag}"), format!("ttb{tag}")],
            addrs: ["198.18.7.1".to_string(), "198.18.7.2".to_string()],
        };
        let veth = [format!("va{tag}"), format!("vb{tag}")];
        let [na, nb] = &pair.names;
        let a = format!("{}/24", pair.addrs[0]);
        let b = format!("{}/24", pair.addrs[1]);
        ip(&["netns", "add", na])?;
        ip(&["netns", "add", nb])?;
        ip(&[
            "link", "add", &veth[0], "type", "veth", "peer", "name", &veth[1],
        ])?;
        ip(&["link", "set", &veth[0], "netns", na])?;
        ip(&["link", "set", &veth[1], "netns", nb])?;
        ip(&["-n", na, "addr", "add", &a, "dev", &veth[0]])?;
        ip(&["-n", nb, "addr", "add", &b, "dev", &veth[1]])?;
        for (n, v) in [(na, &veth[0]), (nb, &veth[1])] {
            ip(&["-n", n, "link", "set", v, "up"])?;
            ip(&["-n", n, "link", "set", "lo", "up"])?;
        }
        Ok(pair)
    }

    /// The command prefix that runs a program on host `k`.
    pub fn exec(&self, k: usize) -> Vec<String> {
        ["ip", "netns", "exec", &self.names[k]]
            .map(String::from)
            .to_vec()
    }
}

impl Drop for Pair {
    fn drop(&mut self) {
        // Deleting a namespace deletes the veth end in it, and with it the pair.
        for n in &self.names {
            let _ = ip(&["netns", "del", n]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    #[test]
    fn no_ip_command_keeps_the_systems_reason() {
        let e = NetnsError::NoIp(std::io::Error::from(std::io::ErrorKind::NotFound));
        assert!(e.to_string().ends_with(": install iproute2"), "{e}");
        assert!(e.source().is_some_and(|c| c.is::<std::io::Error>()));
    }
}
