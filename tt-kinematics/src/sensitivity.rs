//! Sensitivities of the orientation error to the turntable errors (eq 28, Figure 8).
//!
//! $C_{k i} = |\partial f_k / \partial \chi_i|$ for $k \in \{\psi, \theta, \gamma\}$; the
//! paper averages them over the rotation angles and uses their inverses as allocation
//! weights (§4.2). The analytic Jacobian of the exact chain is [`crate::Turntable::jacobian`];
//! the closed-form averages are [`crate::LinearModel::average_abs_coefficients`].

use crate::turntable::Turntable;
use nalgebra::DMatrix;

/// Average of $|\partial f_k/\partial\chi_i|$ of the exact chain at $\chi = 0$ over a midpoint
/// grid of `points` values per free joint covering each joint's range: the numerical check of
/// Figure 8 (rows $\psi, \theta, \gamma$). The midpoint rule on these piecewise-smooth
/// integrands converges as $O(\text{points}^{-2})$.
#[must_use]
pub fn average_sensitivity_numerical(turntable: &Turntable, points: usize) -> DMatrix<f64> {
    let n = points.max(1);
    let free = turntable.free_joints().to_vec();
    let ranges = turntable.joint_ranges_rad();
    let mut pose: Vec<f64> = ranges.iter().map(|r| r[0]).collect();
    let zero = vec![0.0; turntable.n_rotation_errors()];
    let cells = n.pow(free.len() as u32);
    let mut sum = DMatrix::zeros(3, turntable.n_rotation_errors());
    for cell in 0..cells {
        let mut rest = cell;
        for &j in &free {
            let [lo, hi] = ranges[j];
            pose[j] = lo + (hi - lo) * ((rest % n) as f64 + 0.5) / n as f64;
            rest /= n;
        }
        sum += turntable.jacobian_unchecked(&pose, &zero).abs();
    }
    sum / cells as f64
}
