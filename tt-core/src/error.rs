//! One field-located validation error ([`FieldError`]) with its check helpers, and the
//! classification every library error of the workspace implements ([`ErrorClass`]).
//!
//! Every crate checks its inputs with these helpers and wraps [`FieldError`] in its own error
//! enum (`#[from]`), so a caller sees the same message for the same mistake in every crate
//! and can tell, through [`ErrorClass`], whether an error is the caller's input (naming the
//! field) or an internal failure.

use std::ops::Bound;

/// A caller's input rejected by a check, naming the field (`lower_bounds.deps_x`,
/// `pose[1]`, `samples`).
///
/// Field names are the library's: paths into the value that was passed, with `.` between
/// names and `[k]` for an index. A file reader or a command line maps them to its keys and
/// flags.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// A value was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Which input.
        field: String,
        /// The offending value, in the unit the caller used.
        value: f64,
    },
    /// A value that must be strictly positive was zero or negative.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// Which input.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A value that must not be negative was negative.
    #[error("{field} must not be negative, got {value}")]
    Negative {
        /// Which input.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A list has the wrong number of values (one per joint, per error, per position...).
    #[error("{field}: expected {expected} values, got {found}")]
    Length {
        /// Which list.
        field: String,
        /// How many are needed.
        expected: usize,
        /// How many were given.
        found: usize,
    },
    /// A value lies outside its documented range (given in words or as an interval).
    #[error("{field} = {value} is outside {range}")]
    OutOfRange {
        /// Which input.
        field: String,
        /// The offending value.
        value: f64,
        /// The accepted range (`(0, 360] deg`, `one pose per position of the schedule`).
        range: String,
    },
    /// A count was zero or above its maximum.
    #[error("{field} must lie in 1..={max}, got {value}")]
    Count {
        /// Which count (`samples`, `chunk_size`).
        field: String,
        /// The offending value.
        value: u64,
        /// The largest accepted value.
        max: u64,
    },
}

/// The `field` of a [`FieldError`] (`&FieldError` gives `&String`, `&mut FieldError` gives
/// `&mut String`): the one list of the variants for [`FieldError::field`] and
/// [`FieldError::within`].
macro_rules! field_of {
    ($error:expr) => {
        match $error {
            FieldError::NonFinite { field, .. }
            | FieldError::NotPositive { field, .. }
            | FieldError::Negative { field, .. }
            | FieldError::Length { field, .. }
            | FieldError::OutOfRange { field, .. }
            | FieldError::Count { field, .. } => field,
        }
    };
}

impl FieldError {
    /// The field the error is about.
    #[must_use]
    pub fn field(&self) -> &str {
        field_of!(self)
    }

    /// The same error about `prefix.field` (a caller that nests the value under a name).
    #[must_use]
    pub fn within(mut self, prefix: &str) -> Self {
        let f = field_of!(&mut self);
        *f = format!("{prefix}.{f}");
        self
    }
}

/// `value` if finite.
///
/// # Errors
/// [`FieldError::NonFinite`] naming `field`.
pub fn finite(field: impl Into<String>, value: f64) -> Result<f64, FieldError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(FieldError::NonFinite {
            field: field.into(),
            value,
        })
    }
}

/// `value` if finite and strictly positive.
///
/// # Errors
/// [`FieldError::NonFinite`] or [`FieldError::NotPositive`] naming `field`.
pub fn positive(field: impl Into<String>, value: f64) -> Result<f64, FieldError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        let field = field.into();
        finite(field.as_str(), value)?;
        Err(FieldError::NotPositive { field, value })
    }
}

/// `value` if finite and not negative.
///
/// # Errors
/// [`FieldError::NonFinite`] or [`FieldError::Negative`] naming `field`.
pub fn non_negative(field: impl Into<String>, value: f64) -> Result<f64, FieldError> {
    if value >= 0.0 && value.is_finite() {
        Ok(value)
    } else {
        let field = field.into();
        finite(field.as_str(), value)?;
        Err(FieldError::Negative { field, value })
    }
}

/// `Ok` when a list named `field` has the `expected` length.
///
/// # Errors
/// [`FieldError::Length`] naming `field`.
pub fn length(field: impl Into<String>, expected: usize, found: usize) -> Result<(), FieldError> {
    if expected == found {
        Ok(())
    } else {
        Err(FieldError::Length {
            field: field.into(),
            expected,
            found,
        })
    }
}

