//! Repository automation, in the rust-analyzer xtask shape: `cargo xtask <command>`.
//!
//! `cargo xtask test` is the README's test command (the set-up the tests need on a fresh
//! machine, then `cargo test --workspace`); `cargo xtask fuzz` is the mutation fuzzer of the
//! input layer and the report writer (`src/fuzz.rs`: automation, not in the user's binary);
//! `cargo xtask mc --baselines` adds the Monte Carlo's same-run benchmark (`src/mc_baselines.rs`);
//! `cargo xtask public-items [--unused]` counts the library crates' public items
//! (`src/public_items.rs`);
//! every other command is the `ttalloc` command line ([`ttalloc::run_with`]), run from the
//! repository (`cargo xtask reproduce-paper`).

use clap::{CommandFactory, FromArgMatches};
use std::process::ExitCode;

mod fuzz;
mod mc_baselines;
mod public_items;
mod python;
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
                eprintln!("error: {}", tt_core::human::terminal(&format!("{e:#}")));
                ExitCode::FAILURE
            }
        };
    }
    let mut cmd = ttalloc::command("cargo xtask")
        .subcommand(
            suite::Args::command().name("test").about(
                "The test suite on any machine: installs Chromium and the report fonts when missing (as root), then cargo test --workspace, then the Python package's wheel built, installed in a fresh venv and tested with pytest.",
            ),
        )
        .subcommand(fuzz::Args::command().name("fuzz").about(
            "Mutation fuzzing of the study, tolerance and CSV parsers and the report writer (no panic, no hang, located errors, nothing of the user's touched).",
        ));
    cmd = cmd.subcommand(public_items::Args::command().name("public-items").about(
        "The library crates' public items counted per crate (issue 33's rule; --root counts another tree), with --unused those no other crate, test, docs page or Python file names (a text scan: approximate).",
    ));
    if argv.get(1).is_some_and(|a| a == "public-items") {
        let matches = match cmd.try_get_matches_from_mut(&argv) {
            Ok(m) => m,
            Err(e) => e.exit(),
        };
        let sub = matches
            .subcommand_matches("public-items")
            .expect("the public-items subcommand");
        let args = match public_items::Args::from_arg_matches(sub) {
            Ok(a) => a,
            Err(e) => e.format(&mut cmd).exit(),
        };
        return match public_items::run(&args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {}", tt_core::human::terminal(&format!("{e:#}")));
                ExitCode::from(2)
            }
        };
    }
    if argv.get(1).is_some_and(|a| a == "fuzz") {
        // parsed by the whole command line, so that usage errors name `cargo xtask fuzz`
        let matches = match cmd.try_get_matches_from_mut(&argv) {
            Ok(m) => m,
            Err(e) => e.exit(),
        };
        let sub = matches
            .subcommand_matches("fuzz")
            .expect("the fuzz subcommand");
        let args = match fuzz::Args::from_arg_matches(sub) {
            Ok(a) => a,
            Err(e) => e.format(&mut cmd).exit(),
        };
        return ttalloc::finish(fuzz::run(&args));
    }
    if argv.get(1).is_some_and(|a| a == "mc") {
        return mc_baselines::run(cmd, &argv);
    }
    ttalloc::run_with(cmd, argv)
}
