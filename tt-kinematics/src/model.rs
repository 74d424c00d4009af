//! The seam [`OrientationErrorModel`] and its implementations for any turntable.

use crate::error::KinematicsError;
use crate::linear::LinearModel;
use crate::pose::TurntableErrors;
use crate::rotation::rotation_vector;
use crate::turntable::{ChainKind, Turntable};
use tt_core::{OrientationError, Pose};

/// Maps a turntable pose and its geometric errors to the orientation error of the platform.
///
/// Implemented for any turntable by [`ExactChain`], [`SmallAngleChain`] and [`LinearChain`],
/// and for the paper's table by [`crate::paper::ClosedForm`] (eq 26); all agree to first order
/// in the errors (the conformance suite, `crate::conformance` with the `conformance`
/// feature, checks it for any implementation).
///
/// ```
/// use tt_kinematics::{paper, ExactChain, OrientationErrorModel, Pose, TurntableErrors};
/// let table = paper::table3();
/// let chi = TurntableErrors::from_arcmin(&[0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0], &[0.0])?;
/// let e = ExactChain::new(&table).orientation_error(&Pose::from_deg(&[0.0, 0.0])?, &chi)?;
/// // eq 26: delta_theta = dphi_z2 + dalpha_z1, to second order
/// assert!((e.delta_theta_rad - 1.5_f64.to_radians() / 60.0).abs() < 1e-9);
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
pub trait OrientationErrorModel {
    /// $(\Delta\psi, \Delta\theta, \Delta\gamma)$ at `pose` for turntable `errors`.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) when the pose or the errors do not fit the model's
    /// turntable; [`KinematicsError::WrongTurntable`] for a model of one specific table.
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError>;
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

/// The exact chain: every error a finite rotation in the order of the description.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactChain {
    turntable: Turntable,
    /// How angles are read off $\Delta\mathbf R$.
    pub readout: ReadOut,
}

impl ExactChain {
    /// The exact chain of `turntable` with the eq-24 read-out.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            turntable: turntable.clone(),
            readout: ReadOut::MatrixElements,
        }
    }

    /// The same chain with another read-out.
    #[must_use]
    pub fn with_readout(self, readout: ReadOut) -> Self {
        Self { readout, ..self }
    }
}

impl OrientationErrorModel for ExactChain {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let dr = self.turntable.delta_r(pose, errors, ChainKind::Exact)?;
        Ok(match self.readout {
            ReadOut::MatrixElements => OrientationError::from_matrix_elements(&dr),
            ReadOut::RotationVector => {
                let v = rotation_vector(&dr);
                OrientationError {
                    delta_psi_rad: v.y,
                    delta_theta_rad: v.z,
                    delta_gamma_rad: v.x,
                }
            }
        })
    }
}

/// The chain with every run of consecutive error rotations replaced by one small-angle matrix
/// $I + [\delta]_\times$ ([`ChainKind::SmallAngle`]; eq 17-19 as printed for the paper's table),
/// read out by eq 24.
#[derive(Debug, Clone, PartialEq)]
pub struct SmallAngleChain {
    turntable: Turntable,
}

impl SmallAngleChain {
    /// The small-angle chain of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            turntable: turntable.clone(),
        }
    }
}

impl OrientationErrorModel for SmallAngleChain {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        Ok(OrientationError::from_matrix_elements(
            &self
                .turntable
                .delta_r(pose, errors, ChainKind::SmallAngle)?,
        ))
    }
}

/// The first-order model ([`LinearModel`]) as an [`OrientationErrorModel`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinearChain {
    model: LinearModel,
}

impl LinearChain {
    /// The first-order model of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            model: LinearModel::new(turntable),
        }
    }
}

impl OrientationErrorModel for LinearChain {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        self.model.evaluate(pose, errors)
    }
}
