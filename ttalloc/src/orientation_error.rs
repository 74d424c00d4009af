//! `cargo xtask orientation-error [--study FILE] [--model exact|small-angle|linear|closed-form]
//! [CSV]`: the orientation error (eq 24-26) of turntables given as CSV rows.
//!
//! Input: a header naming every joint `<joint>_deg`, every angular error `<error>_arcmin` and
//! every error translation `<error>_mm` of the study's turntable (default: the paper's), in
//! any order, all required; one turntable per row. `CSV` is a file, or standard input when
//! absent or `-`. Output: `dpsi_arcmin,dtheta_arcmin,dgamma_arcmin`, one row per input row,
//! full precision. The whole input is checked before anything is written, so a bad row leaves
//! standard output empty; memory does not grow with the input (see [`crate::csvio`]).

use crate::csvio::Source;
use anyhow::Result;
use clap::{Parser, ValueEnum};
use std::path::PathBuf;
use tt_lab::rows::{Model, ORIENTATION_COLUMNS, OrientationOptions};

/// Which orientation-error model to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ModelChoice {
    /// Every error a finite rotation, in the order of the study's factors (eq 17-24).
    Exact,
    /// Runs of error rotations as small-angle matrices (the printed eq 17-19 for the paper).
    SmallAngle,
    /// The first-order model built from the description (eq 26 for the paper's table).
    Linear,
    /// The paper's printed eq 26 (the paper's table only).
    ClosedForm,
}

/// Arguments of `orientation-error`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Study file whose turntable the rows describe (default: the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// Orientation-error model.
    #[arg(long, value_enum, default_value_t = ModelChoice::Exact)]
    pub model: ModelChoice,
    /// CSV file to read; standard input when absent or `-`.
    pub file: Option<PathBuf>,
}

impl From<ModelChoice> for Model {
    fn from(m: ModelChoice) -> Self {
        match m {
            ModelChoice::Exact => Model::Exact,
            ModelChoice::SmallAngle => Model::SmallAngle,
            ModelChoice::Linear => Model::Linear,
            ModelChoice::ClosedForm => Model::ClosedForm,
        }
    }
}

/// Run the command.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    let rows =
        tt_lab::rows::orientation_rows(&s, &OrientationOptions::default().model(args.model.into()))
            .map_err(crate::input::lab)?;
    let source = Source::from_arg(args.file.as_deref());
    let name = source.name();
    crate::csvio::run_rows(
        &source,
        &s.turntable,
        study::csv::JointColumns::Required,
        ORIENTATION_COLUMNS,
        |line, row| {
            let v = rows.row(&format!("{name}:{line}"), &row)?;
            Ok(v.map(tt_core::human::exact).join(","))
        },
    )
}
