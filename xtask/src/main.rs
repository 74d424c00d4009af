//! Repository automation, in the rust-analyzer xtask shape: `cargo xtask <command>`.
//!
//! `cargo xtask test` is the README's test command (the set-up the tests need on a fresh
//! machine, then `cargo test --workspace`); every other command is the `ttalloc` command line
//! ([`ttalloc::run_with`]), run from the repository (`cargo xtask reproduce-paper`).

use clap::CommandFactory;
use std::process::ExitCode;

mod suite;

fn main() -> ExitCode {
    // `test` passes its arguments on to cargo exactly as given (a `--` included)
    let argv: Vec<std::ffi::OsString> = std::env::args_os().collect();
    if argv.get(1).is_some_and(|a| a == "test")
        && !argv.get(2).is_some_and(|a| a == "-h" || a == "--help")
    {
        let args = suite::Args {
            cargo_args: argv[2..]
                .iter()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
        };
        return match suite::run(&args) {
            Ok(code) => code,
            Err(e) => {
                eprintln!("error: {}", study::fmt::terminal(&format!("{e:#}")));
                ExitCode::FAILURE
            }
        };
    }
    let cmd = ttalloc::command("cargo xtask").subcommand(
        suite::Args::command().name("test").about(
            "The test suite on any machine: installs Chromium and the report fonts when missing (as root), then cargo test --workspace.",
        ),
    );
    ttalloc::run_with(cmd, argv)
}
