//! The crate's error type.

use alloc_opt::AllocError;
use calib_lsq::CalibError;
use mc_verify::McError;
use tt_kinematics::KinematicsError;

/// Errors of the end-to-end check and of the direct and yield-based allocations. Every
/// user-input variant names the offending field or value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum E2eError {
    /// The calibration (schedule, sensor, site) was invalid, or a calibration failed.
    #[error(transparent)]
    Calib(#[from] CalibError),
    /// The turntable rejected an input (lengths, non-finite values).
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// The allocation core failed or its inputs were invalid.
    #[error(transparent)]
    Alloc(#[from] AllocError),
    /// A tolerance box was invalid (non-finite or negative bound, `LB > UB`); names the error
    /// and the bound.
    #[error(transparent)]
    Bounds(#[from] McError),
    /// A lower bound lies above the upper bound of a named box evaluated beside the
    /// allocations (e.g. the paper's Table 4).
    #[error(
        "{component}: the lower bound {lb} rad exceeds the upper bound {ub} rad of the box `{name}`"
    )]
    LowerAboveBox {
        /// The box (`Table 4`, ...).
        name: String,
        /// The error.
        component: String,
        /// The lower bound (rad).
        lb: f64,
        /// The box's upper bound (rad).
        ub: f64,
    },
    /// No error affects any output to first order, so the direct allocation has no bound
    /// and there is no box to certify on the exact chain.
    #[error(
        "no error affects any output to first order: no bound is needed for any error, and there is no box to certify"
    )]
    NoBoxToCertify,
    /// An input was rejected by a check (NaN or infinite, not positive, a count or a value
    /// out of its range), naming the field (`chi.dalpha_x2`, `upper_bounds.dphi_z2`,
    /// `samples`, `yield_fraction`, `step_deg`).
    #[error(transparent)]
    Field(#[from] tt_core::FieldError),
    /// An uncertainty budget's input was rejected (a tolerance, a coverage probability).
    #[error(transparent)]
    Metrology(#[from] metrology::MetrologyError),
    /// The derived second-order bound of an output is at least its accuracy: the direct
    /// allocation cannot be certified on the exact chain for this turntable and sensor.
    #[error(
        "accuracy of output {output} minus its second-order margin must be positive, got {value}"
    )]
    MarginExceedsAccuracy {
        /// The output.
        output: String,
        /// Its accuracy minus its margin (output unit), not positive.
        value: f64,
    },
    /// A specification's noise part alone (its coverage factor times the noise's standard
    /// uncertainty at the study's dwell) reaches its limit: no turntable, however good, lets
    /// the calibration meet it (figures in the specification's unit).
    #[error(
        "no table suffices for {spec}: noise alone is {noise:.6} {unit} >= the limit {limit} {unit}"
    )]
    NoTableSuffices {
        /// The specification's label (`gx bg_x (bias)`).
        spec: String,
        /// Its noise part (its unit).
        noise: f64,
        /// Its limit (its unit).
        limit: f64,
        /// Its unit, as written.
        unit: String,
    },
    /// The reading has no derived second-order bound, so the allocation cannot be certified
    /// on the exact chain.
    #[error(
        "reading `{reading}` has no derived second-order bound: certification needs the user's estimate beta1 with the printed or nominal-rate form, or outputs at the intended orientation"
    )]
    NoSecondOrderBound {
        /// The reading.
        reading: String,
    },
    /// The lower bounds alone violate an output's accuracy on some row (the linearised worst
    /// case of the box $[\mathrm{LB}, \mathrm{LB}]$ exceeds $\omega_m$).
    #[error(
        "the lower bounds alone give a worst-case error of {worst} on output `{output}` at position {position}, above its accuracy {accuracy}"
    )]
    InfeasibleLowerBounds {
        /// The output.
        output: String,
        /// Index of the calibration position in the schedule.
        position: usize,
        /// The lower bounds' worst case (output unit).
        worst: f64,
        /// The accuracy (output unit).
        accuracy: f64,
    },
    /// A simulated calibration of a drawn turntable failed (never silently dropped).
    #[error("turntable {sample} of the Monte Carlo: {reason}")]
    Draw {
        /// Global index of the draw.
        sample: u64,
        /// Why.
        reason: String,
    },
    /// Too few Monte Carlo draws to resolve a yield target: even with every draw meeting the
    /// accuracies, the 95% Wilson interval of the yield would reach below the target
    /// ([`crate::min_yield_samples`]).
    #[error(
        "{samples} turntables cannot resolve a yield target of {target}: even with none failing, the 95% interval of the yield reaches below it; at least {needed} are needed"
    )]
    TooFewSamples {
        /// The draws asked for.
        samples: u64,
        /// The smallest count that can demonstrate the target.
        needed: u64,
        /// The yield target.
        target: f64,
    },
    /// No scale of the allocation shape reaches the requested yield (with positive lower
    /// bounds even the smallest admissible box fails).
    #[error(
        "no scale of the shape reaches a yield of {target}: the smallest admissible box yields {best}"
    )]
    YieldUnreachable {
        /// The requested fraction.
        target: f64,
        /// The best yield found.
        best: f64,
    },
    /// A claim or report needed a part of an answer that it does not hold (a named box, a
    /// reading).
    #[error("the end-to-end answer has no {what}")]
    MissingInAnswer {
        /// What was looked for, e.g. `box "Table 4" under reading intended/beta1/printed`.
        what: String,
    },
    /// The candidate grid of a schedule design would exceed its limit (counted before it is
    /// built).
    #[error(
        "the grid gives {} candidate positions ({} per joint), more than {max}: use a larger step",
        count_text(per_joint_log10.iter().sum()),
        per_joint_log10.iter().map(|c| count_text(*c)).collect::<Vec<_>>().join(" x ")
    )]
    GridTooLarge {
        /// The grid step (deg).
        step_deg: f64,
        /// $\log_{10}$ of the number of grid angles of each joint (a count may exceed any
        /// float).
        per_joint_log10: Vec<f64>,
        /// The limit.
        max: usize,
    },
    /// A schedule design was asked to choose from no candidate position.
    #[error("no candidate position to design a schedule from")]
    EmptyCandidates,
    /// A candidate position lies outside its joint's range.
    #[error("candidate {candidate}: {joint} = {angle_deg} deg is outside the joint's range")]
    CandidateOutsideRange {
        /// Index of the candidate.
        candidate: usize,
        /// The joint.
        joint: String,
        /// The angle (deg).
        angle_deg: f64,
    },
    /// No schedule drawn from the candidates identifies an output: the regressors of every
    /// candidate together leave these coefficients in the null space.
    #[error("no schedule drawn from the {candidates} candidate positions identifies output `{output}`: coefficient(s) {} cannot be separated", coefficients.join(", "))]
    UnidentifiableCandidates {
        /// The output.
        output: String,
        /// The coefficients no candidate set identifies.
        coefficients: Vec<String>,
        /// Number of candidates.
        candidates: usize,
    },
    /// Fewer positions than an output has coefficients to estimate.
    #[error(
        "{positions} positions cannot identify output `{output}`, which has {coefficients} coefficients to estimate"
    )]
    TooFewPositions {
        /// The requested number of positions.
        positions: usize,
        /// The output with the most coefficients.
        output: String,
        /// Its number of estimated coefficients.
        coefficients: usize,
    },
    /// More positions than candidates (a schedule uses each candidate at most once).
    #[error("{positions} positions requested but only {candidates} candidate positions exist")]
    TooManyPositions {
        /// The requested number of positions.
        positions: usize,
        /// Number of candidates.
        candidates: usize,
    },
    /// A schedule used the same candidate twice.
    #[error("candidate {candidate} appears twice in the schedule")]
    RepeatedCandidate {
        /// Index of the candidate.
        candidate: usize,
    },
    /// No schedule the search met identifies every output with a condition number within the
    /// bound.
    #[error("{}", unreachable_text(*max_condition, *best_condition))]
    ConditionUnreachable {
        /// The bound.
        max_condition: f64,
        /// The smallest largest condition number met.
        best_condition: f64,
    },
    /// A total test-time budget shorter than the fewest positions the sensor can be
    /// calibrated with need (each a move and one sample).
    #[error(
        "time_budget_s = {budget_s} s is too short: the fewest positions that identify every output ({positions}, for output `{output}`) take {needed_s} s at one sample each (positions x (move_s + 1/sample_rate_hz))"
    )]
    BudgetTooShort {
        /// The budget (s).
        budget_s: f64,
        /// The fewest positions that can identify every output.
        positions: usize,
        /// The output with the most coefficients.
        output: String,
        /// The shortest test of that many positions (s).
        needed_s: f64,
    },
    /// An iteration did not settle within its bound.
    #[error("{what} did not converge in {iterations} steps (last change {change})")]
    NoConvergence {
        /// What iterated.
        what: &'static str,
        /// Steps made.
        iterations: usize,
        /// The last relative change or violation.
        change: f64,
    },
    /// A magnitude bound of a tolerance sheet names an error the turntable does not have, or
    /// an error twice ([`crate::sheet::ToleranceSheet::new`]).
    #[error("{key}: {reason}")]
    SheetDisc {
        /// The sheet's key of the magnitude (`axes.phi2.wobble_arcsec`).
        key: String,
        /// What is wrong, in words.
        reason: String,
    },
    /// A measured error's coefficients do not fit its model (or it varies as `any`, which a
    /// measurement cannot give).
    #[error(
        "{key}: `{error}` has {coefficients} measured coefficient(s), its model needs {}",
        expected.map_or_else(|| "a constant or harmonics (it varies as `any`)".to_string(), |n| n.to_string())
    )]
    MeasuredModel {
        /// The measurement's key.
        key: String,
        /// The error measured.
        error: String,
        /// Coefficients given.
        coefficients: usize,
        /// Coefficients its model has (`None`: an `any` error, which cannot be measured).
        expected: Option<usize>,
    },
    /// A measured error reaches, somewhere on the revolution, a magnitude above the sheet's
    /// bound: the measured table is outside the sheet, which a check of the sheet assumes.
    #[error(
        "{key}: the measured `{error}` reaches {reached_rad} rad, above the sheet's bound {bound_rad} rad: the measured table is outside its specification"
    )]
    MeasuredOutsideSheet {
        /// The measurement's key.
        key: String,
        /// The error measured.
        error: String,
        /// The magnitude it reaches (rad).
        reached_rad: f64,
        /// The sheet's bound (rad).
        bound_rad: f64,
    },
}

