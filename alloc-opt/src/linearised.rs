//! Any orientation-error model's first-order model, derived from its exact orientation error:
//! [`Linearised`], a [`LinearErrorModel`] whose worst case comes with a proven upper bound, so
//! the allocators, their certificate and the exact-chain margin take any model written once.

use crate::error::AllocError;
use crate::model::{LinearErrorModel, WorstRow};
use nalgebra::DMatrix;
use std::f64::consts::TAU;
use tt_kinematics::{
    DERIVED_FIRST_ORDER_TOLERANCE, OrientationAxis, OrientationErrorModel, Pose, TurntableErrors,
};

/// Most poses of the grid a [`Linearised`] model tabulates its coefficients on (and scans
/// the torus of its joints with): $2^{15}$; per joint the largest multiple of 4 within it (a
/// full turn's grid then holds its quarter turns), 180 for two joints. Memory is
/// $(D + 3n)$ numbers per pose, 5 MB for the az/el example, bounded for any model.
pub const LINEARISED_MAX_POSES: usize = 32_768;

/// A model's first-order coefficients $c_{kj}(p)$ over the poses $p$ of its joint ranges, as a
/// [`LinearErrorModel`] (quantities $\psi, \theta, \gamma$; the model's own error names):
/// the coefficients are the model's [`OrientationErrorModel::first_order`] (derived from its
/// exact orientation error unless it supplies an analytic one, which the conformance suite
/// checks) on a grid of at most [`LINEARISED_MAX_POSES`] poses.
///
/// # The worst case and its proof
/// The worst case $\max_p\sum_j w_j|c_{kj}(p)|$ is the grid's largest value, with a proven
/// upper bound under the model's one assumption: each coefficient is a trigonometric
/// polynomial of degree at most $d$ (the joint harmonic degree, 1 by default) in each joint
/// angle. That holds for every rigid chain of rotations (each joint turns the later axes once:
/// degree 1) and for errors that vary with a joint as harmonics up to order $d$ (set it with
/// [`Linearised::with_joint_harmonic_degree`]). By Bernstein's inequality
/// $|\partial c_{kj}/\partial\phi_i| \le d\,G_{kj}$, $G_{kj} = \max|c_{kj}|$ over the full
/// turns of the moving joints, itself bounded from a grid over those turns of spacing $h'_i$:
/// $G \le (G_\text{grid} + 2\tau)/(1 - d\sum_i h'_i/2)$. A point of the domain lies within
/// $h_i/2$ of a grid point in each joint, so
/// $$\max_p \sum_j w_j|c_{kj}(p)| \le \text{grid value} + d\,\textstyle\sum_i \frac{h_i}{2}
///   \sum_j w_j G_{kj} + 2\tau\sum_j w_j,$$
/// with $\tau$ = [`DERIVED_FIRST_ORDER_TOLERANCE`] for the derivation's error (values within
/// $\tau$ of zero are snapped to zero, so structural zeros stay zero). The value is exact when no
/// joint moves; otherwise [`WorstRow::is_exact`] is false and the allocators shrink by the
/// bound's gap, as for a three-axis turntable.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearised<M> {
    model: M,
    ranges: Vec<[f64; 2]>,
    names: Vec<String>,
    degree: u32,
    /// Grid poses, `joints` numbers each.
    poses: Vec<f64>,
    /// $c_{kj}$ at every grid pose, `3 n` numbers each (row-major by quantity).
    coefficients: Vec<f64>,
    /// $\sum_i h_i/2$ over the moving joints of the domain grid.
    half_spacing: f64,
    /// $\sum_i h'_i/2$ of the torus grid.
    torus_half_spacing: f64,
    /// Grid maxima of $|c_{kj}|$ over the torus.
    torus_max: DMatrix<f64>,
    average: DMatrix<f64>,
}

/// One joint's grid: its points and their spacing (rad).
fn axis_points(lo: f64, hi: f64, per: usize) -> (Vec<f64>, f64) {
    if hi <= lo || per < 2 {
        return (vec![lo], 0.0);
    }
    if hi - lo >= TAU * (1.0 - 1e-12) {
        // a full turn: the end is the start
        let h = (hi - lo) / per as f64;
        ((0..per).map(|i| lo + h * i as f64).collect(), h)
    } else {
        let h = (hi - lo) / (per - 1) as f64;
        ((0..per).map(|i| lo + h * i as f64).collect(), h)
    }
}

