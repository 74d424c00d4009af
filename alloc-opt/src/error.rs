//! The crate's error type.

use tt_kinematics::{KinematicsError, OrientationAxis};

/// Why an allocation could not be made. Every variant names the offending input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AllocError {
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input, for example `requirement.gamma` or `lower_bounds.dalpha_x2`.
        field: String,
        /// The offending value (radians for angles).
        value: f64,
    },
    /// A named input that must be strictly positive was zero or negative.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// Which input, for example `requirement.theta` or `weights.gamma.dalpha_x2`.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A named input that must be non-negative was negative.
    #[error("{field} must not be negative, got {value}")]
    Negative {
        /// Which input, for example `lower_bounds.deps_x`.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A vector or matrix given for the turntable's errors has the wrong size.
    #[error(
        "{field}: expected {expected} values (one per rotation error of the turntable), got {found}"
    )]
    Length {
        /// Which input (`lower_bounds`, `weights`, `upper_bounds`).
        field: String,
        /// How many the turntable needs.
        expected: usize,
        /// How many were given.
        found: usize,
    },
    /// The lower bounds alone already violate a requirement: no upper bounds can satisfy it.
    #[error(
        "problem {}: the lower bounds of {} alone give a worst case of \
         {worst_case_rad:e} rad > requirement {requirement_rad:e} rad",
        .problem.name(),
        .components.join(", ")
    )]
    InfeasibleLowerBounds {
        /// The problem (orientation angle) that cannot be satisfied ((31) gamma, (32) theta,
        /// (33) psi for the paper's table).
        problem: OrientationAxis,
        /// The names of the errors with a positive lower bound that contribute to that worst
        /// case.
        components: Vec<String>,
        /// The worst case of the angle with every involved error at its lower bound (rad).
        worst_case_rad: f64,
        /// The requirement it exceeds (rad).
        requirement_rad: f64,
    },
    /// The constraint does not bound these errors (their coefficients can cancel or are
    /// never positive on the pose range), so the objective has no minimiser.
    #[error("problem {problem}: the constraint does not bound {components:?}")]
    Unbounded {
        /// The problem concerned (`"gamma"`, `"theta"`, `"psi"` or a caller's label).
        problem: String,
        /// The names of the errors that grow without limit.
        components: Vec<String>,
    },
    /// The paper's quarter ranges (problems 31-33 as printed) were asked for on a turntable
    /// that does not have exactly one free joint: they are ranges of a single angle $\phi_2$,
    /// and Lemma 1's proof (35)-(38) extends them to the full turn by the symmetries of eq 26.
    /// Use [`crate::ConstraintForm::FullRange`] (eq 30 itself) for such a table.
    #[error(
        "the paper's quarter ranges (problems 31-33) need a turntable with exactly one free \
         joint; this one has {} ({}): use the full-range form (eq 30)",
        .free_joints.len(),
        if .free_joints.is_empty() { "none".to_string() } else { .free_joints.join(", ") }
    )]
    QuarterRangesNeedOneFreeJoint {
        /// The names of the turntable's free joints.
        free_joints: Vec<String>,
    },
    /// The conic solver did not reach a solution.
    #[error("conic solver failed on problem {problem}: {status}")]
    Solver {
        /// Which problem ("gamma", "theta", "psi" or a caller's label).
        problem: String,
        /// The solver's status, as text.
        status: String,
    },
    /// The exchange (cutting-plane) method did not bring the violation below its tolerance.
    #[error(
        "problem {problem}: exchange method stopped after {iterations} iterations with \
         relative violation {violation:e}"
    )]
    NoConvergence {
        /// Which problem.
        problem: String,
        /// Iterations done.
        iterations: usize,
        /// Remaining relative violation of the semi-infinite constraint.
        violation: f64,
    },
    /// A subproblem given to the generic solver was malformed (lengths, empty cut set).
    #[error("malformed subproblem {problem}: {reason}")]
    Malformed {
        /// Which problem.
        problem: String,
        /// What is wrong.
        reason: String,
    },
    /// A computed quantity came out NaN or infinite where a finite number is required (it is
    /// never returned inside an [`crate::Allocation`]).
    #[error("{what} came out non-finite ({value})")]
    NonFiniteResult {
        /// Which quantity, for example `upper_bounds.dalpha_x2` or `certificate.gamma`.
        what: String,
        /// The value.
        value: f64,
    },
    /// The kinematics library rejected an input (a pose or weight vector of the wrong length).
    #[error("kinematics: {0}")]
    Kinematics(#[from] KinematicsError),
}

/// Check that `value` is finite.
pub(crate) fn finite(field: impl Into<String>, value: f64) -> Result<f64, AllocError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(AllocError::NonFinite {
            field: field.into(),
            value,
        })
    }
}

/// Check that `value` is finite and strictly positive.
pub(crate) fn positive(field: impl Into<String>, value: f64) -> Result<f64, AllocError> {
    let field = field.into();
    let v = finite(field.clone(), value)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(AllocError::NotPositive { field, value })
    }
}

/// Check that `value` is finite and non-negative.
pub(crate) fn non_negative(field: impl Into<String>, value: f64) -> Result<f64, AllocError> {
    let field = field.into();
    let v = finite(field.clone(), value)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(AllocError::Negative { field, value })
    }
}

/// Check that a computed quantity is finite.
pub(crate) fn finite_result(what: impl FnOnce() -> String, value: f64) -> Result<f64, AllocError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(AllocError::NonFiniteResult {
            what: what(),
            value,
        })
    }
}

/// Check a length.
pub(crate) fn length(field: &str, expected: usize, found: usize) -> Result<(), AllocError> {
    if expected == found {
        Ok(())
    } else {
        Err(AllocError::Length {
            field: field.to_string(),
            expected,
            found,
        })
    }
}
