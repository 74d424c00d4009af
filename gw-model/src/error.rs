//! The crate's error type.

/// Errors from constructing sites, orientation errors and sensor models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (for example `latitude` or `outputs[0].terms[2].value`).
        field: String,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// A named input must be strictly positive.
    #[error("{field} must be positive, got {value}")]
    NonPositive {
        /// Which input (for example `earth_rate`).
        field: String,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// The latitude is outside $[-\pi/2, \pi/2]$.
    #[error("latitude must lie in [-90, 90] deg, got {latitude_deg} deg")]
    LatitudeOutOfRange {
        /// The offending latitude, degrees.
        latitude_deg: f64,
    },
    /// A sensor description is invalid; `key` is the path inside it
    /// (`outputs[1].terms[3].regressor`), so that a file reader can name the offending key.
    #[error("{key}: {reason}")]
    Sensor {
        /// Where, relative to the sensor description.
        key: String,
        /// Why it was rejected.
        reason: String,
    },
}

pub(crate) fn finite(field: &str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ModelError::NonFinite {
            field: field.to_string(),
            value,
        })
    }
}

pub(crate) fn positive(field: &str, value: f64) -> Result<f64, ModelError> {
    finite(field, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::NonPositive {
            field: field.to_string(),
            value,
        })
    }
}
