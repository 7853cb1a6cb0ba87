//! `tactile-master`: the HMD node. All logic is in the library.

fn main() -> std::process::ExitCode {
    tactile_master::node::main()
}
