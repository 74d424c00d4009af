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
    /// A named input must not be negative.
    #[error("{field} must not be negative, got {value}")]
    Negative {
        /// Which input (for example `white_per_sqrt_hz`).
        field: String,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// A white-noise density was given in a unit of one family (an angular rate's angle
    /// random walk) for an output of the other (a specific force in mg); `unit` is the
    /// output's unit label as written (shown escaped).
    #[error(
        "`{key}` is a density of {key_family}, but the output's unit {unit:?} is {unit_family}: give the density in a unit of {unit_family}, or in the output's unit with `white_per_sqrt_hz`"
    )]
    UnitFamilyMismatch {
        /// The density's key (`white_deg_per_sqrt_h`, ...).
        key: String,
        /// The output's unit label.
        unit: String,
        /// The family of the key's unit.
        key_family: crate::noise::UnitFamily,
        /// The family of the output's unit.
        unit_family: crate::noise::UnitFamily,
    },
    /// A datasheet density needs converting to the output's unit, but the unit label is not
    /// one of [`crate::noise::OUTPUT_UNITS`].
    #[error(
        "`{key}` must be converted to the output's unit, but {unit:?} is not a unit we know (deg_per_h, deg/h, deg_per_s, deg/s, rad_per_s, rad/s, g, mg, ug, m_per_s2, m/s^2, m/s2): give the density in the output's unit with `white_per_sqrt_hz`"
    )]
    UnknownUnit {
        /// The density's key.
        key: String,
        /// The output's unit label.
        unit: String,
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

pub(crate) fn non_negative(field: &str, value: f64) -> Result<f64, ModelError> {
    finite(field, value)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(ModelError::Negative {
            field: field.to_string(),
            value,
        })
    }
}
