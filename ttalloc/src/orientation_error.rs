//! `cargo xtask orientation-error [--study FILE] [--model exact|small-angle|linear|closed-form]
//! [CSV]`: the orientation error (eq 24-26) of turntables given as CSV rows.
//!
//! Input: a header naming every joint `<joint>_deg`, every angular error `<error>_arcmin` and
//! every error translation `<error>_mm` of the study's turntable (default: the paper's), in
//! any order, all required; one turntable per row. `CSV` is a file, or standard input when
//! absent or `-`. Output: `dpsi_arcmin,dtheta_arcmin,dgamma_arcmin`, one row per input row,
//! full precision. The whole input is checked before anything is written, so a bad row leaves
//! standard output empty; memory does not grow with the input (see [`crate::csvio`]).

use crate::InputError;
use crate::csvio::Source;
use anyhow::Result;
use clap::{Parser, ValueEnum};
use std::path::PathBuf;
use tt_core::units::rad_to_arcmin;
use tt_kinematics::{
    ExactChain, LinearChain, OrientationErrorModel, Pose, SmallAngleChain, TurntableErrors,
    paper::ClosedForm,
};

/// The output header.
pub const OUTPUT_HEADER: &str = "dpsi_arcmin,dtheta_arcmin,dgamma_arcmin";

/// Which orientation-error model to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelChoice {
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
pub struct Args {
    /// Study file whose turntable the rows describe (default: the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// Orientation-error model.
    #[arg(long, value_enum, default_value_t = ModelChoice::Exact)]
    pub model: ModelChoice,
    /// CSV file to read; standard input when absent or `-`.
    pub file: Option<PathBuf>,
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    let t = &s.turntable;
    let model: Box<dyn OrientationErrorModel> = match args.model {
        ModelChoice::Exact => Box::new(ExactChain::new(t)),
        ModelChoice::SmallAngle => Box::new(SmallAngleChain::new(t)),
        ModelChoice::Linear => Box::new(LinearChain::new(t)),
        ModelChoice::ClosedForm => {
            if *t != tt_kinematics::paper::table3() {
                return Err(InputError::new("--model", "closed-form is the paper's eq 26 and applies only to the paper's table; use `linear` for any table").into());
            }
            Box::new(ClosedForm)
        }
    };
    let source = Source::from_arg(args.file.as_deref());
    let name = source.name();
    let eval = |line: usize, row: study::csv::TurntableRow| -> Result<[f64; 3], InputError> {
        let at = || format!("{name}:{line}");
        let pose = Pose::new(row.pose_rad).map_err(|e| InputError::new(at(), e.to_string()))?;
        let errors = TurntableErrors::new(row.chi_rad, row.translations_m)
            .map_err(|e| InputError::new(at(), e.to_string()))?;
        let e = model
            .orientation_error(&pose, &errors)
            .map_err(|e| InputError::new(at(), e.to_string()))?;
        let v = e.to_array().map(rad_to_arcmin);
        if v.iter().any(|x| !x.is_finite()) {
            return Err(InputError::new(
                at(),
                "the model gave a non-finite orientation error",
            ));
        }
        Ok(v)
    };
    crate::csvio::run_rows(
        &source,
        t,
        study::csv::JointColumns::Required,
        OUTPUT_HEADER,
        |line, row| {
            let v = eval(line, row)?;
            Ok(v.map(study::fmt::exact).join(","))
        },
    )
}
