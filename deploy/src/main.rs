//! The `tactile` command. All logic lives in the library so tests and other tools can
//! run it in-process; this file only maps the outcome to an exit status.

fn main() -> std::process::ExitCode {
    tactile::cli::main()
}
