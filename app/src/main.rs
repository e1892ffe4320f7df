//! The `rover` binary: everything is in the library's [`rover::cli`].

fn main() -> std::process::ExitCode {
    rover::cli::main()
}