/// The message of [`E2eError::ConditionUnreachable`].
fn unreachable_text(max_condition: f64, best_condition: f64) -> String {
    let head = format!("no schedule found whose condition numbers are all at most {max_condition}");
    if best_condition.is_finite() {
        // rounded up, so that the value quoted is reachable
        let up = (best_condition * 1e4).ceil() / 1e4;
        format!("{head}: the smallest the search reached is {up} (ask for at least that)")
    } else {
        format!("{head}: no schedule the search met identifies every output")
    }
}

/// A count given by its $\log_{10}$, for messages: the whole number below $10^{15}$, else
/// `about 1.3e621` (the count may exceed any float).
fn count_text(log10: f64) -> String {
    if log10 < 15.0 {
        return format!("{}", 10f64.powf(log10).round());
    }
    let e = log10.floor();
    format!("about {:.1}e{e}", 10f64.powf(log10 - e))
}

pub(crate) use tt_core::{finite, positive};

/// `value` if it lies strictly between 0 and 1.
pub(crate) fn fraction(field: &str, value: f64) -> Result<f64, E2eError> {
    use std::ops::Bound::Excluded;
    Ok(tt_core::in_range(
        field,
        value,
        Excluded(0.0),
        Excluded(1.0),
        "",
    )?)
}

