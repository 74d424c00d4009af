//! Errors in what the user gave us (files, flags): they exit with code 2. The type and the
//! one rule from a library error to it live in the study-level library ([`tt_lab::error`]);
//! here a [`tt_lab::LabError`] becomes the command's error, its input errors still an
//! [`InputError`] for the exit code.

pub use tt_lab::InputError;

/// A study-level error as the command's error: an input error stays an [`InputError`] (exit 2).
pub fn lab(e: tt_lab::LabError) -> anyhow::Error {
    match e {
        tt_lab::LabError::Input(i) => anyhow::Error::new(i),
        other => anyhow::Error::new(other),
    }
}
