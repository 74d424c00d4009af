//! The crate's one error type.

use std::fmt;

/// Where in a recording (or a segments file) a problem is: the source's name as the user gave
/// it, the 1-based line, and the column as its header names it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct At {
    /// The source (a path as given, or `-` / `<stdin>`).
    pub source: String,
    /// 1-based line, when known.
    pub line: Option<u64>,
    /// The column's header, when the problem is one cell.
    pub column: Option<String>,
}

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.source)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        if let Some(c) = &self.column {
            write!(f, " (column `{c}`)")?;
        }
        Ok(())
    }
}

/// Everything that can go wrong while processing a calibration recording.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// A cell, a header or a row of the recording or of the segments file is wrong.
    #[error("{at}: {reason}")]
    Input {
        /// Where.
        at: At,
        /// Why.
        reason: String,
    },
    /// An option (a flag of the command line) is wrong.
    #[error("{field}: {reason}")]
    Option {
        /// The option's name (`--spec`, `--column`, ...).
        field: String,
        /// Why.
        reason: String,
    },
    /// The segments (given or detected) do not match the study's schedule.
    #[error("segments: {reason}")]
    Segments {
        /// Every mismatch, one per line.
        reason: String,
    },
    /// The output file exists: it is never overwritten.
    #[error("{path}: exists; the calibration file is never overwritten (choose another name)")]
    Exists {
        /// The path as given.
        path: String,
    },
    /// The calibration file cannot be read as one.
    #[error("{path}: not a calibration file: {reason}")]
    CalibrationFile {
        /// The path as given.
        path: String,
        /// Why.
        reason: String,
    },
    /// Reading or writing failed (not the input's fault).
    #[error("{what}: {source}")]
    Io {
        /// What was read or written.
        what: String,
        /// The cause.
        source: std::io::Error,
    },
    /// A library computation failed where the input was accepted.
    #[error("{0}")]
    Internal(String),
}

impl RunError {
    pub(crate) fn input(
        source: &str,
        line: Option<u64>,
        column: Option<&str>,
        reason: impl Into<String>,
    ) -> Self {
        RunError::Input {
            at: At {
                source: source.to_string(),
                line,
                column: column.map(str::to_string),
            },
            reason: reason.into(),
        }
    }

    pub(crate) fn option(field: &str, reason: impl Into<String>) -> Self {
        RunError::Option {
            field: field.to_string(),
            reason: reason.into(),
        }
    }
}

impl tt_core::ErrorClass for RunError {
    fn input_field(&self) -> Option<&str> {
        match self {
            RunError::Input { at, .. } => Some(&at.source),
            RunError::Option { field, .. } => Some(field),
            RunError::Segments { .. } => Some("segments"),
            RunError::Exists { path } | RunError::CalibrationFile { path, .. } => Some(path),
            RunError::Io { .. } | RunError::Internal(_) => None,
        }
    }
}
