//! Turntable poses: commanded joint angles.

use crate::error::{FieldError, finite};
use crate::units::RAD_PER_DEG;

/// Commanded joint angles of a turntable, radians, in the order of the description's joints
/// (the order in which they appear from the base to the platform).
///
/// A pose is not tied to one turntable; a turntable checks that it has one angle per joint
/// when it is used.
///
/// ```
/// use tt_core::Pose;
/// let p = Pose::from_deg(&[90.0, 45.0])?;
/// assert_eq!(p.angles_rad()[0], std::f64::consts::FRAC_PI_2);
/// assert!(Pose::from_deg(&[0.0, f64::NAN]).is_err()); // names `pose[1]`
/// # Ok::<(), tt_core::FieldError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Pose {
    angles_rad: Vec<f64>,
}

/// The first non-finite angle, named `pose[k]`.
fn check(angles: &[f64]) -> Result<(), FieldError> {
    match angles.iter().position(|a| !a.is_finite()) {
        Some(k) => finite(format!("pose[{k}]"), angles[k]).map(|_| ()),
        None => Ok(()),
    }
}

impl Pose {
    /// A pose from angles in radians; rejects NaN and infinities, naming `pose[k]`.
    ///
    /// # Errors
    /// [`FieldError::NonFinite`] naming the angle.
    pub fn new(angles_rad: Vec<f64>) -> Result<Self, FieldError> {
        check(&angles_rad)?;
        Ok(Self { angles_rad })
    }

    /// A pose from angles in degrees.
    ///
    /// # Errors
    /// As [`Pose::new`] (the value reported in degrees).
    pub fn from_deg(angles_deg: &[f64]) -> Result<Self, FieldError> {
        check(angles_deg)?;
        Self::new(angles_deg.iter().map(|a| a * RAD_PER_DEG).collect())
    }

    /// The angles, radians.
    #[must_use]
    pub fn angles_rad(&self) -> &[f64] {
        &self.angles_rad
    }

    /// The angles, degrees.
    #[must_use]
    pub fn angles_deg(&self) -> Vec<f64> {
        self.angles_rad.iter().map(|a| a / RAD_PER_DEG).collect()
    }

    /// Number of angles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.angles_rad.len()
    }

    /// Whether the pose has no angle.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.angles_rad.is_empty()
    }
}
