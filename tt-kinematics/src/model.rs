//! The seam [`OrientationErrorModel`] and its three implementations.

use crate::chain::{ChainKind, delta_r};
use crate::errors::TurntableErrors;
use crate::linear::{LinearModel, OrientationAxis};
use crate::pose::Pose;
use nalgebra::{Matrix3, Vector3};

/// The orientation error of the GyroWheel axes (eq 24-25), radians.
///
/// $\Delta\psi$ is the rotation error about $y$, $\Delta\theta$ about $z$, $\Delta\gamma$ about
/// $x$ (paper Figure 3 and eq 7).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OrientationError {
    /// $\Delta\psi$ (about $y$), rad.
    pub delta_psi_rad: f64,
    /// $\Delta\theta$ (about $z$), rad.
    pub delta_theta_rad: f64,
    /// $\Delta\gamma$ (about $x$), rad.
    pub delta_gamma_rad: f64,
}

impl OrientationError {
    /// `[delta_psi, delta_theta, delta_gamma]`, radians (the order of eq 24-26).
    #[must_use]
    pub fn to_array(&self) -> [f64; 3] {
        [
            self.delta_psi_rad,
            self.delta_theta_rad,
            self.delta_gamma_rad,
        ]
    }

    /// From `[delta_psi, delta_theta, delta_gamma]`, radians.
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
}

/// Maps a turntable pose and its geometric errors to the orientation error of the sensor.
///
/// Implemented by [`ExactChain`], [`SmallAngleChain`] and [`ClosedForm`]; all agree to first
/// order in the errors (tested by one conformance suite).
///
/// ```
/// use tt_kinematics::{ClosedForm, OrientationErrorModel, Pose, TurntableErrors};
/// let chi = TurntableErrors::from_arcmin([0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0], 0.0)?;
/// let e = ClosedForm.orientation_error(&Pose::from_deg(0.0, 0.0)?, &chi);
/// // eq 26: delta_theta = dphi_z2 + dalpha_z1
/// assert!((e.delta_theta_rad - 1.5_f64.to_radians() / 60.0).abs() < 1e-15);
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
pub trait OrientationErrorModel {
    /// $(\Delta\psi, \Delta\theta, \Delta\gamma)$ at `pose` for turntable `errors`.
    fn orientation_error(&self, pose: &Pose, errors: &TurntableErrors) -> OrientationError;
}

/// How the exact chain turns $\Delta\mathbf R$ into three angles (NOTES item 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReadOut {
    /// The paper's eq 24: the elements $\Delta R_{13}, \Delta R_{21}, \Delta R_{32}$. These are
    /// the angles only to first order; this is also what the paper's Monte Carlo evaluates.
    #[default]
    MatrixElements,
    /// The rotation vector of $\Delta\mathbf R$ (axis times angle, the logarithm map), whose
    /// $y$, $z$, $x$ components are $\Delta\psi, \Delta\theta, \Delta\gamma$. Exact for a single
    /// rotation; differs from [`ReadOut::MatrixElements`] at second order.
    RotationVector,
}

/// The exact chain: every error a finite rotation in Table 3's order (eq 17-23).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ExactChain {
    /// How angles are read off $\Delta\mathbf R$.
    pub readout: ReadOut,
}

impl OrientationErrorModel for ExactChain {
    fn orientation_error(&self, pose: &Pose, errors: &TurntableErrors) -> OrientationError {
        let dr = delta_r(pose, errors, ChainKind::Exact);
        match self.readout {
            ReadOut::MatrixElements => OrientationError::from_matrix_elements(&dr),
            ReadOut::RotationVector => {
                let v = rotation_vector(&dr);
                OrientationError {
                    delta_psi_rad: v.y,
                    delta_theta_rad: v.z,
                    delta_gamma_rad: v.x,
                }
            }
        }
    }
}

/// The chain of eq 17-23 with the small-angle matrices exactly as printed, read out by eq 24.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SmallAngleChain;

impl OrientationErrorModel for SmallAngleChain {
    fn orientation_error(&self, pose: &Pose, errors: &TurntableErrors) -> OrientationError {
        OrientationError::from_matrix_elements(&delta_r(pose, errors, ChainKind::SmallAngle))
    }
}

/// The closed form of eq 26 (first order in $\chi$; see [`LinearModel::paper_eq26`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ClosedForm;

impl OrientationErrorModel for ClosedForm {
    fn orientation_error(&self, pose: &Pose, errors: &TurntableErrors) -> OrientationError {
        LinearModel::paper_eq26().evaluate(pose.phi2_rad, errors)
    }
}

/// The rotation vector (axis times angle) of a rotation matrix, accurate for small angles.
///
/// With $v = \tfrac12\operatorname{vee}(R - R^T) = \sin\vartheta\,\hat n$ and
/// $\cos\vartheta = \tfrac12(\operatorname{tr}R - 1)$, $\vartheta = \operatorname{atan2}(|v|, \cos\vartheta)$
/// keeps full relative precision near $\vartheta = 0$ (unlike $\arccos$). Valid for
/// $\vartheta < \pi$, which holds for every turntable error of interest.
fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let angle = s.atan2(c);
    if s == 0.0 { v } else { v * (angle / s) }
}
