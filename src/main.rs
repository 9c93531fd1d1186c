//! The dustdem executable: everything is in the library's `cli` module.

fn main() -> std::process::ExitCode {
    dustdem::cli::main()
}
