//! `cargo xtask orientation-error`: evaluate turntables given as CSV rows.
//!
//! Input columns (header required, in this order):
//! `phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,
//! dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm`.
//! Output: `dpsi_arcmin,dtheta_arcmin,dgamma_arcmin`, one row per input row, printed with
//! Rust's shortest round-trip formatting (full precision). Blank lines are skipped. The whole
//! input is checked before anything is written, so a bad row leaves standard output empty.

use crate::InputError;
use anyhow::{Context, Result};
use clap::{Parser, ValueEnum};
use std::io::{Read, Write};
use std::path::PathBuf;
use tt_kinematics::units::{arcmin_to_rad, rad_to_arcmin};
use tt_kinematics::{
    ClosedForm, ExactChain, OrientationErrorModel, Pose, SmallAngleChain, TurntableErrors,
};

/// The input header, in order.
pub const INPUT_COLUMNS: [&str; 11] = [
    "phi1_deg",
    "phi2_deg",
    "dphi_y1_arcmin",
    "dphi_z2_arcmin",
    "dalpha_x1_arcmin",
    "dalpha_z1_arcmin",
    "dalpha_x2_arcmin",
    "dalpha_y2_arcmin",
    "deps_x_arcmin",
    "deps_y_arcmin",
    "deta_mm",
];

/// The output header.
pub const OUTPUT_HEADER: &str = "dpsi_arcmin,dtheta_arcmin,dgamma_arcmin";

/// Which orientation-error model to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelChoice {
    /// Every error a finite rotation (eq 17-24, Table 3 order).
    Exact,
    /// The printed small-angle matrices of eq 17-19.
    SmallAngle,
    /// The closed form of eq 26.
    ClosedForm,
}

/// Arguments of `orientation-error`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Orientation-error model.
    #[arg(long, value_enum, default_value_t = ModelChoice::Exact)]
    pub model: ModelChoice,
    /// CSV file to read; standard input when absent.
    pub file: Option<PathBuf>,
}

/// Run the command: read, evaluate, then write everything at once.
pub fn run(args: &Args) -> Result<()> {
    let (name, text) = match &args.file {
        Some(path) => (
            path.display().to_string(),
            std::fs::read_to_string(path)
                .map_err(|e| InputError::new(path.display().to_string(), e.to_string()))?,
        ),
        None => {
            let mut s = String::new();
            std::io::stdin()
                .read_to_string(&mut s)
                .context("reading standard input")?;
            ("<stdin>".to_string(), s)
        }
    };
    let out = evaluate_csv(&name, &text, args.model)?;
    let mut stdout = std::io::stdout().lock();
    stdout.write_all(out.as_bytes())?;
    stdout.flush()?;
    Ok(())
}

/// Evaluate a whole CSV text; returns the output CSV or the first input error.
pub fn evaluate_csv(source: &str, text: &str, model: ModelChoice) -> Result<String, InputError> {
    let model: &dyn OrientationErrorModel = match model {
        ModelChoice::Exact => &ExactChain::default(),
        ModelChoice::SmallAngle => &SmallAngleChain,
        ModelChoice::ClosedForm => &ClosedForm,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (header_no, header) = lines
        .next()
        .ok_or_else(|| InputError::new(source, "empty input: expected a header line"))?;
    let found: Vec<&str> = header.split(',').map(str::trim).collect();
    if found != INPUT_COLUMNS {
        return Err(InputError::new(
            format!("{source}:{}", header_no + 1),
            format!(
                "header must be `{}`, found `{}`",
                INPUT_COLUMNS.join(","),
                header.trim()
            ),
        ));
    }
    let mut out = String::from(OUTPUT_HEADER);
    out.push('\n');
    for (i, line) in lines {
        let at = |col: usize| format!("{source}:{} column {col}", i + 1);
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != INPUT_COLUMNS.len() {
            return Err(InputError::new(
                format!("{source}:{}", i + 1),
                format!(
                    "expected {} columns, found {}",
                    INPUT_COLUMNS.len(),
                    fields.len()
                ),
            ));
        }
        let mut v = [0.0; 11];
        for (col, (field, slot)) in fields.iter().zip(v.iter_mut()).enumerate() {
            let x: f64 = field.parse().map_err(|_| {
                InputError::new(
                    at(col + 1),
                    format!("`{}`: `{field}` is not a number", INPUT_COLUMNS[col]),
                )
            })?;
            if !x.is_finite() {
                return Err(InputError::new(
                    at(col + 1),
                    format!("`{}` must be finite, found `{field}`", INPUT_COLUMNS[col]),
                ));
            }
            *slot = x;
        }
        let pose = Pose::from_deg(v[0], v[1]).map_err(|e| InputError::new(at(1), e.to_string()))?;
        let mut chi = [0.0; 8];
        chi.copy_from_slice(&v[2..10]);
        let errors = TurntableErrors::from_rad(chi.map(arcmin_to_rad), v[10] * 1e-3)
            .map_err(|e| InputError::new(format!("{source}:{}", i + 1), e.to_string()))?;
        let e = model.orientation_error(&pose, &errors);
        out.push_str(&format!(
            "{},{},{}\n",
            rad_to_arcmin(e.delta_psi_rad),
            rad_to_arcmin(e.delta_theta_rad),
            rad_to_arcmin(e.delta_gamma_rad)
        ));
    }
    Ok(out)
}
