//! An az/el mount, defined outside the workspace's library crates and used through their
//! public API only (no `Turntable` anywhere): the proof of issue 20, item 1.
//!
//! # The model
//! Pose $(a, e)$: azimuth $a \in [0, 2\pi)$ about $z$, then elevation $e \in [0, \pi/2]$ about
//! $y$; intended $\mathbf R_d = R_z(a) R_y(e)$. Four errors (rad), names lower case as every
//! name of the workspace:
//! - `az_tilt` $\chi_0$: the azimuth axis tilted about the base $x$ axis;
//! - `el_offset` $\chi_1$: the elevation encoder's zero offset;
//! - `non_perp` $\chi_2$: the elevation axis not perpendicular to azimuth (about $x$ between
//!   the two joints);
//! - `flexure` $\chi_3$: gravity sag of the elevation structure, an elevation error of
//!   $\chi_3\cos e$. It depends on the joint angle, so no list of constant factor rotations
//!   (a [`tt_kinematics::TurntableDescription`]) expresses it.
//!
//! $$\mathbf R_t = R_x(\chi_0)\,R_z(a)\,R_x(\chi_2)\,R_y(e + \chi_1 + \chi_3\cos e),\qquad
//!   \Delta\mathbf R = \mathbf R_d^T\mathbf R_t,$$
//! read by eq 24 ($\Delta\psi = \Delta R_{13}$, $\Delta\theta = \Delta R_{21}$,
//! $\Delta\gamma = \Delta R_{32}$). To first order, $\Delta\mathbf R = \mathbf I +
//! [\boldsymbol\delta]_\times$ with $\boldsymbol\delta = \sum_j \chi_j \mathbf v_j$ in the
//! platform frame: $\mathbf v_0 = \mathbf R_d^T\mathbf e_x = (\cos e\cos a, -\sin a,
//! \sin e\cos a)$, $\mathbf v_1 = \mathbf e_y$, $\mathbf v_2 = R_y(e)^T\mathbf e_x = (\cos e,
//! 0, \sin e)$, $\mathbf v_3 = \cos e\,\mathbf e_y$; so (rows $\psi = \delta_y$,
//! $\theta = \delta_z$, $\gamma = \delta_x$)
//! $$c_\psi = (-\sin a,\ 1,\ 0,\ \cos e),\quad c_\theta = (\sin e\cos a,\ 0,\ \sin e,\ 0),\quad
//!   c_\gamma = (\cos e\cos a,\ 0,\ \cos e,\ 0).$$
//! The library derives these from the exact $\Delta\mathbf R$ (central differences,
//! `tt_kinematics::derived_first_order`); they are kept here as closed forms only for the
//! tests to check the derivation against. The worst cases over the domain are then
//! ($w \ge 0$): $\max\sum_j w_j|c_{\psi j}| = w_0 + w_1 + w_3$ at $(\pi/2, 0)$,
//! $\max\sum_j w_j|c_{\theta j}| = w_0 + w_2$ at $(0, \pi/2)$,
//! $\max\sum_j w_j|c_{\gamma j}| = w_0 + w_2$ at $(0, 0)$; the averages of $|c|$ are
//! $2/\pi$ for $|\sin a|$, $|\cos a|$, $\sin e$, $\cos e$ and $4/\pi^2$ for their products.
//!
//! # One definition
//! [`AzElMount`] implements [`OrientationErrorModel`] once: its error names, its exact
//! $\Delta\mathbf R$ and the one fact the end-to-end second-order bound needs (its angle-sum
//! bound). Everything else comes from the library:
//! - the angles: read off $\Delta\mathbf R$ by eq 24 (the trait's default);
//! - the first order: `tt_kinematics::derived_first_order` (the trait's default);
//! - the linear model, its proven worst case, the allocators and their certificate:
//!   [`alloc_opt::Linearised`] ([`linearised`]);
//! - the exact-chain check and margin: [`alloc_opt::exact_chain_check`],
//!   [`alloc_opt::allocate_with_exact_margin`] on that model;
//! - the Monte Carlo: `mc_verify::MonteCarlo::for_model`;
//! - end to end: the mount at a schedule's poses, [`tt_kinematics::AtPoses`] ([`at_poses`]),
//!   into `e2e_verify::EndToEnd::for_model`;
//! - the conformance suite: `tt_kinematics::conformance::check_model_general`.

use alloc_opt::{
    AllocError, AllocationProblem, Allocator, LinearErrorModel, Linearised, MethodDetails,
    ToleranceBox, Weights, finish,
};
use nalgebra::Matrix3;
use std::f64::consts::{FRAC_PI_2, TAU};
use tt_core::{Axis, Pose};
use tt_kinematics::rotation::rot;
use tt_kinematics::{AtPoses, KinematicsError, OrientationErrorModel, TurntableErrors};

/// The errors' names, lower case.
pub const ERROR_NAMES: [&str; 4] = ["az_tilt", "el_offset", "non_perp", "flexure"];

/// The az/el mount (see the crate docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AzElMount;

impl AzElMount {
    /// The joint ranges (rad): azimuth a full turn, elevation horizon to zenith.
    #[must_use]
    pub fn joint_ranges_rad(&self) -> Vec<[f64; 2]> {
        vec![[0.0, TAU], [0.0, FRAC_PI_2]]
    }