/// `value` if it lies between `lo` and `hi` (NaN never does); the message writes the interval
/// (`(0, 360] deg`) followed by `unit` when it is not empty.
///
/// # Errors
/// [`FieldError::OutOfRange`] naming `field`.
pub fn in_range(
    field: impl Into<String>,
    value: f64,
    lo: Bound<f64>,
    hi: Bound<f64>,
    unit: &str,
) -> Result<f64, FieldError> {
    let above = match lo {
        Bound::Included(l) => value >= l,
        Bound::Excluded(l) => value > l,
        Bound::Unbounded => !value.is_nan(),
    };
    let below = match hi {
        Bound::Included(h) => value <= h,
        Bound::Excluded(h) => value < h,
        Bound::Unbounded => !value.is_nan(),
    };
    if above && below {
        return Ok(value);
    }
    let left = match lo {
        Bound::Included(l) => format!("[{l}"),
        Bound::Excluded(l) => format!("({l}"),
        Bound::Unbounded => "(-inf".to_string(),
    };
    let right = match hi {
        Bound::Included(h) => format!("{h}]"),
        Bound::Excluded(h) => format!("{h})"),
        Bound::Unbounded => "inf)".to_string(),
    };
    let range = if unit.is_empty() {
        format!("{left}, {right}")
    } else {
        format!("{left}, {right} {unit}")
    };
    Err(FieldError::OutOfRange {
        field: field.into(),
        value,
        range,
    })
}

/// `value` if it lies in `1..=max`.
///
/// # Errors
/// [`FieldError::Count`] naming `field`.
pub fn count(field: impl Into<String>, value: u64, max: u64) -> Result<u64, FieldError> {
    if (1..=max).contains(&value) {
        Ok(value)
    } else {
        Err(FieldError::Count {
            field: field.into(),
            value,
            max,
        })
    }
}

/// Whether an error is the caller's input (naming the field at fault) or an internal failure
/// (a solver that did not converge, a computed value that came out non-finite).
///
/// Implemented by every library error of the workspace; a command line turns it into its exit
/// code with one rule (input: the user's mistake, exit 2, located by the field; otherwise 1).
///
/// ```
/// use tt_core::{ErrorClass, FieldError, finite};
/// let e: FieldError = finite("site.latitude", f64::NAN).unwrap_err();
/// assert_eq!(e.input_field(), Some("site.latitude"));
/// assert!(e.is_input());
/// ```
pub trait ErrorClass {
    /// The input field at fault (a path such as `lower_bounds.deps_x` or `samples`) when the
    /// error is the caller's input; `None` for an internal failure.
    fn input_field(&self) -> Option<&str>;

    /// Whether the error is the caller's input ([`ErrorClass::input_field`] names it).
    fn is_input(&self) -> bool {
        self.input_field().is_some()
    }
}

impl ErrorClass for FieldError {
    fn input_field(&self) -> Option<&str> {
        Some(self.field())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_check_names_its_field_and_passes_good_values() {
        assert_eq!(finite("a", 1.0), Ok(1.0));
        assert_eq!(positive("a", 2.0), Ok(2.0));
        assert_eq!(non_negative("a", 0.0), Ok(0.0));
        assert_eq!(length("a", 2, 2), Ok(()));
        assert_eq!(count("a", 3, 3), Ok(3));
        for e in [
            finite("x.y", f64::NAN).unwrap_err(),
            positive("x.y", 0.0).unwrap_err(),
            positive("x.y", f64::INFINITY).unwrap_err(),
            non_negative("x.y", -1.0).unwrap_err(),
            length("x.y", 2, 3).unwrap_err(),
            count("x.y", 0, 5).unwrap_err(),
            in_range(
                "x.y",
                361.0,
                Bound::Excluded(0.0),
                Bound::Included(360.0),
                "deg",
            )
            .unwrap_err(),
        ] {
            assert_eq!(e.input_field(), Some("x.y"), "{e}");
            assert!(e.to_string().starts_with("x.y"), "{e}");
        }
    }

    #[test]
    fn messages_state_the_rule_and_the_value() {
        assert_eq!(
            positive("earth_rate", -1.0).unwrap_err().to_string(),
            "earth_rate must be positive, got -1"
        );
        assert_eq!(
            non_negative("lb", f64::NAN).unwrap_err().to_string(),
            "lb must be finite, got NaN"
        );
        assert_eq!(
            length("pose", 3, 2).unwrap_err().to_string(),
            "pose: expected 3 values, got 2"
        );
        assert_eq!(
            count("samples", 0, 10).unwrap_err().to_string(),
            "samples must lie in 1..=10, got 0"
        );
        assert_eq!(
            in_range(
                "step",
                0.0,
                Bound::Excluded(0.0),
                Bound::Included(360.0),
                "deg"
            )
            .unwrap_err()
            .to_string(),
            "step = 0 is outside (0, 360] deg"
        );
        assert_eq!(
            in_range(
                "p",
                f64::NAN,
                Bound::Excluded(0.0),
                Bound::Excluded(1.0),
                ""
            )
            .unwrap_err()
            .to_string(),
            "p = NaN is outside (0, 1)"
        );
        assert_eq!(
            finite("b", 1.0 / 0.0).unwrap_err().within("a").to_string(),
            "a.b must be finite, got inf"
        );
    }
}
