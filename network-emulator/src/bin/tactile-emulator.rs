//! `tactile-emulator`: the network emulator node. All logic is in the library.

fn main() -> std::process::ExitCode {
    tactile_network_emulator::node::main()
}
