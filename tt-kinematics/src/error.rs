//! The crate's error type.

/// Errors from constructing turntable poses and error vectors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (for example `dalpha_x2` or `phi2`).
        field: &'static str,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
}

pub(crate) fn finite(field: &'static str, value: f64) -> Result<f64, KinematicsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(KinematicsError::NonFinite { field, value })
    }
}
