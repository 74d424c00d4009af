//! The orientation-accuracy requirement $(I_\psi, I_\theta, I_\gamma)$ of eq 15-16.

use crate::error::{FieldError, finite, positive};
use crate::orientation::OrientationAxis;
use crate::units::deg_to_rad;

/// The orientation-accuracy requirement $|\Delta\psi| \le I_\psi$, $|\Delta\theta| \le
/// I_\theta$, $|\Delta\gamma| \le I_\gamma$ (eq 15-16), radians.
///
/// An angle may carry no requirement (`None`), for example when no sensor output depends on
/// it: it then imposes no constraint. Every given value is finite and positive.
///
/// ```
/// use tt_core::{OrientationAxis, Requirement};
/// let r = Requirement::from_options([None, Some(2e-4), None])?;
/// assert_eq!(r.get(OrientationAxis::Theta), Some(2e-4));
/// assert_eq!(r.constrained_axes(), vec![OrientationAxis::Theta]);
/// assert!(Requirement::new(1e-4, -1.0, 1e-4).is_err()); // names `requirement.theta`
/// # Ok::<(), tt_core::FieldError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Requirement {
    rad: [Option<f64>; 3],
}

impl Requirement {
    /// A requirement on all three angles, radians; each must be finite and positive.
    ///
    /// # Errors
    /// [`FieldError::NonFinite`] or [`FieldError::NotPositive`] naming `requirement.<angle>`.
    pub fn new(psi_rad: f64, theta_rad: f64, gamma_rad: f64) -> Result<Self, FieldError> {
        Self::from_options([Some(psi_rad), Some(theta_rad), Some(gamma_rad)])
    }

    /// A requirement with some angles left free (`None`), order $\psi, \theta, \gamma$,
    /// radians; each given value must be finite and positive.
    ///
    /// # Errors
    /// As [`Requirement::new`].
    pub fn from_options(rad: [Option<f64>; 3]) -> Result<Self, FieldError> {
        let mut out = [None; 3];
        for axis in OrientationAxis::ALL {
            if let Some(v) = rad[axis.index()] {
                out[axis.index()] = Some(positive(format!("requirement.{}", axis.name()), v)?);
            }
        }
        Ok(Self { rad: out })
    }

    /// The same requirement for all three angles, in degrees.
    ///
    /// # Errors
    /// As [`Requirement::new`] (`requirement_deg` when not finite).
    pub fn uniform_deg(deg: f64) -> Result<Self, FieldError> {
        let r = deg_to_rad(finite("requirement_deg", deg)?);
        Self::new(r, r, r)
    }

    /// No requirement on any angle.
    #[must_use]
    pub fn none() -> Self {
        Self { rad: [None; 3] }
    }

    /// $I_k$ in radians, `None` when the angle carries no requirement.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> Option<f64> {
        self.rad[axis.index()]
    }

    /// All three, in the order $\psi, \theta, \gamma$, radians.
    #[must_use]
    pub fn to_array(&self) -> [Option<f64>; 3] {
        self.rad
    }

    /// All three in degrees (`None` where unconstrained).
    #[must_use]
    pub fn deg(&self) -> [Option<f64>; 3] {
        self.rad.map(|r| r.map(f64::to_degrees))
    }

    /// The smallest of the three, rad (`None` if none is constrained).
    #[must_use]
    pub fn min_rad(&self) -> Option<f64> {
        self.rad.iter().flatten().copied().reduce(f64::min)
    }

    /// The angles that carry a requirement, in the order $\psi, \theta, \gamma$.
    #[must_use]
    pub fn constrained_axes(&self) -> Vec<OrientationAxis> {
        OrientationAxis::ALL
            .into_iter()
            .filter(|a| self.get(*a).is_some())
            .collect()
    }

    /// The requirement multiplied by `factor` (in $(0, 1]$ for a safety margin); angles
    /// without a requirement stay without.
    ///
    /// # Errors
    /// [`FieldError::NotPositive`] when `factor` is not positive and finite.
    pub fn scaled(&self, factor: f64) -> Result<Self, FieldError> {
        let f = positive("requirement_factor", factor)?;
        Self::from_options(self.rad.map(|v| v.map(|v| v * f)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_values_name_the_angle() {
        let e = Requirement::from_options([Some(1e-4), None, Some(f64::NAN)]).unwrap_err();
        assert_eq!(e.field(), "requirement.gamma");
        let e = Requirement::new(0.0, 1e-4, 1e-4).unwrap_err();
        assert_eq!(e.field(), "requirement.psi");
        assert_eq!(
            Requirement::uniform_deg(f64::NAN).unwrap_err().field(),
            "requirement_deg"
        );
        let r = Requirement::new(1e-4, 2e-4, 3e-4).unwrap();
        assert_eq!(r.scaled(-1.0).unwrap_err().field(), "requirement_factor");
    }

    #[test]
    fn free_angles_stay_free_and_the_minimum_ignores_them() {
        let r = Requirement::from_options([None, Some(2e-4), Some(1e-4)]).unwrap();
        assert_eq!(
            r.scaled(0.5).unwrap().to_array(),
            [None, Some(1e-4), Some(5e-5)]
        );
        assert_eq!(r.min_rad(), Some(1e-4));
        assert_eq!(Requirement::none().min_rad(), None);
        assert!(Requirement::none().constrained_axes().is_empty());
    }
}
