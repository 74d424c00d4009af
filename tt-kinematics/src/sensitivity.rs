//! Sensitivities of the orientation error to the turntable errors (eq 28, Figure 8).
//!
//! $C_{k i} = |\partial f_k / \partial \chi_i|$ for $k \in \{\psi, \theta, \gamma\}$; the
//! paper averages them over the rotation angles and uses their inverses as allocation
//! weights (§4.2).

use crate::chain::exact_factors;
use crate::errors::{CHI_LEN, TurntableErrors};
use crate::linear::LinearModel;
use crate::pose::Pose;
use crate::rotation::{rot, skew};
use nalgebra::{Matrix3, SMatrix};
use std::f64::consts::TAU;

/// Analytic Jacobian of the exact chain's eq-24 read-out
/// $(\Delta R_{13}, \Delta R_{21}, \Delta R_{32})$ with respect to $\chi$, at any pose and any
/// (not only small) errors. Rows $\psi, \theta, \gamma$; columns in the order of eq 25.
///
/// # Formula
/// With $\mathbf R_t = F_1 \cdots F_{10}$ the ten elementary rotations of Table 3 and
/// $F_j = R_{a_j}(\chi_i)$,
/// $$\frac{\partial \Delta\mathbf R}{\partial \chi_i} = \mathbf R_d^T\, F_1\cdots F_j\,[e_{a_j}]_\times\, F_{j+1}\cdots F_{10}.$$
/// At $\chi = 0$ it equals the coefficients of eq 26 ([`LinearModel::paper_eq26`]).
#[must_use]
pub fn exact_jacobian(pose: &Pose, errors: &TurntableErrors) -> SMatrix<f64, 3, CHI_LEN> {
    let factors = exact_factors(pose, errors);
    let mats: Vec<Matrix3<f64>> = factors.iter().map(|f| rot(f.axis, f.angle_rad)).collect();
    let rd_t = (rot(crate::rotation::Axis::Y, pose.phi1_rad)
        * rot(crate::rotation::Axis::Z, pose.phi2_rad))
    .transpose();
    // prefix[j] = F_1 ... F_j (prefix[0] = I); suffix[j] = F_{j+1} ... F_10.
    let mut prefix = vec![Matrix3::identity(); mats.len() + 1];
    for j in 0..mats.len() {
        prefix[j + 1] = prefix[j] * mats[j];
    }
    let mut suffix = vec![Matrix3::identity(); mats.len() + 1];
    for j in (0..mats.len()).rev() {
        suffix[j] = mats[j] * suffix[j + 1];
    }
    let mut jac = SMatrix::zeros();
    for (j, f) in factors.iter().enumerate() {
        if let Some(c) = f.component {
            let d = rd_t * prefix[j + 1] * skew(&f.axis.unit()) * suffix[j + 1];
            jac[(0, c.index())] = d[(0, 2)];
            jac[(1, c.index())] = d[(1, 0)];
            jac[(2, c.index())] = d[(2, 1)];
        }
    }
    jac
}

/// Average sensitivities of a linear model over the rotation angles, in closed form
/// (Figure 8 for [`LinearModel::paper_eq26`]): see [`LinearModel::average_abs_coefficients`].
#[must_use]
pub fn average_sensitivity_closed_form(model: &LinearModel) -> SMatrix<f64, 3, CHI_LEN> {
    model.average_abs_coefficients()
}

/// Average of $|\partial f_k/\partial\chi_i|$ of the exact chain at $\chi = 0$ over a
/// midpoint grid of `n_phi1 x n_phi2` poses covering $[0, 2\pi)^2$: the numerical check of
/// Figure 8. The midpoint rule on these piecewise-smooth periodic integrands converges as
/// $O(n_{\phi_2}^{-2})$.
#[must_use]
pub fn average_sensitivity_numerical(n_phi1: usize, n_phi2: usize) -> SMatrix<f64, 3, CHI_LEN> {
    let n1 = n_phi1.max(1);
    let n2 = n_phi2.max(1);
    let mut sum: SMatrix<f64, 3, CHI_LEN> = SMatrix::zeros();
    for i in 0..n1 {
        let phi1 = TAU * (i as f64 + 0.5) / n1 as f64;
        for j in 0..n2 {
            let phi2 = TAU * (j as f64 + 0.5) / n2 as f64;
            let pose = Pose {
                phi1_rad: phi1,
                phi2_rad: phi2,
            };
            sum += exact_jacobian(&pose, &TurntableErrors::ZERO).abs();
        }
    }
    sum / (n1 * n2) as f64
}
