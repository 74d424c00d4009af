//! The crate's error type.

use gw_model::ModelError;

/// Errors from schedules, least squares, the orientation-error analysis and the requirement.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CalibError {
    /// An input of the sensor model was invalid (site, orientation angles, sensor).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// An input was rejected by a check (NaN or infinite, not positive, wrong length), naming
    /// the field (`accuracy`, `outputs[3]`, `delta_r`, `dwell_s[2]`).
    #[error(transparent)]
    Field(#[from] tt_core::FieldError),
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

pub(crate) use tt_core::{finite, positive};

impl tt_core::ErrorClass for CalibError {
    /// Input: the fields, a schedule that cannot identify a coefficient (`positions`), a
    /// reading's name, a grid, a timing, an unknown name. Internal: an unbounded requirement
    /// region (the search found no boundary).
    fn input_field(&self) -> Option<&str> {
        match self {
            CalibError::Model(e) => tt_core::ErrorClass::input_field(e),
            CalibError::Field(e) => Some(e.field()),
            CalibError::Unidentifiable { .. } => Some("positions"),
            CalibError::NoSensitivity => Some("sensor"),
            CalibError::UnknownReading { .. } => Some("reading"),
            CalibError::BadGrid { .. } => Some("grid"),
            CalibError::Timing { field, .. } => Some(field),
            CalibError::Unknown { what, .. } => Some(what),
            CalibError::Unbounded { .. } => None,
        }
    }
}
