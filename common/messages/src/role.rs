//! The three parts of a run. Every file, lock, log, service and record of a node is
//! named after its role, so the role is a type and its name is written once, here.

use std::fmt;

/// A node of the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    /// Operator, master device and HMD kernels; the loop's clock.
    Master,
    /// The network between them.
    Emulator,
    /// HSD kernels, slave device and environment.
    Slave,
}

impl Role {
    /// Every role, in the loop's order (the order of a report's node tables).
    pub const ALL: [Role; 3] = [Role::Master, Role::Emulator, Role::Slave];

    /// The name in file names, logs, records and reports.
    pub const fn name(self) -> &'static str {
        match self {
            Role::Master => "master",
            Role::Emulator => "emulator",
            Role::Slave => "slave",
        }
    }

    /// The node's program.
    pub const fn program(self) -> &'static str {
        match self {
            Role::Master => "tactile-master",
            Role::Emulator => "tactile-emulator",
            Role::Slave => "tactile-slave",
        }
    }

    /// Position in [`Role::ALL`]: an index into per-node arrays.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The role named `name`, if any.
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_indices_and_programs_agree() {
        for (i, r) in Role::ALL.into_iter().enumerate() {
            assert_eq!(r.index(), i);
            assert_eq!(Role::from_name(r.name()), Some(r));
            assert_eq!(r.program(), format!("tactile-{r}"));
        }
        assert_eq!(Role::from_name("operator"), None);
    }
}
