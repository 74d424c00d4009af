//! The three orientation-error angles of the sensor axes, their names, and the orientation
//! error $(\Delta\psi, \Delta\theta, \Delta\gamma)$ with its matrix $\Delta\mathbf R$.
//!
//! $\Delta\psi$ turns about $y$, $\Delta\theta$ about $z$, $\Delta\gamma$ about $x$, all in the
//! platform (sensor) frame (§2.2, Figure 3, eq 7 of Zhao et al. 2017).

use crate::axis::Axis;
use crate::error::{FieldError, finite};
use crate::units::RAD_PER_DEG;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// One of the three orientation-error angles, in the order of eq 24-26.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum OrientationAxis {
    /// $\Delta\psi$, rotation error about $y$.
    Psi,
    /// $\Delta\theta$, rotation error about $z$.
    Theta,
    /// $\Delta\gamma$, rotation error about $x$.
    Gamma,
}

impl OrientationAxis {
    /// All three, in the order $\psi, \theta, \gamma$ (eq 24-26).
    pub const ALL: [OrientationAxis; 3] = [
        OrientationAxis::Psi,
        OrientationAxis::Theta,
        OrientationAxis::Gamma,
    ];

    /// Row index (0, 1, 2).
    #[must_use]
    pub fn index(self) -> usize {
        self as usize
    }

    /// `"psi"`, `"theta"` or `"gamma"`: the one spelling of the angles' names in keys, JSON
    /// and messages.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            OrientationAxis::Psi => "psi",
            OrientationAxis::Theta => "theta",
            OrientationAxis::Gamma => "gamma",
        }
    }

    /// The frame axis the angle turns about: $y$ for $\psi$, $z$ for $\theta$, $x$ for
    /// $\gamma$ (Figure 3, eq 7).
    #[must_use]
    pub fn frame_axis(self) -> Axis {
        match self {
            OrientationAxis::Psi => Axis::Y,
            OrientationAxis::Theta => Axis::Z,
            OrientationAxis::Gamma => Axis::X,
        }
    }
}

/// How a triple of orientation-error angles becomes a matrix $\Delta\mathbf R$.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum DeltaRKind {
    /// The printed small-angle matrix of eq 7, $I + [\boldsymbol\delta]_\times$ (not orthonormal).
    /// The default: it is what the paper uses.
    #[default]
    SmallAngle,
    /// The exact rotation $\exp([\boldsymbol\delta]_\times)$ with the rotation vector
    /// $\boldsymbol\delta = (\Delta\gamma, \Delta\psi, \Delta\theta)$ (about $x$, $y$, $z$); it
    /// equals eq 7 to first order and needs no choice of rotation order.
    Exact,
}

impl DeltaRKind {
    /// `"small-angle"` or `"exact"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            DeltaRKind::SmallAngle => "small-angle",
            DeltaRKind::Exact => "exact",
        }
    }
}

/// The orientation error of the sensor axes (eq 24-25), radians: $\Delta\psi$ about $y$,
/// $\Delta\theta$ about $z$, $\Delta\gamma$ about $x$ (§2.2, Figure 3), in the platform
/// (sensor) frame.
///
/// What a turntable model returns for a pose and its errors, and what a sensor model turns
/// into a matrix $\Delta\mathbf R$ ([`OrientationError::delta_r`]).
///
/// ```
/// use tt_core::{DeltaRKind, OrientationAxis, OrientationError};
/// let e = OrientationError::from_deg(0.5, 0.0, 0.0)?;
/// assert_eq!(e.get(OrientationAxis::Psi), 0.5_f64.to_radians());
/// // eq 7: delta_psi sits at (1, 3) of the small-angle matrix
/// assert_eq!(e.delta_r(DeltaRKind::SmallAngle)[(0, 2)], e.delta_psi_rad);
/// # Ok::<(), tt_core::FieldError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OrientationError {
    /// $\Delta\psi$ (about $y$), rad.
    pub delta_psi_rad: f64,
    /// $\Delta\theta$ (about $z$), rad.
    pub delta_theta_rad: f64,
    /// $\Delta\gamma$ (about $x$), rad.
    pub delta_gamma_rad: f64,
}

impl OrientationError {
    /// No orientation error.
    pub const ZERO: Self = Self {
        delta_psi_rad: 0.0,
        delta_theta_rad: 0.0,
        delta_gamma_rad: 0.0,
    };

    /// From radians, each checked finite.
    ///
    /// # Errors
    /// [`FieldError::NonFinite`] naming `delta_psi`, `delta_theta` or `delta_gamma`.
    pub fn new(
        delta_psi_rad: f64,
        delta_theta_rad: f64,
        delta_gamma_rad: f64,
    ) -> Result<Self, FieldError> {
        Ok(Self {
            delta_psi_rad: finite("delta_psi", delta_psi_rad)?,
            delta_theta_rad: finite("delta_theta", delta_theta_rad)?,
            delta_gamma_rad: finite("delta_gamma", delta_gamma_rad)?,
        })
    }