    /// $\Delta\mathbf R$ exactly.
    fn exact_delta_r(pose: &[f64], chi: &[f64]) -> Matrix3<f64> {
        let (a, e) = (pose[0], pose[1]);
        let rd = rot(Axis::Z, a) * rot(Axis::Y, e);
        let rt = rot(Axis::X, chi[0])
            * rot(Axis::Z, a)
            * rot(Axis::X, chi[2])
            * rot(Axis::Y, e + chi[1] + chi[3] * e.cos());
        rd.transpose() * rt
    }

    /// The first-order coefficients at $(a, e)$ (rows $\psi, \theta, \gamma$) in closed form:
    /// not used by the model (its first order is derived), kept for the tests.
    #[must_use]
    pub fn coefficients(a: f64, e: f64) -> [[f64; 4]; 3] {
        [
            [-a.sin(), 1.0, 0.0, e.cos()],
            [e.sin() * a.cos(), 0.0, e.sin(), 0.0],
            [e.cos() * a.cos(), 0.0, e.cos(), 0.0],
        ]
    }

    fn check(pose: &Pose, errors: &TurntableErrors) -> Result<(), KinematicsError> {
        tt_core::length("pose", 2, pose.angles_rad().len())?;
        tt_core::length("chi", 4, errors.chi_rad().len())?;
        Ok(())
    }
}

impl OrientationErrorModel for AzElMount {
    fn error_names(&self) -> Vec<String> {
        ERROR_NAMES.iter().map(|n| n.to_string()).collect()
    }

    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        Self::check(pose, errors)?;
        Ok(Self::exact_delta_r(pose.angles_rad(), errors.chi_rad()))
    }

    /// $\Delta\mathbf R = R_y(-e)R_z(-a)R_x(\chi_0)R_z(a)R_y(e)\cdot R_y(-e)R_x(\chi_2)R_y(e)
    /// \cdot R_y(\chi_1 + \chi_3\cos e)$ is a product of rotations by $\chi_0$, $\chi_2$ and
    /// $\chi_1 + \chi_3\cos e$, whose angles sum to at most $\sum_j \mathrm{UB}_j$ (the
    /// library passes finite bounds only).
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        Some(ub_rad.iter().sum())
    }
}

/// The mount's first-order model over its joint ranges, derived by the library: what the
/// allocators, the certificate and the exact-chain margin take.
///
/// # Errors
/// As [`Linearised::new`].
pub fn linearised() -> Result<Linearised<AzElMount>, AllocError> {
    Linearised::new(AzElMount, AzElMount.joint_ranges_rad())
}

/// The mount at the positions of a calibration schedule, `poses` (azimuth, elevation, rad):
/// what the end-to-end analysis takes (`e2e_verify::EndToEnd::for_model`).
///
/// # Errors
/// [`KinematicsError`] for a non-finite angle.
pub fn at_poses(poses: &[[f64; 2]]) -> Result<AtPoses<AzElMount>, KinematicsError> {
    let poses = poses
        .iter()
        .map(|p| Pose::new(p.to_vec()))
        .collect::<Result<_, _>>()?;
    Ok(AtPoses::of(AzElMount, poses))
}

/// The intended orientation $\mathbf R_d = R_z(a)R_y(e)$ (sensor to base) of every pose.
#[must_use]
pub fn base_from_sensor(poses: &[[f64; 2]]) -> Vec<Matrix3<f64>> {
    poses
        .iter()
        .map(|[a, e]| rot(Axis::Z, *a) * rot(Axis::Y, *e))
        .collect()
}

/// An allocator of our own, generic over any [`LinearErrorModel`]: every constrained error gets
/// the same bound $u$, the largest that keeps every quantity's worst case within its limit,
/// $u = \min_k I_k / \max_p\sum_{j} |c_{kj}(p)|$ over the involved errors; then the library's
/// public finishing step (certificate, safety shrink, objective with the inverse average
/// sensitivities, finiteness).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UniformBound;

impl<M: LinearErrorModel> Allocator<M> for UniformBound {
    fn name(&self) -> &str {
        "uniform-bound"
    }

    fn allocate(&self, problem: &AllocationProblem<M>) -> Result<ToleranceBox, AllocError> {
        let model = problem.model();
        let n = model.n_errors();
        let mut u = f64::INFINITY;
        for (k, limit) in problem.limits().iter().enumerate() {
            let Some(limit) = limit else { continue };
            let mut ones = vec![0.0; n];
            for j in model.involved(k) {
                ones[j] = 1.0;
            }
            let worst = model.worst_case(k, &ones)?.upper_bound();
            if worst > 0.0 {
                u = u.min(limit / worst);
            }
        }
        let ub: Vec<f64> = problem
            .lower_bounds_rad()
            .iter()
            .map(|&lb| u.max(lb))
            .collect();
        finish(
            problem,
            Allocator::<M>::name(self),
            Weights::inverse_average_sensitivity(model),
            ub,
            MethodDetails::External {
                description: format!("one bound for every error: {u:e} rad"),
            },
        )
    }
}

/// The reuse tutorial's code, compiled and run with the crates' default features (no `paper`).
#[cfg(doctest)]
#[doc = include_str!("../../../docs/tutorials/reuse-a-crate.md")]
pub struct ReuseTutorial;
