//! The one error type of the crate: every variant names the field (or the input quantity) it
//! is about and the value given.

use std::ops::Bound;
use tt_core::FieldError;

/// What went wrong, naming the field and the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MetrologyError {
    /// A number or a list was rejected by a check (NaN or infinite, not positive, outside its
    /// range, wrong length), naming the field: `coverage`, `prior.sd`, `length.half_width`
    /// (an input's name, then its parameter), `output_names`.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// A matrix has the wrong size.
    #[error("{field}: {rows} x {cols} given, expected {expected}")]
    Shape {
        /// The matrix (`sensitivities`, `correlation`, `map`).
        field: &'static str,
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
        /// The expected size, in words (`3 x 5 (outputs x input components)`).
        expected: String,
    },
    /// A matrix entry is NaN or infinite.
    #[error("{field}[{row}, {col}] must be finite, got {value}")]
    NonFiniteEntry {
        /// The matrix.
        field: &'static str,
        /// Row, from 0.
        row: usize,
        /// Column, from 0.
        col: usize,
        /// The value given.
        value: f64,
    },
    /// A correlation matrix is not symmetric with a unit diagonal and entries in [-1, 1], or
    /// not positive semi-definite.
    #[error("{field}: {reason}")]
    InvalidCorrelation {
        /// `correlation[i, j]`, or `correlation` for the whole matrix.
        field: String,
        /// What is wrong, in words.
        reason: String,
    },
    /// Two input quantities share a name (a budget row must say which input it is).
    #[error("inputs: the name `{name}` is given twice")]
    DuplicateName {
        /// The repeated name.
        name: String,
    },
    /// The measurement model returned NaN or an infinite value.
    #[error("model: output {output} of trial {trial} is {value}, not a finite number")]
    NonFiniteModelValue {
        /// The output's index, from 0.
        output: usize,
        /// The trial's global index, from 0.
        trial: u64,
        /// The value returned.
        value: f64,
    },
}

impl tt_core::ErrorClass for MetrologyError {
    /// Every variant is the caller's input: a field, a matrix, an input's name or the model
    /// the caller gave (`model`).
    fn input_field(&self) -> Option<&str> {
        match self {
            MetrologyError::Field(e) => Some(e.field()),
            MetrologyError::Shape { field, .. } | MetrologyError::NonFiniteEntry { field, .. } => {
                Some(field)
            }
            MetrologyError::InvalidCorrelation { field, .. } => Some(field),
            MetrologyError::DuplicateName { .. } => Some("inputs"),
            MetrologyError::NonFiniteModelValue { .. } => Some("model"),
        }
    }
}

/// `value` if strictly between 0 and 1 (a coverage probability, a risk), else
/// [`FieldError::OutOfRange`] naming `field`.
pub(crate) fn probability(field: &str, value: f64) -> Result<f64, MetrologyError> {
    Ok(tt_core::in_range(
        field,
        value,
        Bound::Excluded(0.0),
        Bound::Excluded(1.0),
        "",
    )?)
}

/// Checks that `m` is `rows x cols` with finite entries.
pub(crate) fn check_matrix(
    field: &'static str,
    m: &nalgebra::DMatrix<f64>,
    rows: usize,
    cols: usize,
    expected: impl FnOnce() -> String,
) -> Result<(), MetrologyError> {
    if m.nrows() != rows || m.ncols() != cols {
        return Err(MetrologyError::Shape {
            field,
            rows: m.nrows(),
            cols: m.ncols(),
            expected: expected(),
        });
    }
    for j in 0..cols {
        for i in 0..rows {
            let value = m[(i, j)];
            if !value.is_finite() {
                return Err(MetrologyError::NonFiniteEntry {
                    field,
                    row: i,
                    col: j,
                    value,
                });
            }
        }
    }
    Ok(())
}
