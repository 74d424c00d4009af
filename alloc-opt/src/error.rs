//! The crate's error type.

use tt_kinematics::KinematicsError;

/// Why an allocation could not be made. Every variant names the offending input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AllocError {
    /// An input was rejected by a check (NaN or infinite, not positive, negative, wrong
    /// length), naming the field (`requirement.gamma`, `lower_bounds.dalpha_x2`,
    /// `weights.gamma.dalpha_x2`, `upper_bounds`).
    #[error(transparent)]
    Field(#[from] tt_core::FieldError),
    /// The lower bounds alone already violate a requirement: no upper bounds can satisfy it.
    #[error(
        "problem {problem}: the lower bounds of {} alone give a worst case of \
         {worst_case_rad:e} rad > requirement {requirement_rad:e} rad",
        .components.join(", ")
    )]
    InfeasibleLowerBounds {
        /// The problem (quantity name) that cannot be satisfied ((31) gamma, (32) theta,
        /// (33) psi for the paper's table).
        problem: String,
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
    /// A method was asked of a model it does not apply to (the paper's quarter ranges on a
    /// model that is not a turntable's [`tt_kinematics::LinearModel`]).
    #[error("the {method} method does not apply to this model: {reason}")]
    NotApplicable {
        /// The method.
        method: String,
        /// Why.
        reason: String,
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
    /// A method's own failure, for an allocator outside this crate whose errors are its own
    /// type: its message, and whether it is the caller's input (with the field) or internal
    /// ([`tt_core::ErrorClass`]).
    #[error("{method}: {message}")]
    Method {
        /// The allocator's name.
        method: String,
        /// Its error, as text.
        message: String,
        /// The input field at fault; `None` for an internal failure.
        input_field: Option<String>,
    },
    /// The kinematics library rejected an input (a pose or weight vector of the wrong length).
    #[error("kinematics: {0}")]
    Kinematics(#[from] KinematicsError),
}

pub(crate) use tt_core::{finite, length, non_negative, positive};

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

impl tt_core::ErrorClass for AllocError {
    /// Input: the fields, lower bounds that alone violate the requirement (`lower_bounds`),
    /// the paper's quarter ranges on a table they do not fit (`constraint_form`), the
    /// kinematics' input errors. Internal: an unbounded problem, the conic solver, the
    /// exchange method, a malformed subproblem, a non-finite result.
    fn input_field(&self) -> Option<&str> {
        match self {
            AllocError::Field(e) => Some(e.field()),
            AllocError::InfeasibleLowerBounds { .. } => Some("lower_bounds"),
            AllocError::QuarterRangesNeedOneFreeJoint { .. } | AllocError::NotApplicable { .. } => {
                Some("constraint_form")
            }
            AllocError::Kinematics(e) => tt_core::ErrorClass::input_field(e),
            AllocError::Method { input_field, .. } => input_field.as_deref(),
            AllocError::Unbounded { .. }
            | AllocError::Solver { .. }
            | AllocError::NoConvergence { .. }
            | AllocError::Malformed { .. }
            | AllocError::NonFiniteResult { .. } => None,
        }
    }
}
