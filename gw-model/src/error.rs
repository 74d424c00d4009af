//! The crate's error type.

/// Errors from constructing sites, positions, coefficient sets and scale factors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (for example `latitude` or `D(x)_F`).
        field: &'static str,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// A named input must be strictly positive.
    #[error("{field} must be positive, got {value}")]
    NonPositive {
        /// Which input (for example `earth_rate`).
        field: &'static str,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// The latitude is outside $[-\pi/2, \pi/2]$.
    #[error("latitude must lie in [-90, 90] deg, got {latitude_deg} deg")]
    LatitudeOutOfRange {
        /// The offending latitude, degrees.
        latitude_deg: f64,
    },
}

pub(crate) fn finite(field: &'static str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ModelError::NonFinite { field, value })
    }
}

pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64, ModelError> {
    finite(field, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::NonPositive { field, value })
    }
}