/// Every pose of the product of `axes` (the first joint fastest), to `visit`.
fn for_each_pose(
    axes: &[Vec<f64>],
    mut visit: impl FnMut(&[f64]) -> Result<(), AllocError>,
) -> Result<(), AllocError> {
    let total: usize = axes.iter().map(Vec::len).product();
    let mut pose = vec![0.0; axes.len()];
    for cell in 0..total {
        let mut rest = cell;
        for (p, a) in pose.iter_mut().zip(axes) {
            *p = a[rest % a.len()];
            rest /= a.len();
        }
        visit(&pose)?;
    }
    Ok(())
}

impl<M: OrientationErrorModel> Linearised<M> {
    /// The first-order model of `model` over `joint_ranges_rad` (one `[lo, hi]` per joint;
    /// `lo == hi` holds a joint fixed), with joint harmonic degree 1.
    ///
    /// # Errors
    /// [`AllocError::Field`] naming `joint_ranges[j]` for a non-finite or reversed range;
    /// [`AllocError::Kinematics`] when the model rejects a pose of the ranges (or its own
    /// first order does not have its error count).
    pub fn new(model: M, joint_ranges_rad: Vec<[f64; 2]>) -> Result<Self, AllocError> {
        Self::build(model, joint_ranges_rad, 1)
    }

    /// The same model with joint harmonic degree `degree` (at least 1): for errors that vary
    /// with a joint as harmonics up to that order.
    ///
    /// # Errors
    /// As [`Linearised::new`]; [`AllocError::Field`] naming `joint_harmonic_degree` when the
    /// degree is 0 or the grid is too coarse for it.
    pub fn with_joint_harmonic_degree(self, degree: u32) -> Result<Self, AllocError> {
        if degree == 0 {
            return Err(tt_core::FieldError::NotPositive {
                field: "joint_harmonic_degree".into(),
                value: 0.0,
            }
            .into());
        }
        Self::build(self.model, self.ranges, degree)
    }

