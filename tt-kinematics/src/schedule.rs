//! A turntable at the positions of a calibration schedule, as a [`ScheduleErrorModel`]: the
//! implementation the end-to-end analysis uses for a [`Turntable`] (the segmented chain,
//! [`PoseFrames`], with the nominal part computed once per position).

use crate::error::KinematicsError;
use crate::linear::LinearModel;
use crate::model::{ScheduleErrorModel, pose_at};
use crate::turntable::{PoseFrames, Turntable};
use nalgebra::{DMatrix, Matrix3, Vector3};
use tt_core::Pose;

/// A [`Turntable`] at a list of poses (one per schedule position), as a
/// [`ScheduleErrorModel`] over its angular errors: $\Delta\mathbf R_i$ by the segmented exact
/// chain ([`Turntable::segment_rotations`] once per error vector, [`PoseFrames`] once per
/// pose), the first order by the turntable's [`LinearModel`] (analytic).
///
/// ```
/// use tt_kinematics::{paper, Pose, ScheduleErrorModel, TurntableSchedule};
/// let poses = vec![Pose::from_deg(&[0.0, 0.0])?, Pose::from_deg(&[90.0, 45.0])?];
/// let s = TurntableSchedule::new(&paper::table3(), &poses)?;
/// assert_eq!((s.n_errors(), s.n_positions()), (8, 2));
/// // every rotation of the chain turns by at most its error: the angles sum to |chi|_1
/// assert_eq!(s.angle_sum_bound(&[0.25; 8]), Some(2.0));
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurntableSchedule {
    turntable: Turntable,
    poses: Vec<Pose>,
    frames: Vec<PoseFrames>,
    linear: LinearModel,
}

impl TurntableSchedule {
    /// `turntable` at `poses`.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] (length) naming `pose` for a pose that does not fit the
    /// turntable.
    pub fn new(turntable: &Turntable, poses: &[Pose]) -> Result<Self, KinematicsError> {
        let frames = poses
            .iter()
            .map(|p| turntable.pose_frames(p))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            turntable: turntable.clone(),
            poses: poses.to_vec(),
            frames,
            linear: LinearModel::new(turntable),
        })
    }

    /// The turntable.
    #[must_use]
    pub fn turntable(&self) -> &Turntable {
        &self.turntable
    }

    /// The turntable's first-order model (one per schedule, so what it computes once, such as
    /// its average sensitivities, is shared by every user of the schedule).
    #[must_use]
    pub fn linear_model(&self) -> &LinearModel {
        &self.linear
    }

    /// The poses, one per position.
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// The nominal data of the segmented chain at every position (the fast path of the
    /// end-to-end analysis).
    #[doc(hidden)]
    #[must_use]
    pub fn frames(&self) -> &[PoseFrames] {
        &self.frames
    }
}

impl ScheduleErrorModel for TurntableSchedule {
    fn n_errors(&self) -> usize {
        self.turntable.n_rotation_errors()
    }

    fn n_positions(&self) -> usize {
        self.poses.len()
    }

    fn delta_r_into(
        &self,
        chi_rad: &[f64],
        out: &mut [Matrix3<f64>],
    ) -> Result<(), KinematicsError> {
        tt_core::length("delta_r", self.poses.len(), out.len())?;
        let mut e = vec![Matrix3::identity(); self.turntable.n_segments()];
        self.turntable.segment_rotations(chi_rad, &mut e)?;
        for (o, f) in out.iter_mut().zip(&self.frames) {
            *o = f.delta_r(&e);
        }
        Ok(())
    }

    fn error_names(&self) -> Vec<String> {
        self.turntable
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect()
    }

    fn first_order(&self, position: usize) -> Result<DMatrix<f64>, KinematicsError> {
        self.linear.coefficients(pose_at(&self.poses, position)?)
    }

    fn rotation_vectors(&self, position: usize) -> Result<Vec<Vector3<f64>>, KinematicsError> {
        self.linear
            .rotation_vectors(pose_at(&self.poses, position)?)
    }

    /// $\sum_j \mathrm{UB}_j$ over the finite bounds: $\Delta\mathbf R$ is a product of
    /// rotations by the errors themselves.
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        Some(ub_rad.iter().filter(|u| u.is_finite()).sum())
    }

    fn joint_ranges_rad(&self) -> Vec<[f64; 2]> {
        self.turntable.joint_ranges_rad()
    }

    fn as_turntable_schedule(&self) -> Option<&TurntableSchedule> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::paper;
    use approx::assert_relative_eq;

    /// Rounding of a product of a few 3x3 rotations (dimensionless matrix entries).
    const ROUNDING: f64 = 1e-14;

    fn schedule() -> TurntableSchedule {
        let poses = [[0.0, 0.0], [90.0, 45.0], [200.0, -30.0]]
            .iter()
            .map(|p| Pose::from_deg(p).unwrap())
            .collect::<Vec<_>>();
        TurntableSchedule::new(&paper::table3(), &poses).unwrap()
    }

    #[test]
    fn segmented_delta_r_equals_the_plain_exact_chain() {
        let s = schedule();
        let chi: Vec<f64> = (0..8).map(|j| 1e-4 * (j as f64 - 3.5)).collect();
        let mut dr = vec![Matrix3::identity(); 3];
        s.delta_r_into(&chi, &mut dr).unwrap();
        let errors = crate::TurntableErrors::new(chi, vec![0.0]).unwrap();
        for (d, p) in dr.iter().zip(s.poses()) {
            let plain = s
                .turntable()
                .delta_r(p, &errors, crate::ChainKind::Exact)
                .unwrap();
            assert_relative_eq!(*d, plain, epsilon = ROUNDING);
        }
    }

    #[test]
    fn default_rotation_vectors_read_first_order_as_gamma_psi_theta() {
        // the trait's default reads the 3 x n first order as (gamma, psi, theta) about (x, y, z);
        // the turntable's analytic vectors must be that reading of its own coefficients
        struct ByDefault<'a>(&'a TurntableSchedule);
        impl ScheduleErrorModel for ByDefault<'_> {
            fn n_errors(&self) -> usize {
                self.0.n_errors()
            }
            fn n_positions(&self) -> usize {
                self.0.n_positions()
            }
            fn delta_r_into(
                &self,
                chi: &[f64],
                out: &mut [Matrix3<f64>],
            ) -> Result<(), KinematicsError> {
                self.0.delta_r_into(chi, out)
            }
            fn first_order(&self, i: usize) -> Result<DMatrix<f64>, KinematicsError> {
                self.0.first_order(i)
            }
        }
        let s = schedule();
        for i in 0..3 {
            let a = s.rotation_vectors(i).unwrap();
            let b = ByDefault(&s).rotation_vectors(i).unwrap();
            for (x, y) in a.iter().zip(&b) {
                assert_relative_eq!(*x, *y, epsilon = ROUNDING);
            }
        }
        assert_eq!(ByDefault(&s).angle_sum_bound(&[1.0; 8]), None);
        assert!(ByDefault(&s).as_turntable_schedule().is_none());
    }

    #[test]
    fn a_position_outside_the_schedule_is_an_error_naming_position() {
        let e = schedule().first_order(3).unwrap_err();
        assert!(e.to_string().contains("position"), "{e}");
    }
}