impl tt_core::ErrorClass for E2eError {
    /// Input: the fields, the parts of the calibration, turntable, allocation and box that
    /// are the caller's input, a tolerance sheet's entries (the key named), lower bounds
    /// above a box or infeasible, a reading without a
    /// second-order bound (`reading`), too few draws for a yield target (`samples`), a yield
    /// no scale reaches (`lower_bounds`), the schedule design's settings and candidates.
    /// Internal: a margin at least the accuracy, a failed draw, a missing part of an answer,
    /// no box to certify, an iteration that did not converge, and the inner crates' internal
    /// errors.
    fn input_field(&self) -> Option<&str> {
        match self {
            E2eError::Calib(e) => e.input_field(),
            E2eError::Kinematics(e) => e.input_field(),
            E2eError::Alloc(e) => e.input_field(),
            E2eError::Bounds(e) => e.input_field(),
            E2eError::Field(e) => Some(e.field()),
            E2eError::Metrology(e) => e.input_field(),
            E2eError::LowerAboveBox { .. }
            | E2eError::InfeasibleLowerBounds { .. }
            | E2eError::YieldUnreachable { .. } => Some("lower_bounds"),
            E2eError::NoSecondOrderBound { .. } => Some("reading"),
            E2eError::TooFewSamples { .. } => Some("samples"),
            E2eError::GridTooLarge { .. } => Some("step_deg"),
            E2eError::EmptyCandidates
            | E2eError::CandidateOutsideRange { .. }
            | E2eError::RepeatedCandidate { .. } => Some("candidates"),
            E2eError::UnidentifiableCandidates { .. } => Some("candidate_positions"),
            E2eError::TooFewPositions { .. } | E2eError::TooManyPositions { .. } => {
                Some("positions")
            }
            E2eError::ConditionUnreachable { .. } => Some("max_condition"),
            E2eError::BudgetTooShort { .. } => Some("time_budget_s"),
            E2eError::SheetDisc { key, .. }
            | E2eError::MeasuredModel { key, .. }
            | E2eError::MeasuredOutsideSheet { key, .. } => Some(key),
            E2eError::MarginExceedsAccuracy { .. }
            | E2eError::NoTableSuffices { .. }
            | E2eError::NoBoxToCertify
            | E2eError::Draw { .. }
            | E2eError::MissingInAnswer { .. }
            | E2eError::NoConvergence { .. } => None,
        }
    }
}
