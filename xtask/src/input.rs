//! Errors in what the user gave us (files, flags): they exit with code 2.

use std::fmt;

/// A problem with the user's input, naming where it is (file, line, column or key) and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError {
    /// Where: a file and line/column, a key, or a flag.
    pub location: String,
    /// Why it was rejected.
    pub reason: String,
}

impl InputError {
    /// A new input error.
    pub fn new(location: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            location: location.into(),
            reason: reason.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.reason)
    }
}

impl std::error::Error for InputError {}
