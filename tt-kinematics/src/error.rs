//! The crate's error type.

/// Errors from describing a turntable and from evaluating it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (for example `dalpha_x2` or `phi2`).
        field: String,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// A turntable description is invalid. `key` is the path inside the description
    /// (`factors[3].about`, `joint_ranges_deg.phi1`, ...), so that a file reader can name the
    /// offending key.
    #[error("{key}: {reason}")]
    Description {
        /// Where, relative to the description (`factors[2].error`, `error_order[0]`).
        key: String,
        /// Why it was rejected.
        reason: String,
    },
    /// A vector passed to a turntable has the wrong length (one value per joint, per
    /// rotation error or per translation error).
    #[error("{what}: expected {expected} values, got {found}")]
    Length {
        /// What was passed (`pose`, `chi`, `translations`, `weights`).
        what: &'static str,
        /// How many the turntable needs.
        expected: usize,
        /// How many were given.
        found: usize,
    },
    /// A model was asked about a turntable it does not describe (for example the paper's
    /// closed form of eq 26 on a three-axis table).
    #[error("{model} applies only to {applies_to}")]
    WrongTurntable {
        /// The model.
        model: &'static str,
        /// What it applies to.
        applies_to: &'static str,
    },
}

pub(crate) fn finite(field: &str, value: f64) -> Result<f64, KinematicsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(KinematicsError::NonFinite {
            field: field.to_string(),
            value,
        })
    }
}

pub(crate) fn length(
    what: &'static str,
    expected: usize,
    found: usize,
) -> Result<(), KinematicsError> {
    if expected == found {
        Ok(())
    } else {
        Err(KinematicsError::Length {
            what,
            expected,
            found,
        })
    }
}

pub(crate) fn description(key: impl Into<String>, reason: impl Into<String>) -> KinematicsError {
    KinematicsError::Description {
        key: key.into(),
        reason: reason.into(),
    }
}
