//! The crate's error type.

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
    /// A bound was NaN or infinite.
    #[error("{kind} of {component} must be finite, got {value} rad", kind = kind.name())]
    NonFiniteBound {
        /// Error component name (`dphi_y1`, ..., `deps_y`).
        component: &'static str,
        /// Lower or upper bound.
        kind: BoundKind,
        /// The offending value, rad.
        value: f64,
    },
    /// A bound was negative (bounds are limits on $|\chi_i|$).
    #[error("{kind} of {component} must be >= 0 (a bound on |chi|), got {value} rad", kind = kind.name())]
    NegativeBound {
        /// Error component name.
        component: &'static str,
        /// Lower or upper bound.
        kind: BoundKind,
        /// The offending value, rad.
        value: f64,
    },
    /// $\mathrm{LB}_i > \mathrm{UB}_i$.
    #[error("LB of {component} ({lb_rad} rad) exceeds its UB ({ub_rad} rad)")]
    LowerAboveUpper {
        /// Error component name.
        component: &'static str,
        /// The lower bound, rad.
        lb_rad: f64,
        /// The upper bound, rad.
        ub_rad: f64,
    },
    /// A requirement $I_k$ was not a positive finite angle.
    #[error("requirement for {axis} must be positive and finite, got {value} rad")]
    Requirement {
        /// `psi`, `theta` or `gamma`.
        axis: &'static str,
        /// The offending value, rad.
        value: f64,
    },
    /// A histogram half-range was not a positive finite angle.
    #[error("histogram half-range for {axis} must be positive and finite, got {value} rad")]
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
    /// A caller-supplied orientation-error model returned NaN or an infinity.
    #[error("the model returned a non-finite {axis} ({value}) at sample {sample}")]
    NonFiniteModelOutput {
        /// Global index of the sample (stream position, see [`crate::chunk_rng`]).
        sample: u64,
        /// `psi`, `theta` or `gamma`.
        axis: &'static str,
        /// The value returned.
        value: f64,
    },
}
