//! `ttalloc`: the command line of the turntable error-allocation workspace, as a library whose
//! one entry point is [`run`] (the `ttalloc` binary and `cargo xtask` both call it).
//!
//! Install it with `cargo install --path ttalloc` and run it anywhere: user paths resolve
//! against the current directory; without `--study` the paper's study is read from the
//! workspace when run inside a clone, else the copy compiled into the binary.
//!
//! One module per subcommand. Errors caused by the user's input (a malformed file, a bad
//! flag value) are [`InputError`]s and exit with code 2 with nothing on standard output;
//! anything else exits with code 1. A closed standard output (`| head`) ends quietly.
//!
//! The report is also a library: [`Report::compute`] then [`Report::files`], testable without
//! the binary.

use clap::{CommandFactory, FromArgMatches, Subcommand};
use std::ffi::OsString;
use std::process::ExitCode;

mod allan;
mod allocate;
mod apply;
mod args;
mod calibrate;
mod calibration_error;
mod check_turntable;
mod csvio;
mod design_budget;
mod design_rates;
mod design_schedule;
mod end_to_end;
mod estimable;
mod input;
mod json;
mod loaded;
mod mc;
// the output files' safety, in the study-level library
use tt_lab::{newfile, outdir};
mod orientation_error;
mod out;
#[doc(hidden)]
pub mod paths;
mod report;
mod requirement;
mod text;
// the text modules under their old paths, for the commands and the report that still use them
use text::groups;

pub use input::InputError;

/// What the mutation fuzzer (`cargo xtask fuzz`, in the repository's `xtask` crate) drives and
/// checks, exposed for it alone: not an API for other uses, and not stable. The fuzzer lives
/// outside the user's binary; these are the input layer and the report writer it attacks, the
/// manifest format it judges the writer by, and the flag and output conventions it shares with
/// every command.
pub mod fuzzing {
    pub use crate::args::{count, seed};
    pub use crate::csvio::for_each_row_in;
    pub use crate::input::lab;
    pub use crate::out::print;
    pub use crate::outdir::{
        MANIFEST, OLD_SIGNATURE, Prepared, SIGNATURE, is_report_file, manifest_text, sha256_hex,
    };
    pub use crate::paths::workspace_root;
    pub use crate::report::default_report_dir;
}
/// The Monte Carlo command with a same-run benchmark after it, for `cargo xtask mc
/// --baselines` (the benchmark lives in xtask, not in the user's binary); not a stable API.
#[doc(hidden)]
pub mod bench {
    pub use crate::mc::{Args as McArgs, Bench, run_with as mc};
}
/// The report as a library (the `tt-report` crate), re-exported for the callers of `ttalloc::Report`.
pub use tt_report::{Report, ReportFile, ReportOptions};

/// Commands of the turntable error-allocation project (Zhao et al. 2017, generalised).
#[derive(Debug, clap::Parser)]
#[command(name = "ttalloc", version, about)]
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
    /// The report of a study (md, self-contained html, SVG figures, CSV tables, results.json).
    Report(report::Args),
    /// The report of the paper's study with the paper's printed values beside ours and its claims.
    ReproducePaper(report::PaperArgs),
    /// Design the test positions that let the cheapest turntable meet every accuracy.
    DesignSchedule(design_schedule::Args),
    /// Noise from a log: overlapping Allan deviation, white noise, bias instability (IEEE 952).
    Allan(allan::Args),
    /// Process the recording of the planned calibration: coefficients with uncertainties, residuals, verdicts, the calibration file.
    Calibrate(calibrate::Args),
    /// Correct a recording with a calibration file (the inputs the calibrated model maps to the outputs), streamed.
    Apply(apply::Args),
}

/// The command line's definition, shown as `bin_name` in help and usage lines (`ttalloc`,
/// `cargo xtask`); a caller may add subcommands of its own before [`run_with`].
#[must_use]
pub fn command(bin_name: &'static str) -> clap::Command {
    Cli::command().name(bin_name).bin_name(bin_name)
}

/// Run one command line: `args` as `std::env::args_os()` gives them (the program's name
/// first), `bin_name` as the help and usage lines show the program.
///
/// The exit code follows one rule: 0 on success (and on a closed standard output), 2 when the
/// input is wrong (an [`InputError`]: a flag, a study, a sheet, a CSV row, named in the
/// message), 1 when the program failed. Errors go to standard error, escaped.
pub fn run(args: impl IntoIterator<Item = OsString>, bin_name: &'static str) -> ExitCode {
    run_with(command(bin_name), args)
}

/// [`run`] with a given definition ([`command`] plus the caller's own subcommands, which the
/// caller handles before; reaching one here is a usage error, exit 2).
pub fn run_with(cmd: clap::Command, args: impl IntoIterator<Item = OsString>) -> ExitCode {
    let mut cmd = cmd;
    let matches = match cmd.try_get_matches_from_mut(args) {
        Ok(m) => m,
        Err(e) => e.exit(),
    };
    let cli = match Cli::from_arg_matches(&matches) {
        Ok(c) => c,
        Err(e) => e.format(&mut cmd).exit(),
    };
    let result = match cli.command {
        Command::Requirement(a) => requirement::run(&a),
        Command::Allocate(a) => allocate::run(&a),
        Command::Mc(a) => mc::run(&a),
        Command::EndToEnd(a) => end_to_end::run(&a),
        Command::Estimable(a) => estimable::run(&a),
        Command::CheckTurntable(a) => check_turntable::run(&a),
        Command::OrientationError(a) => orientation_error::run(&a),
        Command::CalibrationError(a) => calibration_error::run(&a),
        Command::Report(a) => report::run(&a),
        Command::ReproducePaper(a) => report::run_paper(&a),
        Command::DesignSchedule(a) => design_schedule::run(&a),
        Command::Allan(a) => allan::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
        Command::Apply(a) => apply::run(&a),
    };
    finish(result)
}

/// The exit code of a command's `result`, its error (if any) printed to standard error,
/// escaped: the rule of [`run`] (0 on success and on a closed standard output, 2 for an
/// [`InputError`], 1 otherwise), for the commands a caller adds to [`command`] (`cargo xtask
/// fuzz`).
pub fn finish(result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) if err.downcast_ref::<out::BrokenPipe>().is_some() => ExitCode::SUCCESS,
        Err(err) => {
            // a message may quote a file's text: never a raw control character
            eprintln!("error: {}", ::tt_core::human::terminal(&format!("{err:#}")));
            if err.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
