//! The `tactile` command as a library: the binary is a thin wrapper around
//! [`cli::main`], so every subcommand can also be driven in-process. [`cmd`] holds one
//! module per subcommand, each owning its arguments, its printing and its exit status;
//! launching and sweeping runs is the `tactile-launch` crate (which the Python package
//! calls too), the report the `tactile-report` crate.
#![doc = include_str!("../../README.md")]

pub mod cli;
pub mod cmd;

/// The user guide (`docs/`), one module per chapter, so its Rust examples run as
/// doctests and the guide reads in rustdoc beside the code.
pub mod guide {
    #[doc = include_str!("../../docs/01-the-loop.md")]
    pub mod the_loop {}
    #[doc = include_str!("../../docs/02-running-by-hand.md")]
    pub mod running_by_hand {}
    #[doc = include_str!("../../docs/03-across-hosts.md")]
    pub mod across_hosts {}
    #[doc = include_str!("../../docs/04-networks-and-codecs.md")]
    pub mod networks_and_codecs {}
    #[doc = include_str!("../../docs/05-control.md")]
    pub mod control {}
    #[doc = include_str!("../../docs/06-records-and-reports.md")]
    pub mod records_and_reports {}
    #[doc = include_str!("../../docs/07-latency.md")]
    pub mod latency {}
    #[doc = include_str!("../../docs/08-kernels-and-the-paper.md")]
    pub mod kernels_and_the_paper {}
    #[doc = include_str!("../../docs/09-the-hardware.md")]
    pub mod the_hardware {}
    #[doc = include_str!("../../docs/10-recordings.md")]
    pub mod recordings {}
    #[doc = include_str!("../../docs/11-real-devices-and-ros2.md")]
    pub mod real_devices_and_ros2 {}
    #[doc = include_str!("../../docs/12-fuzzing.md")]
    pub mod fuzzing {}
    #[doc = include_str!("../../docs/13-any-arm.md")]
    pub mod any_arm {}
    #[doc = include_str!("../../docs/14-six-dof-master.md")]
    pub mod six_dof_master {}
    #[doc = include_str!("../../docs/15-python.md")]
    pub mod python {}
    #[doc = include_str!("../../docs/16-physics-world.md")]
    pub mod physics_world {}
    #[doc = include_str!("../../docs/17-lerobot.md")]
    pub mod lerobot {}
}
