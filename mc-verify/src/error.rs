//! The crate's error type.

use tt_kinematics::KinematicsError;

/// Which end of a tolerance interval $[\mathrm{LB}_i, \mathrm{UB}_i]$.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundKind {
    /// The lower bound $\mathrm{LB}_i$ (manufacturing capability).
    Lower,
    /// The upper bound $\mathrm{UB}_i$ (the allocated tolerance).
    Upper,
}

impl BoundKind {
    /// `"LB"` or `"UB"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BoundKind::Lower => "LB",
            BoundKind::Upper => "UB",
        }
    }
}

/// Errors from configuring or running a Monte Carlo verification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum McError {
    /// `samples` was zero: there is nothing to verify.
    #[error("samples must be at least 1, got 0")]
    ZeroSamples,
    /// `chunk_size` was zero.
    #[error("chunk_size must be at least 1, got 0")]
    ZeroChunkSize,
    /// The histogram needs at least one bin and at most [`crate::MAX_HISTOGRAM_BINS`].
    #[error("histogram_bins must be in 1..={max}, got {bins}")]
    HistogramBins {
        /// The requested number of bins.
        bins: usize,
        /// The largest accepted number.
        max: usize,
    },
    /// A list of bounds did not have one value per angular error of the turntable.
    #[error("{kind} needs one value per angular error of the turntable ({expected}), got {found}", kind = kind.name())]
    BoundsLength {
        /// Lower or upper bounds.
        kind: BoundKind,
        /// Number of angular errors of the turntable.
        expected: usize,
        /// Number of values given.
        found: usize,
    },
    /// A bound was NaN or infinite.
    #[error("{kind} of {component} must be finite, got {value}", kind = kind.name())]
    NonFiniteBound {
        /// Name of the angular error (from the turntable description).
        component: String,
        /// Lower or upper bound.
        kind: BoundKind,
        /// The offending value, in the caller's unit (rad or arcmin).
        value: f64,
    },
    /// A bound was negative (bounds are limits on $|\chi_i|$).
    #[error("{kind} of {component} must be >= 0 (a bound on |chi|), got {value}", kind = kind.name())]
    NegativeBound {
        /// Name of the angular error.
        component: String,
        /// Lower or upper bound.
        kind: BoundKind,
        /// The offending value, in the caller's unit (rad or arcmin).
        value: f64,
    },
    /// $\mathrm{LB}_i > \mathrm{UB}_i$.
    #[error("LB of {component} ({lb}) exceeds its UB ({ub})")]
    LowerAboveUpper {
        /// Name of the angular error.
        component: String,
        /// The lower bound, in the caller's unit.
        lb: f64,
        /// The upper bound, in the caller's unit.
        ub: f64,
    },
    /// The bounds were made for another turntable (their error names differ from the
    /// turntable's angular errors).
    #[error(
        "the bounds do not belong to this turntable: angular error {position} is `{expected}`, the bounds name `{found}`"
    )]
    BoundsForAnotherTurntable {
        /// Position in $\chi$ of the first difference.
        position: usize,
        /// The turntable's error name there (empty if the turntable has fewer errors).
        expected: String,
        /// The bounds' error name there (empty if the bounds have fewer).
        found: String,
    },
    /// A box (or $\chi$) does not have the model's error count
    /// ([`tt_kinematics::OrientationErrorModel::n_errors`]).
    #[error(
        "the error box has {found} errors, the model has {expected} ({names}): one bound per error of the model"
    )]
    ModelErrorCount {
        /// The model's error count.
        expected: usize,
        /// The box's.
        found: usize,
        /// The model's error names, comma separated.
        names: String,
    },
    /// A histogram half-range was not a positive finite angle (large enough for a finite
    /// inverse bin width).
    #[error(
        "histogram half-range for {axis} must be positive and finite (and bins / (2 H) finite), got {value} rad"
    )]
    HistogramRange {
        /// `psi`, `theta` or `gamma`.
        axis: &'static str,
        /// The offending value, rad.
        value: f64,
    },
    /// The requested SIMD level is not supported by this CPU.
    #[error("simd level {level} is not available on this CPU")]
    SimdUnavailable {
        /// The level's name.
        level: &'static str,
    },
    /// An orientation-error evaluation returned NaN or an infinity.
    #[error("the model returned a non-finite {axis} ({value}) at sample {sample}")]
    NonFiniteModelOutput {
        /// Global index of the sample (stream position, see [`crate::chunk_rng`]).
        sample: u64,
        /// `psi`, `theta` or `gamma`.
        axis: &'static str,
        /// The value returned.
        value: f64,
    },
    /// A caller-supplied orientation-error model returned an error.
    #[error("the model failed at sample {sample}: {source}")]
    Model {
        /// Global index of the sample (stream position, see [`crate::chunk_rng`]).
        sample: u64,
        /// The model's error.
        source: KinematicsError,
    },
    /// A kinematic computation on the turntable failed (for example the certified worst
    /// case of the histogram range).
    #[error("turntable: {0}")]
    Kinematics(#[from] KinematicsError),
    /// The specialised paper kernel (`baseline`) was asked to run another turntable.
    #[error("the specialised paper kernel applies only to the paper's Table 3 turntable")]
    NotThePaperTable,
}

impl tt_core::ErrorClass for McError {
    /// Input: the configuration (`samples`, `chunk_size`, `histogram_bins`,
    /// `histogram_half_range`, `simd`), the box (`lower_bounds`, `upper_bounds`, `bounds` for a
    /// box of another turntable), the kinematics' input errors, and a table the specialised
    /// kernel does not apply to (`turntable`). Internal: a model that returned a non-finite
    /// value or failed during the run.
    fn input_field(&self) -> Option<&str> {
        let bound = |kind: &BoundKind| match kind {
            BoundKind::Lower => "lower_bounds",
            BoundKind::Upper => "upper_bounds",
        };
        match self {
            McError::ZeroSamples => Some("samples"),
            McError::ZeroChunkSize => Some("chunk_size"),
            McError::HistogramBins { .. } => Some("histogram_bins"),
            McError::BoundsLength { kind, .. }
            | McError::NonFiniteBound { kind, .. }
            | McError::NegativeBound { kind, .. } => Some(bound(kind)),
            McError::LowerAboveUpper { .. } => Some("lower_bounds"),
            McError::BoundsForAnotherTurntable { .. } | McError::ModelErrorCount { .. } => {
                Some("bounds")
            }
            McError::HistogramRange { .. } => Some("histogram_half_range"),
            McError::SimdUnavailable { .. } => Some("simd"),
            McError::Kinematics(e) => tt_core::ErrorClass::input_field(e),
            McError::NotThePaperTable => Some("turntable"),
            McError::NonFiniteModelOutput { .. } | McError::Model { .. } => None,
        }
    }
}