    fn build(model: M, ranges: Vec<[f64; 2]>, degree: u32) -> Result<Self, AllocError> {
        for (j, &[lo, hi]) in ranges.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(tt_core::FieldError::OutOfRange {
                    field: format!("joint_ranges[{j}]"),
                    value: if lo.is_finite() { hi } else { lo },
                    range: "finite, lower end at most the upper end".into(),
                }
                .into());
            }
        }
        let names = model.error_names();
        let n = names.len();
        let moving = ranges.iter().filter(|[lo, hi]| hi > lo).count();
        let per = if moving == 0 {
            1
        } else {
            let per = (LINEARISED_MAX_POSES as f64)
                .powf(1.0 / moving as f64)
                .floor() as usize;
            // a multiple of 4, so a full turn's grid holds its quarter turns
            if per >= 8 { per - per % 4 } else { per.max(2) }
        };
        let zero = TurntableErrors::zero(n, model.n_translation_errors());
        let first_order = |pose: &[f64]| -> Result<DMatrix<f64>, AllocError> {
            let c = model.first_order(&Pose::new(pose.to_vec())?, &zero)?;
            tt_core::length("first_order columns", n, c.ncols())?;
            Ok(c.map(|v| {
                if v.abs() <= DERIVED_FIRST_ORDER_TOLERANCE {
                    0.0
                } else {
                    v
                }
            }))
        };
        // the domain grid: every coefficient tabulated
        let (axes, spacing): (Vec<Vec<f64>>, Vec<f64>) = ranges
            .iter()
            .map(|&[lo, hi]| axis_points(lo, hi, per))
            .unzip();
        let mut poses = Vec::new();
        let mut coefficients = Vec::new();
        let mut sum = DMatrix::zeros(3, n);
        for_each_pose(&axes, |pose| {
            let c = first_order(pose)?;
            poses.extend_from_slice(pose);
            for k in 0..3 {
                for j in 0..n {
                    coefficients.push(c[(k, j)]);
                    sum[(k, j)] += c[(k, j)].abs();
                }
            }
            Ok(())
        })?;
        let count = (poses.len() / ranges.len().max(1)).max(1);
        // the torus of the moving joints: the maxima Bernstein's inequality needs
        let (torus, torus_spacing): (Vec<Vec<f64>>, Vec<f64>) = ranges
            .iter()
            .map(|&[lo, hi]| {
                if hi > lo {
                    axis_points(0.0, TAU, per)
                } else {
                    (vec![lo], 0.0)
                }
            })
            .unzip();
        let mut torus_max = DMatrix::zeros(3, n);
        for_each_pose(&torus, |pose| {
            let c = first_order(pose)?;
            torus_max.zip_apply(&c, |m: &mut f64, v: f64| *m = m.max(v.abs()));
            Ok(())
        })?;
        let half = |s: &[f64]| s.iter().sum::<f64>() / 2.0;
        let out = Self {
            model,
            names,
            degree,
            poses,
            coefficients,
            half_spacing: half(&spacing),
            torus_half_spacing: half(&torus_spacing),
            torus_max,
            average: sum / count as f64,
            ranges,
        };
        if out.bernstein_denominator() <= 0.0 {
            return Err(tt_core::FieldError::OutOfRange {
                field: "joint_harmonic_degree".into(),
                value: f64::from(degree),
                range: format!(
                    "below 2 / (sum of the grid spacings) = {} for {per} poses per joint",
                    1.0 / out.torus_half_spacing
                ),
            }
            .into());
        }
        Ok(out)
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The joint ranges (rad).
    #[must_use]
    pub fn joint_ranges_rad(&self) -> &[[f64; 2]] {
        &self.ranges
    }

    /// The joint harmonic degree $d$ the worst-case bound assumes.
    #[must_use]
    pub fn joint_harmonic_degree(&self) -> u32 {
        self.degree
    }

    fn bernstein_denominator(&self) -> f64 {
        1.0 - f64::from(self.degree) * self.torus_half_spacing
    }

    fn n_poses(&self) -> usize {
        self.coefficients.len() / (3 * self.names.len()).max(1)
    }

    fn coefficient(&self, pose: usize, k: usize, j: usize) -> f64 {
        let n = self.names.len();
        self.coefficients[pose * 3 * n + k * n + j]
    }

    fn pose(&self, pose: usize) -> &[f64] {
        let d = self.ranges.len();
        &self.poses[pose * d..(pose + 1) * d]
    }
}

impl<M: OrientationErrorModel> LinearErrorModel for Linearised<M> {
    fn n_errors(&self) -> usize {
        self.names.len()
    }
    fn n_quantities(&self) -> usize {
        3
    }
    fn quantity_name(&self, k: usize) -> String {
        OrientationAxis::ALL[k].name().to_string()
    }
    fn error_name(&self, j: usize) -> String {
        self.names[j].clone()
    }
    fn worst_case(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        let n = self.names.len();
        tt_core::length("weights", n, w.len())?;
        let mut best = (f64::NEG_INFINITY, 0);
        for p in 0..self.n_poses() {
            let v: f64 = (0..n).map(|j| w[j] * self.coefficient(p, k, j).abs()).sum();
            if v > best.0 {
                best = (v, p);
            }
        }
        let tau = DERIVED_FIRST_ORDER_TOLERANCE;
        let g: f64 = (0..n)
            .map(|j| w[j] * (self.torus_max[(k, j)] + 2.0 * tau))
            .sum::<f64>()
            / self.bernstein_denominator();
        let slack =
            f64::from(self.degree) * self.half_spacing * g + 2.0 * tau * w.iter().sum::<f64>();
        let point = self.pose(best.1).to_vec();
        let tag = self
            .ranges
            .iter()
            .rposition(|[lo, hi]| hi > lo)
            .map_or(0.0, |i| point[i]);
        Ok(WorstRow {
            value: best.0,
            upper_bound: best.0 + slack,
            exact: self.ranges.iter().all(|[lo, hi]| hi <= lo),
            row: (0..n)
                .map(|j| self.coefficient(best.1, k, j).abs())
                .collect(),
            point,
            tag,
        })
    }
    fn average_abs_coefficients(&self) -> DMatrix<f64> {
        self.average.clone()
    }
}
