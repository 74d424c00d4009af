//! `cargo xtask calibration-error [--study FILE] [CSV]`: the calibration error of turntables
//! given as CSV rows: the study's error columns (`<error>_arcmin`, `<error>_mm`, as in
//! `orientation-error --study` but without joint angles: the same errors act at every
//! position of the study's schedule).
//!
//! For each turntable the outputs are simulated at the actual orientation of every test
//! position and calibrated at the intended one (eq 6, the user's estimate). Output, one row
//! per turntable: `<coefficient>_error` (estimate minus true value, in the coefficient's unit:
//! output unit per regressor unit) for every estimated coefficient in study order, then
//! `<output>_rate_error` (eq 14 under the study's reading, output unit; 0 when at or below the
//! computation's precision, `e2e_verify::EndToEnd::precisions`). Full precision. As
//! for `orientation-error`, the whole input is checked before anything is written.
//!
//! With rate steps in the study the rate steps are simulated too (their revolution averages
//! through the exact chain), and a row's `<error>_mm` translations act at them (the sensor
//! off the turning axis); the table's rate accuracy and ripple are held at zero.

use crate::csvio::Source;
use anyhow::Result;
use clap::Parser;
use std::path::PathBuf;

/// Arguments of `calibration-error`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Study file: turntable, sensor, site, schedule, reading (default: the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// CSV file to read; standard input when absent or `-`.
    pub file: Option<PathBuf>,
}

/// Run the command.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    let mut rows = tt_lab::rows::calibration_rows(&s).map_err(crate::input::lab)?;
    let header = rows.columns().join(",");
    let source = Source::from_arg(args.file.as_deref());
    let name = source.name();
    crate::csvio::run_rows(
        &source,
        &s.turntable,
        study::csv::JointColumns::Absent,
        &header,
        |line, row| {
            let v = rows.row(&format!("{name}:{line}"), &row)?;
            Ok(v.iter()
                .map(|x| tt_core::human::exact(*x))
                .collect::<Vec<_>>()
                .join(","))
        },
    )
}
