//! The study a command works on, loaded by the study-level library ([`tt_lab::loaded`]), its
//! errors as the command's.

use study::Study;
pub use tt_lab::loaded::{StudyRequirement, load, requirement_problem};

/// [`tt_lab::loaded::requirement`] as the command's result.
///
/// # Errors
/// An [`crate::InputError`] naming `requirement`.
pub fn requirement(s: &Study) -> anyhow::Result<StudyRequirement> {
    tt_lab::loaded::requirement(s).map_err(crate::input::lab)
}
