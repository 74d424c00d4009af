//! Turntable pose: the commanded rotation angles of the two axes.

use crate::error::{KinematicsError, finite};
use crate::units::deg_to_rad;

/// Commanded turntable angles $\phi = (\phi_1, \phi_2)$ (eq 21), radians.
///
/// $\phi_1$ rotates the outer axis about $y$ of the base frame, $\phi_2$ the inner axis about
/// $z$ of the inner-axis reference frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Outer-axis angle $\phi_1$ (about $y$), rad.
    pub phi1_rad: f64,
    /// Inner-axis angle $\phi_2$ (about $z$), rad.
    pub phi2_rad: f64,
}

impl Pose {
    /// A pose from angles in radians; rejects NaN and infinities by name.
    pub fn new(phi1_rad: f64, phi2_rad: f64) -> Result<Self, KinematicsError> {
        Ok(Self {
            phi1_rad: finite("phi1", phi1_rad)?,
            phi2_rad: finite("phi2", phi2_rad)?,
        })
    }

    /// A pose from angles in degrees.
    pub fn from_deg(phi1_deg: f64, phi2_deg: f64) -> Result<Self, KinematicsError> {
        Ok(Self {
            phi1_rad: deg_to_rad(finite("phi1", phi1_deg)?),
            phi2_rad: deg_to_rad(finite("phi2", phi2_deg)?),
        })
    }
}
