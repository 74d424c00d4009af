//! Project commands, in the rust-analyzer xtask shape: `cargo xtask <command>`.
//!
//! One module per subcommand. Errors caused by the user's input (a malformed file, a bad
//! flag value) are [`InputError`]s and exit with code 2 with nothing on standard output;
//! anything else exits with code 1. A closed standard output (`| head`) ends quietly.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod allan;
mod allocate;
mod angle;
mod angle_alloc;
mod args;
mod calibration_error;
mod check_turntable;
mod csvio;
mod design_budget;
mod design_rates;
mod design_schedule;
mod end_to_end;
mod estimable;
mod fuzz;
mod groups;
mod input;
mod mc;
mod newfile;
mod noise;
mod orientation_error;
mod out;
mod outdir;
mod paths;
mod rate;
mod report;
mod requirement;
mod study;
mod suite;

pub use input::InputError;

/// Commands of the turntable error-allocation project (Zhao et al. 2017, generalised).
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", bin_name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Orientation requirement I_psi, I_theta, I_gamma (eq 15-16) for the study's sensor.
    Requirement(requirement::Args),
    /// Two-step turntable error allocation (section 4.2, problems 31-34) for the study.
    Allocate(allocate::Args),
    /// Monte Carlo check of a tolerance box on the exact chain (section 4.3, Figure 9).
    Mc(mc::Args),
    /// End to end: does the turntable deliver every output's calibration accuracy? Direct and yield-based allocation.
    EndToEnd(end_to_end::Args),
    /// Which table errors the calibration estimates itself (joint least squares with the sensor coefficients), and the allocation of the rest.
    Estimable(estimable::Args),
    /// Will a vendor's tolerances deliver the study's accuracies, and which error dominates?
    CheckTurntable(check_turntable::Args),
    /// Orientation error (eq 24-26) of turntables given as CSV rows.
    OrientationError(orientation_error::Args),
    /// Calibration error (coefficients and eq 14) of turntables given as CSV rows.
    CalibrationError(calibration_error::Args),
    /// Mutation fuzzing of the study, tolerance and CSV parsers (no panic, no hang, located errors).
    Fuzz(fuzz::Args),
    /// The report of a study (md, self-contained html, SVG figures, CSV tables, results.json).
    Report(report::Args),
    /// The report of the paper's study with the paper's printed values beside ours and its claims.
    ReproducePaper(report::PaperArgs),
    /// Design the test positions that let the cheapest turntable meet every accuracy.
    DesignSchedule(design_schedule::Args),
    /// Noise from a log: overlapping Allan deviation, white noise, bias instability (IEEE 952).
    Allan(allan::Args),
    /// The test suite on any machine: installs Chromium and the report fonts when missing (as root), then cargo test --workspace.
    Test(suite::Args),
}

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
                eprintln!("error: {}", ::study::fmt::terminal(&format!("{e:#}")));
                ExitCode::FAILURE
            }
        };
    }
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Requirement(a) => requirement::run(&a),
        Command::Allocate(a) => allocate::run(&a),
        Command::Mc(a) => mc::run(&a),
        Command::EndToEnd(a) => end_to_end::run(&a),
        Command::Estimable(a) => estimable::run(&a),
        Command::CheckTurntable(a) => check_turntable::run(&a),
        Command::OrientationError(a) => orientation_error::run(&a),
        Command::CalibrationError(a) => calibration_error::run(&a),
        Command::Fuzz(a) => fuzz::run(&a),
        Command::Report(a) => report::run(&a),
        Command::ReproducePaper(a) => report::run_paper(&a),
        Command::DesignSchedule(a) => design_schedule::run(&a),
        Command::Allan(a) => allan::run(&a),
        Command::Test(a) => match suite::run(&a) {
            Ok(code) => return code,
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) if err.downcast_ref::<out::BrokenPipe>().is_some() => ExitCode::SUCCESS,
        Err(err) => {
            // a message may quote a file's text: never a raw control character
            eprintln!("error: {}", ::study::fmt::terminal(&format!("{err:#}")));
            if err.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
