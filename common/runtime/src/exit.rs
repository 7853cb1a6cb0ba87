//! The exit statuses of every Tactile program, nodes and launcher alike: the launcher
//! reads its nodes' statuses with the same constants it exits with.

/// Exit status: the run completed.
pub const EXIT_OK: u8 = 0;
/// Exit status: a failure while running.
pub const EXIT_FAILURE: u8 = 1;
/// Exit status: bad input (arguments, scenario, prefix in use); nothing was started.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status: SIGINT or SIGTERM stopped the program; what it had was written
/// (128 + SIGINT, by convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The exit statuses, for each node's `--help`.
pub const EXIT_CODES_HELP: &str = "Exit status: 0 the run completed; 1 a failure while running; \
2 bad input (arguments, scenario, a prefix in use), nothing started; 130 stopped by SIGINT or \
SIGTERM (the record is complete).\n\nThe record (ROLE.rec) and log (ROLE.log) go to --out; \
`tactile report DIR...` joins the nodes' folders into the run's report.";
