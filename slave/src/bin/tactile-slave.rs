//! `tactile-slave`: the HSD node. All logic is in the library.

fn main() -> std::process::ExitCode {
    tactile_slave::node::main()
}
