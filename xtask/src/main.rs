//! Project commands, in the rust-analyzer xtask shape: `cargo xtask <command>`.
//!
//! One module per subcommand. Errors caused by the user's input (a malformed file, a bad
//! flag value) are [`InputError`]s and exit with code 2; anything else exits with code 1.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod allocate;
mod end_to_end;
mod input;
mod mc;
mod orientation_error;
mod plots;
mod report;
mod reproduce;
mod reproduce_mc;
mod requirement;
mod study;
mod svg;

pub use input::InputError;

/// Commands of the GyroWheel turntable error-allocation project.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", bin_name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Regenerate every table, figure and claim of the paper with a paper-versus-ours report.
    ReproducePaper(reproduce::Args),
    /// Orientation error (eq 24-26) of turntables given as CSV rows (FILE or standard input).
    OrientationError(orientation_error::Args),
    /// Orientation requirement I_psi, I_theta, I_gamma (eq 15-16) for the paper's inputs.
    Requirement(requirement::Args),
    /// Turntable error allocation (section 4.2-4.3, problems 31-34) beside Table 4.
    Allocate(allocate::Args),
    /// Monte Carlo check of an allocation (section 4.3, Figure 9): random turntables, exact chain.
    Mc(mc::Args),
    /// End to end (issue 7): does the allocated turntable deliver the calibration accuracy?
    EndToEnd(end_to_end::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::ReproducePaper(args) => reproduce::run(&args),
        Command::OrientationError(args) => orientation_error::run(&args),
        Command::Requirement(args) => requirement::run(&args),
        Command::Allocate(args) => allocate::run(&args),
        Command::Mc(args) => mc::run(&args),
        Command::EndToEnd(args) => end_to_end::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            if err.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
