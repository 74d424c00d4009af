//! The crate's error type.

use alloc_opt::AllocError;
use calib_lsq::CalibError;
use mc_verify::McError;

/// Errors of the end-to-end check and of the direct and yield-based allocations. Every
/// user-input variant names the offending field or value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum E2eError {
    /// The calibration (schedule, coefficients, site) was invalid.
    #[error(transparent)]
    Calib(#[from] CalibError),
    /// The allocation core failed or its inputs were invalid.
    #[error(transparent)]
    Alloc(#[from] AllocError),
    /// A tolerance box was invalid (non-finite or negative bound, `LB > UB`); names the
    /// component and the bound.
    #[error(transparent)]
    Bounds(#[from] McError),
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (e.g. `omega_m`).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A named input must be strictly positive.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// Which input.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A sample count was zero.
    #[error("{field} must be at least 1, got 0")]
    ZeroSamples {
        /// Which count (`samples`, `chunk_size`, `histogram_bins`).
        field: &'static str,
    },
    /// A probability had to lie strictly between 0 and 1.
    #[error("{field} must lie in (0, 1), got {value}")]
    FractionOutOfRange {
        /// Which input (`yield_fraction`).
        field: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A step or size parameter was outside its documented range.
    #[error("{field} = {value} is outside {range}")]
    OutOfRange {
        /// Which input.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// The lower bounds alone violate the rate requirement on some row (the linearised worst
    /// case of the box $[\mathrm{LB}, \mathrm{LB}]$ exceeds $\omega_m$).
    #[error(
        "the lower bounds alone give a worst-case rate error of {worst_rad_per_s} rad/s on the {axis} axis at position {position} (omega_m = {omega_m_rad_per_s} rad/s)"
    )]
    InfeasibleLowerBounds {
        /// `x` or `y`.
        axis: &'static str,
        /// Index of the calibration position in the schedule.
        position: usize,
        /// The lower bounds' worst case, rad/s.
        worst_rad_per_s: f64,
        /// The requirement, rad/s.
        omega_m_rad_per_s: f64,
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
}

pub(crate) fn finite(field: &str, value: f64) -> Result<f64, E2eError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(E2eError::NonFinite {
            field: field.to_string(),
            value,
        })
    }
}

pub(crate) fn positive(field: &str, value: f64) -> Result<f64, E2eError> {
    finite(field, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(E2eError::NotPositive {
            field: field.to_string(),
            value,
        })
    }
}

pub(crate) fn fraction(field: &'static str, value: f64) -> Result<f64, E2eError> {
    if value.is_finite() && value > 0.0 && value < 1.0 {
        Ok(value)
    } else {
        Err(E2eError::FractionOutOfRange { field, value })
    }
}