    /// From degrees, each checked finite.
    ///
    /// # Errors
    /// As [`OrientationError::new`] (the value reported in degrees).
    pub fn from_deg(
        delta_psi_deg: f64,
        delta_theta_deg: f64,
        delta_gamma_deg: f64,
    ) -> Result<Self, FieldError> {
        Self::new(
            finite("delta_psi", delta_psi_deg)?.to_radians(),
            finite("delta_theta", delta_theta_deg)?.to_radians(),
            finite("delta_gamma", delta_gamma_deg)?.to_radians(),
        )
    }

    /// `[delta_psi, delta_theta, delta_gamma]`, radians (the order of eq 24-26 and of
    /// [`OrientationAxis::ALL`]).
    #[must_use]
    pub fn to_array(&self) -> [f64; 3] {
        [
            self.delta_psi_rad,
            self.delta_theta_rad,
            self.delta_gamma_rad,
        ]
    }

    /// From `[delta_psi, delta_theta, delta_gamma]`, radians (not checked).
    #[must_use]
    pub fn from_array(a: [f64; 3]) -> Self {
        Self {
            delta_psi_rad: a[0],
            delta_theta_rad: a[1],
            delta_gamma_rad: a[2],
        }
    }

    /// One angle, radians.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> f64 {
        self.to_array()[axis.index()]
    }

    /// The angles in degrees, in the order of [`OrientationError::to_array`].
    #[must_use]
    pub fn to_deg(&self) -> [f64; 3] {
        self.to_array().map(|a| a / RAD_PER_DEG)
    }

    /// Read the angles off $\Delta\mathbf R$ as eq 24 does:
    /// $\Delta\psi = \Delta R_{13}$, $\Delta\theta = \Delta R_{21}$, $\Delta\gamma = \Delta R_{32}$.
    #[must_use]
    pub fn from_matrix_elements(dr: &Matrix3<f64>) -> Self {
        Self {
            delta_psi_rad: dr[(0, 2)],
            delta_theta_rad: dr[(1, 0)],
            delta_gamma_rad: dr[(2, 1)],
        }
    }

    /// The rotation vector $(\Delta\gamma, \Delta\psi, \Delta\theta)$ (about $x$, $y$, $z$), rad.
    #[must_use]
    pub(crate) fn rotation_vector(&self) -> Vector3<f64> {
        Vector3::new(
            self.delta_gamma_rad,
            self.delta_psi_rad,
            self.delta_theta_rad,
        )
    }

    /// The angles of a rotation vector $(v_x, v_y, v_z)$: $\Delta\psi = v_y$,
    /// $\Delta\theta = v_z$, $\Delta\gamma = v_x$ (the inverse of
    /// [`OrientationError::rotation_vector`]).
    #[must_use]
    pub fn from_rotation_vector(v: &Vector3<f64>) -> Self {
        Self {
            delta_psi_rad: v.y,
            delta_theta_rad: v.z,
            delta_gamma_rad: v.x,
        }
    }

    /// The orientation-error matrix $\Delta\mathbf R$.
    ///
    /// # Formula
    /// Small angle (eq 7):
    /// $$\Delta\mathbf R = \begin{bmatrix} 1 & -\Delta\theta & \Delta\psi \\ \Delta\theta & 1 &
    ///   -\Delta\gamma \\ -\Delta\psi & \Delta\gamma & 1 \end{bmatrix};$$
    /// exact: $\exp$ of the same skew-symmetric part.
    ///
    /// # Reference
    /// Eq 7.
    #[must_use]
    pub fn delta_r(&self, kind: DeltaRKind) -> Matrix3<f64> {
        let w = self.rotation_vector();
        match kind {
            DeltaRKind::SmallAngle => Matrix3::identity() + w.cross_matrix(),
            DeltaRKind::Exact => Rotation3::new(w).into_inner(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_frame_axes_follow_eq_7() {
        assert_eq!(
            OrientationAxis::ALL.map(OrientationAxis::name),
            ["psi", "theta", "gamma"]
        );
        assert_eq!(
            OrientationAxis::ALL.map(OrientationAxis::frame_axis),
            [Axis::Y, Axis::Z, Axis::X]
        );
        assert_eq!(OrientationAxis::ALL.map(OrientationAxis::index), [0, 1, 2]);
    }

    #[test]
    fn matrix_elements_and_rotation_vector_read_back_the_angles() {
        let e = OrientationError::new(1e-3, -2e-3, 3e-3).unwrap();
        assert_eq!(
            OrientationError::from_matrix_elements(&e.delta_r(DeltaRKind::SmallAngle)),
            e
        );
        assert_eq!(
            OrientationError::from_rotation_vector(&e.rotation_vector()),
            e
        );
        assert_eq!(OrientationError::from_array(e.to_array()), e);
    }

    #[test]
    fn non_finite_angles_are_named() {
        let err = OrientationError::new(0.0, f64::NAN, 0.0).unwrap_err();
        assert_eq!(err.field(), "delta_theta");
        let err = OrientationError::from_deg(0.0, 0.0, f64::INFINITY).unwrap_err();
        assert_eq!(err.field(), "delta_gamma");
    }
}
