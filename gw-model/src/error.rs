//! The crate's error type.

/// Errors from constructing sites, orientation errors and sensor models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// An input was rejected by a check (NaN or infinite, not positive, negative), naming the
    /// field (`latitude`, `outputs[0].terms[2].value`, `white_per_sqrt_hz`).
    #[error(transparent)]
    Field(#[from] tt_core::FieldError),
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
    /// A specification ([`crate::spec::Specification`]) is invalid; `key` is its field
    /// (`coefficient`, `unit`, `coverage`, `limit`, `range`, `range_unit`, `output`).
    #[error("{key}: {reason}")]
    Specification {
        /// The field.
        key: String,
        /// Why it was rejected (naming the value as written).
        reason: String,
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

pub(crate) use tt_core::{finite, non_negative, positive};

impl tt_core::ErrorClass for ModelError {
    /// Every variant is the caller's input: the field, the latitude, the sensor key or the
    /// noise density's key.
    fn input_field(&self) -> Option<&str> {
        match self {
            ModelError::Field(e) => Some(e.field()),
            ModelError::LatitudeOutOfRange { .. } => Some("latitude"),
            ModelError::Sensor { key, .. } | ModelError::Specification { key, .. } => Some(key),
            ModelError::UnitFamilyMismatch { key, .. } | ModelError::UnknownUnit { key, .. } => {
                Some(key)
            }
        }
    }
}
