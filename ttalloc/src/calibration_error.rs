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

use crate::InputError;
use crate::csvio::Source;
use anyhow::Result;
use clap::Parser;
use e2e_verify::EndToEnd;
use std::path::PathBuf;

/// Arguments of `calibration-error`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file: turntable, sensor, site, schedule, reading (default: the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// CSV file to read; standard input when absent or `-`.
    pub file: Option<PathBuf>,
}

/// The output header for a study's sensor ([`study::csv::calibration_error_columns`]).
#[must_use]
pub fn header(e2e: &EndToEnd) -> String {
    study::csv::calibration_error_columns(e2e.calibration().sensor())
        .into_iter()
        .map(|(c, _)| c)
        .collect::<Vec<_>>()
        .join(",")
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    let e2e = EndToEnd::new(
        &s.turntable,
        &s.calibration,
        &crate::loaded::poses(&s)?,
        s.reading,
    )
    .map_err(|e| crate::input::library(e, &s))?;
    let source = Source::from_arg(args.file.as_deref());
    let name = source.name();
    let mut work = e2e.work();
    let mut eval = |line: usize, row: study::csv::TurntableRow| -> Result<Vec<f64>, InputError> {
        let at = || format!("{name}:{line}");
        // rate steps: the row's translations act there (rate accuracy and ripple held at 0)
        let with_rows;
        let e2e = if e2e.has_rate_steps() {
            let mut extra = vec![0.0; e2e.extra_errors().len()];
            for (x, v) in e2e.extra_errors().iter().zip(extra.iter_mut()) {
                if let e2e_verify::ExtraError::Translation(i) = *x {
                    *v = row.translations_m[i];
                }
            }
            with_rows = e2e
                .with_extra_values(&extra)
                .map_err(|e| InputError::new(at(), e.to_string()))?;
            &with_rows
        } else {
            &e2e
        };
        let mut v = e2e
            .coefficient_errors(&row.chi_rad)
            .map_err(|e| InputError::new(at(), e.to_string()))?;
        e2e.delta_omega_into(&row.chi_rad, &mut work)
            .map_err(|e| InputError::new(at(), e.to_string()))?;
        // a rate error at or below the computation's precision is reported as 0
        v.extend(
            work.delta_omega
                .iter()
                .zip(e2e.precisions())
                .map(|(d, p)| e2e_verify::resolved(*d, *p)),
        );
        if v.iter().any(|x| !x.is_finite()) {
            return Err(InputError::new(
                at(),
                "the calibration gave a non-finite result",
            ));
        }
        Ok(v)
    };
    let line_of = |v: &[f64]| {
        v.iter()
            .map(|x| study::fmt::exact(*x))
            .collect::<Vec<_>>()
            .join(",")
    };
    crate::csvio::run_rows(
        &source,
        &s.turntable,
        study::csv::JointColumns::Absent,
        &header(&e2e),
        |line, row| Ok(line_of(&eval(line, row)?)),
    )
}
