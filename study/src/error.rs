//! The crate's error type.

/// A problem with a study, tolerance or CSV input, naming where it is (file and key, or file,
/// line and column) and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{location}: {reason}")]
#[non_exhaustive]
pub struct StudyError {
    /// Where: a file and key (``file: key `turntable.factors[3].about` ``), a file, line and column (`file:12 column 4`), or the file.
    pub location: String,
    /// Why it was rejected.
    pub reason: String,
}

impl StudyError {
    /// A new error.
    pub fn new(location: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            location: location.into(),
            reason: reason.into(),
        }
    }
}

impl tt_core::ErrorClass for StudyError {
    /// Always the user's input: the location names the file and key, or the line and column.
    fn input_field(&self) -> Option<&str> {
        Some(&self.location)
    }
}
