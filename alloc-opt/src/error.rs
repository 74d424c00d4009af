//! The crate's error type.

use tt_kinematics::{ErrorComponent, OrientationAxis};

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
    /// The lower bounds alone already violate a requirement: no upper bounds can satisfy it.
    #[error(
        "problem {}: the lower bounds of {} alone give a worst case of \
         {worst_case_rad:e} rad > requirement {requirement_rad:e} rad",
        .problem.name(),
        names(.components)
    )]
    InfeasibleLowerBounds {
        /// The problem (orientation angle) that cannot be satisfied: (31) gamma, (32) theta,
        /// (33) psi.
        problem: OrientationAxis,
        /// The components with a positive lower bound that contribute to that worst case.
        components: Vec<ErrorComponent>,
        /// The worst case of the angle with every involved error at its lower bound (rad).
        worst_case_rad: f64,
        /// The requirement it exceeds (rad).
        requirement_rad: f64,
    },
    /// The constraint does not bound these components (their coefficients can cancel or are
    /// never positive on the pose range), so the objective has no minimiser.
    #[error("problem {problem}: the constraint does not bound {components:?}")]
    Unbounded {
        /// The problem concerned (`"gamma"`, `"theta"`, `"psi"` or a caller's label).
        problem: String,
        /// The names of the components that grow without limit.
        components: Vec<String>,
    },
    /// A pose range was empty, reversed or not finite.
    #[error("pose range for {problem:?} must satisfy lo < hi (finite), got [{lo_rad}, {hi_rad}]")]
    InvalidPoseRange {
        /// The problem concerned.
        problem: OrientationAxis,
        /// Lower end (rad).
        lo_rad: f64,
        /// Upper end (rad).
        hi_rad: f64,
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
}

/// `"dalpha_x2, deps_x"`.
fn names(components: &[ErrorComponent]) -> String {
    components
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
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
