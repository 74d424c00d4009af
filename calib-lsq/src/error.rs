//! The crate's error type.

use gw_model::ModelError;

/// Errors from schedules, least squares, the orientation-error analysis and the requirement.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CalibError {
    /// An input of the sensor model was invalid (site, orientation angles, sensor).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A named input was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input (for example `accuracy` or `outputs[3]`).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A named input must be strictly positive.
    #[error("{field} must be positive, got {value}")]
    NonPositive {
        /// Which input.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A schedule (or regression matrix) cannot identify some coefficients: they lie in the
    /// null space of $\mathbf A$.
    #[error(
        "the schedule cannot identify {} of output `{output}` (rank {rank} of {columns} with {positions} positions)",
        coefficients.join(", ")
    )]
    Unidentifiable {
        /// The output whose regression is rank deficient.
        output: String,
        /// Names of the coefficients that are not identifiable.
        coefficients: Vec<String>,
        /// Numerical rank of $\mathbf A$.
        rank: usize,
        /// Number of estimated coefficients.
        columns: usize,
        /// Number of positions.
        positions: usize,
    },
    /// Two vectors that must have equal lengths do not.
    #[error("{what}: expected {expected} entries, got {found}")]
    LengthMismatch {
        /// What was passed (for example `outputs` or `delta_r`).
        what: &'static str,
        /// The required length (number of positions).
        expected: usize,
        /// The given length.
        found: usize,
    },
    /// The requirement region is not bounded within the search range (the reading gives no
    /// error growth in some direction).
    #[error(
        "rate error of output `{output}` stays below its accuracy up to {limit_rad} rad of orientation error in direction {direction:?}"
    )]
    Unbounded {
        /// Output whose region is unbounded.
        output: String,
        /// Direction (unit vector in the output's angle space) along which no boundary was found.
        direction: Vec<f64>,
        /// The search limit, rad.
        limit_rad: f64,
    },
    /// No output is sensitive to any orientation angle: there is no orientation requirement.
    #[error(
        "no output's calibration error depends on the orientation: no requirement can be derived"
    )]
    NoSensitivity,
    /// A reading name could not be parsed.
    #[error(
        "unknown reading `{name}`; expected `outputs/estimate/form`, e.g. `intended/beta1/printed` (see Reading::all)"
    )]
    UnknownReading {
        /// The name given.
        name: String,
    },
    /// A grid specification was invalid.
    #[error(
        "grid needs at least 2 points per side and a positive half range, got {points} points and {half_range_rad} rad"
    )]
    BadGrid {
        /// Points per side.
        points: usize,
        /// Half range, rad.
        half_range_rad: f64,
    },
    /// A calibration timing (dwell, move time, sample rate) is invalid; `field` names it
    /// (`move_s`, `dwell_s[3]`).
    #[error("{field}: {reason}")]
    Timing {
        /// Which value.
        field: String,
        /// Why it was rejected.
        reason: String,
    },
    /// An output or angle was named that does not exist.
    #[error("{what} `{name}` does not exist")]
    Unknown {
        /// What kind of thing (`output`, `angle`).
        what: &'static str,
        /// The name given.
        name: String,
    },
}

pub(crate) fn finite(field: impl Into<String>, value: f64) -> Result<f64, CalibError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(CalibError::NonFinite {
            field: field.into(),
            value,
        })
    }
}

pub(crate) fn positive(field: impl Into<String>, value: f64) -> Result<f64, CalibError> {
    let field = field.into();
    finite(field.as_str(), value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(CalibError::NonPositive { field, value })
    }
}
