//! The first-order (linear) orientation-error model of any turntable, its worst case over the
//! poses (the quantity Lemma 1 bounds) and its average sensitivities (eq 28, Figure 8).
//!
//! # Formula
//! At $\chi = 0$, $\partial\Delta\mathbf R/\partial\chi_i = [\mathbf v_i]_\times$ with
//! $\mathbf v_i(\phi) = \mathbf S_j^T\hat e_j$, where $F_j$ is the factor of $\chi_i$, $\hat e_j$
//! its (signed) axis and $\mathbf S_j$ the nominal product of the factors after it. So to first
//! order $\Delta\mathbf R = I + [\boldsymbol\delta]_\times$ with
//! $\boldsymbol\delta = \sum_i \chi_i\mathbf v_i(\phi)$, and eq 24 reads
//! $$f_k(\phi, \chi) = \sum_i c_{ki}(\phi)\,\chi_i,\qquad (c_{\psi i}, c_{\theta i}, c_{\gamma i}) =
//! (v_{i,y}, v_{i,z}, v_{i,x}).$$
//! For the paper's Table 3 this is eq 26 (`paper::ClosedForm`).
//!
//! # Structure in the joint angles
//! $\mathbf S_j$ holds each later joint rotation once, so $c_{ki}$ is a first harmonic
//! $a\cos\phi + b\sin\phi + c$ in each free joint angle when the others are fixed. With one
//! free joint (every two-axis table whose outer joint comes first, like the paper's) the worst
//! case over the pose of a weighted coefficient sum is found exactly, piece by piece between
//! the zeros of the coefficients; with more, the last free joint is still solved exactly and
//! the others are searched on a grid refined by golden sections, and
//! [`LinearModel::worst_pose_certified`] adds a rigorous upper bound by branch and bound (a
//! second-order cell bound; the Lipschitz constant $\sum_i w_i$ as a fall-back,
//! $|\partial c_{ki}/\partial\phi| \le 1$ for a component of a rotating unit vector).

use crate::error::{KinematicsError, length};
use crate::pose::TurntableErrors;
use crate::rotation::{SignedAxis, rot_sc};
use crate::turntable::{Factor, Turntable};
use nalgebra::{DMatrix, Matrix3, Vector3};
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::sync::{Arc, Mutex, OnceLock};
use tt_core::Pose;
use tt_core::{OrientationAxis, OrientationError};

/// A coefficient whose magnitude is below this is a structural zero (unitless: coefficients
/// are components of unit vectors; rounding of a chain of a few rotations stays near
/// $10^{-16}$).
pub const STRUCTURAL_ZERO: f64 = 1e-12;

/// Grid points per outer free joint of the pose search (the total grid has at most about
/// 4096 points).
pub const POSE_GRID_POINTS: usize = 256;

/// Golden-section steps of the local refinement of an outer free joint (bracket shrinks by
/// $0.618^{60} \approx 3\times10^{-13}$ of a grid cell).
pub const POSE_REFINE_STEPS: usize = 60;

/// Relative gap at which [`LinearModel::worst_pose_certified`] stops.
pub const CERTIFY_REL_GAP: f64 = 1e-9;

/// Largest number of evaluations [`LinearModel::worst_pose_certified`] spends.
pub const CERTIFY_MAX_EVALUATIONS: usize = 200_000;

/// Midpoint points per outer free joint for average sensitivities with two or more free
/// joints (the last is integrated exactly); error $O(N^{-2})$.
pub const AVERAGE_GRID_POINTS: usize = 512;

/// The worst pose of a weighted coefficient sum and its value.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WorstPose {
    /// The largest value found (in the unit of the weights, radians for error bounds); it is
    /// reached at [`WorstPose::pose_rad`].
    pub(crate) value: f64,
    /// A pose (every joint, rad) where it is reached; joints that cancel sit at their range's
    /// lower end.
    pub(crate) pose_rad: Vec<f64>,
    /// A rigorous upper bound on the maximum: equal to `value` when the search is exact (at
    /// most one free joint), the branch-and-bound bound of
    /// [`LinearModel::worst_pose_certified`] otherwise, and `+inf` when not computed.
    pub(crate) upper_bound: f64,
    /// Whether `value` is the exact maximum (at most one free joint).
    pub(crate) exact: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl WorstPose {
    /// The largest value found (in the unit of the weights, radians for error bounds); it is
    /// reached at [`WorstPose::pose_rad`].
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// A pose (every joint, rad) where it is reached; joints that cancel sit at their range's
    /// lower end.
    #[must_use]
    pub fn pose_rad(&self) -> &[f64] {
        &self.pose_rad
    }

    /// A rigorous upper bound on the maximum: equal to `value` when the search is exact (at
    /// most one free joint), the branch-and-bound bound of
    /// [`LinearModel::worst_pose_certified`] otherwise, and `+inf` when not computed.
    #[must_use]
    pub fn upper_bound(&self) -> f64 {
        self.upper_bound
    }

    /// Whether `value` is the exact maximum (at most one free joint).
    #[must_use]
    pub fn exact(&self) -> bool {
        self.exact
    }
}

/// Grids of inner-joint harmonics a [`LinearModel`] keeps (one per axis and set of joint
/// ranges searched; the oldest is dropped beyond this).
const GRID_CACHE_ENTRIES: usize = 12;

/// The harmonic parts in the inner free joint at every point of the worst-pose search's grid
/// of outer joints, for one axis and set of ranges: they do not depend on the weights, so
/// every search of an allocation's cutting-plane loop shares them.
struct GridHarmonics {
    axis: usize,
    /// The ranges' bits (the grid's points and the other joints' angles follow from them).
    ranges: Vec<[u64; 2]>,
    harmonics: Arc<Vec<Vec<[f64; 3]>>>,
}

/// The first-order orientation-error model of a turntable (see the [module](self)).
pub struct LinearModel {
    turntable: Turntable,
    /// [`LinearModel::average_abs_coefficients`], computed on first use (a function of the
    /// turntable alone; every weighted allocation asks for it again).
    average: OnceLock<DMatrix<f64>>,
    /// The worst-pose search's grids ([`GridHarmonics`]), computed on first use.
    grids: Mutex<Vec<GridHarmonics>>,
}

impl Clone for LinearModel {
    fn clone(&self) -> Self {
        let grids = self.grids.lock().map_or_else(
            |_| Vec::new(),
            |g| {
                g.iter()
                    .map(|e| GridHarmonics {
                        axis: e.axis,
                        ranges: e.ranges.clone(),
                        harmonics: Arc::clone(&e.harmonics),
                    })
                    .collect()
            },
        );
        Self {
            turntable: self.turntable.clone(),
            average: self.average.clone(),
            grids: Mutex::new(grids),
        }
    }
}

// The cache is not part of the model: equality and `Debug` are the turntable's.
impl PartialEq for LinearModel {
    fn eq(&self, other: &Self) -> bool {
        self.turntable == other.turntable
    }
}

impl std::fmt::Debug for LinearModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinearModel")
            .field("turntable", &self.turntable)
            .finish()
    }
}

impl LinearModel {
    /// The linear model of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            turntable: turntable.clone(),
            average: OnceLock::new(),
            grids: Mutex::new(Vec::new()),
        }
    }

    /// The turntable.
    #[must_use]
    pub fn turntable(&self) -> &Turntable {
        &self.turntable
    }

    /// Number of angular errors (columns).
    #[must_use]
    pub fn n_errors(&self) -> usize {
        self.turntable.n_rotation_errors()
    }

    /// $\mathbf v_i$ of every error for joint angles given by their sines and cosines.
    fn vectors_sc(&self, sc: &[(f64, f64)]) -> Vec<Vector3<f64>> {
        let mut v = vec![Vector3::zeros(); self.n_errors()];
        self.walk_errors_sc(sc, |error, about, s| {
            v[error] = s.transpose() * about.unit()
        });
        v
    }

    /// The walk from the platform to the base over the factors: `at_error(error, about, s)`
    /// at each rotation error, $\mathbf S$ (`s`) the product of the joint and fixed rotations
    /// between it and the platform, the joint angles given by their sines and cosines `sc`.
    fn walk_errors_sc(
        &self,
        sc: &[(f64, f64)],
        mut at_error: impl FnMut(usize, SignedAxis, &Matrix3<f64>),
    ) {
        let mut s = Matrix3::identity();
        for f in self.turntable.factors().iter().rev() {
            match *f {
                Factor::Rotation { error, about } => at_error(error, about, &s),
                Factor::Joint { joint, about } => {
                    let (sj, cj) = sc[joint];
                    s = rot_sc(about.axis, about.sign() * sj, cj) * s;
                }
                Factor::Fixed { angle_rad, about } => {
                    s = crate::rotation::rot_signed(about, angle_rad) * s;
                }
                Factor::Translation { .. } => {}
            }
        }
    }

    /// The derivatives $\partial\mathbf v_i/\partial\phi_j$ of the rotation vectors with
    /// respect to joint `joint`: the same walk with $\mathbf S$ and $d\mathbf S$, where the
    /// joint's factor $R(\mathbf e, \phi)$ contributes $[\mathbf e]_\times R$.
    fn vector_derivatives_sc(&self, sc: &[(f64, f64)], joint_d: usize) -> Vec<Vector3<f64>> {
        let mut v = vec![Vector3::zeros(); self.n_errors()];
        let mut s = Matrix3::identity();
        let mut ds = Matrix3::zeros();
        for f in self.turntable.factors().iter().rev() {
            match *f {
                Factor::Rotation { error, about } => v[error] = ds.transpose() * about.unit(),
                Factor::Joint { joint, about } => {
                    let (sj, cj) = sc[joint];
                    let r = rot_sc(about.axis, about.sign() * sj, cj);
                    ds = r * ds;
                    if joint == joint_d {
                        ds += crate::rotation::skew(&about.unit()) * r * s;
                    }
                    s = r * s;
                }
                Factor::Fixed { angle_rad, about } => {
                    let r = crate::rotation::rot_signed(about, angle_rad);
                    s = r * s;
                    ds = r * ds;
                }
                Factor::Translation { .. } => {}
            }
        }
        v
    }

    /// The coefficients $c_{ki}$ (rows $\psi, \theta, \gamma$) for sines and cosines of the
    /// joint angles.
    fn coefficients_sc(&self, sc: &[(f64, f64)]) -> Vec<[f64; 3]> {
        self.vectors_sc(sc)
            .into_iter()
            .map(|v| [v.y, v.z, v.x])
            .collect()
    }

    fn sc_of(pose: &[f64]) -> Vec<(f64, f64)> {
        pose.iter().map(|a| a.sin_cos()).collect()
    }

    /// The 3 x n coefficient (Jacobian at $\chi = 0$) matrix at `pose`, rows
    /// $\psi, \theta, \gamma$.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a pose of the wrong length.
    pub fn coefficients(&self, pose: &Pose) -> Result<DMatrix<f64>, KinematicsError> {
        self.turntable.check_pose(pose)?;
        Ok(self.coefficients_unchecked(pose.angles_rad()))
    }

    pub(crate) fn coefficients_unchecked(&self, pose: &[f64]) -> DMatrix<f64> {
        let c = self.coefficients_sc(&Self::sc_of(pose));
        DMatrix::from_fn(3, c.len(), |k, i| c[i][k])
    }

    /// The rotation vectors $\mathbf v_i$ (x, y, z components) at `pose`: the first-order
    /// rotation vector of $\Delta\mathbf R$ is $\sum_i \chi_i\mathbf v_i$.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a pose of the wrong length.
    pub fn rotation_vectors(&self, pose: &Pose) -> Result<Vec<Vector3<f64>>, KinematicsError> {
        self.turntable.check_pose(pose)?;
        Ok(self.vectors_sc(&Self::sc_of(pose.angles_rad())))
    }

    /// $f(\phi, \chi)$ for all three angles.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn evaluate(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        self.turntable.check_pose(pose)?;
        self.turntable.check_errors(errors)?;
        let c = self.coefficients_sc(&Self::sc_of(pose.angles_rad()));
        let mut out = [0.0; 3];
        for (ci, x) in c.iter().zip(errors.chi_rad()) {
            for k in 0..3 {
                out[k] += ci[k] * x;
            }
        }
        Ok(OrientationError::from_array(out))
    }

    /// The free joints (see [`Turntable::free_joints`]).
    #[must_use]
    pub fn free_joints(&self) -> &[usize] {
        self.turntable.free_joints()
    }

    /// Sines and cosines of a pose where every free joint sits at a quarter turn
    /// `quarters[k]` (0, 1, 2 for 0, 90, 180 deg, given exactly) and the others at 0.
    fn quarter_sc(&self, quarters: &[usize]) -> Vec<(f64, f64)> {
        let mut sc = vec![(0.0, 1.0); self.turntable.n_joints()];
        for (&j, &q) in self.free_joints().iter().zip(quarters) {
            sc[j] = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0)][q];
        }
        sc
    }

    /// Whether coefficient $c_{ki}$ is identically zero. It is multi-affine in
    /// $(\cos\phi_j, \sin\phi_j)$ of the free joints, so it vanishes everywhere if and only if
    /// it vanishes on the $3^d$ quarter-turn points $\{0, 90°, 180°\}^d$.
    #[must_use]
    pub fn is_involved(&self, axis: OrientationAxis, error: usize) -> bool {
        let d = self.free_joints().len();
        let mut quarters = vec![0usize; d];
        loop {
            let c = self.coefficients_sc(&self.quarter_sc(&quarters));
            if c[error][axis.index()].abs() > STRUCTURAL_ZERO {
                return true;
            }
            // next point of {0,1,2}^d
            let mut k = 0;
            loop {
                if k == d {
                    return false;
                }
                quarters[k] += 1;
                if quarters[k] < 3 {
                    break;
                }
                quarters[k] = 0;
                k += 1;
            }
        }
    }

    /// The errors an angle depends on (coefficient not identically zero): $\chi_\psi$,
    /// $\chi_\theta$, $\chi_\gamma$ of eq 27 for the paper's table.
    #[must_use]
    pub fn involved(&self, axis: OrientationAxis) -> Vec<usize> {
        (0..self.n_errors())
            .filter(|&i| self.is_involved(axis, i))
            .collect()
    }

    /// The harmonic parts $(a_i, b_i, c_i)$ of the coefficients of `axis` in free joint `j`
    /// when the other joints have sines and cosines `sc`: $c_{ki}(\phi_j) = a_i\cos\phi_j +
    /// b_i\sin\phi_j + c_i$. Values below [`STRUCTURAL_ZERO`] are set to zero.
    fn harmonics_in(&self, axis: OrientationAxis, j: usize, sc: &[(f64, f64)]) -> Vec<[f64; 3]> {
        self.harmonics_of(axis, j, sc, None)
    }

    /// The harmonic parts in joint `j` of the coefficients of `axis` (`deriv: None`) or of
    /// their derivatives with respect to another joint (`Some(k)`, `k != j`): both are
    /// $a\cos\phi_j + b\sin\phi_j + c$ (every joint appears once in the chain).
    fn harmonics_of(
        &self,
        axis: OrientationAxis,
        j: usize,
        sc: &[(f64, f64)],
        deriv: Option<usize>,
    ) -> Vec<[f64; 3]> {
        let mut sc = sc.to_vec();
        let mut at = |s: f64, c: f64| {
            sc[j] = (s, c);
            match deriv {
                None => self.coefficients_sc(&sc),
                Some(k) => self
                    .vector_derivatives_sc(&sc, k)
                    .into_iter()
                    .map(|v| [v.y, v.z, v.x])
                    .collect(),
            }
        };
        let (f0, f90, f180) = (at(0.0, 1.0), at(1.0, 0.0), at(0.0, -1.0));
        let snap = |x: f64| if x.abs() < STRUCTURAL_ZERO { 0.0 } else { x };
        (0..self.n_errors())
            .map(|i| {
                let k = axis.index();
                let c = 0.5 * (f0[i][k] + f180[i][k]);
                let a = 0.5 * (f0[i][k] - f180[i][k]);
                let b = f90[i][k] - c;
                [snap(a), snap(b), snap(c)]
            })
            .collect()
    }

    /// For the paper's kind of table (one free joint): the harmonic parts $(a, b, c)$ of every
    /// coefficient of `axis` in that joint. `None` unless exactly one joint is free.
    #[must_use]
    pub fn single_joint_harmonics(&self, axis: OrientationAxis) -> Option<Vec<[f64; 3]>> {
        match self.free_joints() {
            [j] => Some(self.harmonics_in(axis, *j, &vec![(0.0, 1.0); self.turntable.n_joints()])),
            _ => None,
        }
    }

    fn ranges(&self, ranges: Option<&[[f64; 2]]>) -> Vec<[f64; 2]> {
        ranges.map_or_else(|| self.turntable.joint_ranges_rad(), <[[f64; 2]]>::to_vec)
    }

    /// $\max_\phi \sum_i w_i\,|c_{ki}(\phi)|$ over the joint ranges (the turntable's, or
    /// `ranges` per joint): with $w = \mathrm{UB}$ the worst case of $|f_k|$ over every
    /// $|\chi_i| \le \mathrm{UB}_i$ (signs chosen adversarially) and every pose, the quantity
    /// Lemma 1 bounds. Exact for at most one free joint; a grid-and-refine search otherwise
    /// (see the [module](self); [`LinearModel::worst_pose_certified`] adds a rigorous bound).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for weights or ranges of the wrong length.
    pub fn max_abs_weighted(
        &self,
        axis: OrientationAxis,
        weights: &[f64],
        ranges: Option<&[[f64; 2]]>,
    ) -> Result<WorstPose, KinematicsError> {
        self.search(axis, weights, true, ranges)
    }

    /// $\max_\phi \sum_i x_i\,c_{ki}(\phi)$ (no absolute values) over the joint ranges: the
    /// left side of the constraints of problems (31)-(33) as printed.
    ///
    /// # Errors
    /// As [`LinearModel::max_abs_weighted`].
    pub fn max_signed_weighted(
        &self,
        axis: OrientationAxis,
        x: &[f64],
        ranges: Option<&[[f64; 2]]>,
    ) -> Result<WorstPose, KinematicsError> {
        self.search(axis, x, false, ranges)
    }

    fn check_inputs(&self, w: &[f64], ranges: Option<&[[f64; 2]]>) -> Result<(), KinematicsError> {
        length("weights", self.n_errors(), w.len())?;
        if let Some(r) = ranges {
            length("ranges", self.turntable.n_joints(), r.len())?;
        }
        Ok(())
    }

    /// Component `k` (0, 1, 2 for $\psi, \theta, \gamma$) of every coefficient $c_{ki}$ for
    /// joint sines and cosines `sc`, written to `out` (length [`LinearModel::n_errors`]).
    ///
    /// The same walk as [`LinearModel::vectors_sc`], with the same products $\mathbf S$; of
    /// $\mathbf v_i = \mathbf S^T(\sigma\mathbf e_a)$ only the component needed is taken,
    /// $\sigma S_{ac}$ ($c$ = y, z, x for $\psi, \theta, \gamma$). The full product sums
    /// $\sigma S_{ac}$ (exact: $\sigma = \pm1$) and two products with a zero, so the values
    /// are bit for bit those of [`LinearModel::coefficients_sc`] except perhaps the sign of a
    /// zero, which [`LinearModel::inner_max`] snaps away (this runs for every point of the
    /// worst-pose search).
    fn axis_coefficients_into(&self, sc: &[(f64, f64)], k: usize, out: &mut [f64]) {
        out.fill(0.0);
        let c = [1, 2, 0][k];
        self.walk_errors_sc(sc, |error, about, s| {
            out[error] = about.sign() * s[(about.axis.index(), c)];
        });
    }

    /// Exact maximum over the last free joint for fixed other angles `pose`.
    ///
    /// The harmonic parts are those of [`LinearModel::harmonics_in`] (the same formula on the
    /// same values, bit for bit: $c = (f_0 + f_{180})/2$, $a = (f_0 - f_{180})/2$,
    /// $b = f_{90} - c$, each snapped at [`STRUCTURAL_ZERO`], which also makes every zero
    /// $+0$ whatever the signs of the zeros it came from), computed without the intermediate
    /// vectors.
    fn inner_max(
        &self,
        axis: OrientationAxis,
        w: &[f64],
        abs: bool,
        pose: &[f64],
        inner: usize,
        range: [f64; 2],
    ) -> (f64, f64) {
        let h = self.inner_harmonics(axis, pose, inner);
        max_harmonic_sum(&h, w, abs, range[0], range[1])
    }

    /// The harmonic parts of [`LinearModel::inner_max`] at `pose`.
    fn inner_harmonics(&self, axis: OrientationAxis, pose: &[f64], inner: usize) -> Vec<[f64; 3]> {
        let mut sc = Self::sc_of(pose);
        let n = self.n_errors();
        let k = axis.index();
        let mut f = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (q, (s, c)) in [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0)]
            .into_iter()
            .enumerate()
        {
            sc[inner] = (s, c);
            self.axis_coefficients_into(&sc, k, &mut f[q]);
        }
        let [f0, f90, f180] = &f;
        let snap = |x: f64| if x.abs() < STRUCTURAL_ZERO { 0.0 } else { x };
        (0..n)
            .map(|i| {
                let c = 0.5 * (f0[i] + f180[i]);
                let a = 0.5 * (f0[i] - f180[i]);
                let b = f90[i] - c;
                [snap(a), snap(b), snap(c)]
            })
            .collect()
    }

    /// The inner harmonics ([`LinearModel::inner_harmonics`]) at every grid point `flat` of
    /// `0..count` (`at_index` places the outer joints of `base`), kept per axis and ranges:
    /// the same values as computed at each point, so a search that uses them finds the same
    /// bits.
    #[allow(clippy::too_many_arguments)]
    fn grid_harmonics(
        &self,
        axis: OrientationAxis,
        ranges: &[[f64; 2]],
        base: &[f64],
        inner: usize,
        count: usize,
        at_index: &(dyn Fn(usize, &mut [f64]) + Sync),
    ) -> Arc<Vec<Vec<[f64; 3]>>> {
        let key: Vec<[u64; 2]> = ranges
            .iter()
            .map(|r| [r[0].to_bits(), r[1].to_bits()])
            .collect();
        let found = self.grids.lock().ok().and_then(|g| {
            g.iter()
                .find(|e| e.axis == axis.index() && e.ranges == key)
                .map(|e| Arc::clone(&e.harmonics))
        });
        if let Some(h) = found {
            return h;
        }
        let h: Arc<Vec<Vec<[f64; 3]>>> = Arc::new(
            (0..count)
                .into_par_iter()
                .map(|flat| {
                    let mut p = base.to_vec();
                    at_index(flat, &mut p);
                    self.inner_harmonics(axis, &p, inner)
                })
                .collect(),
        );
        // (a poisoned lock only costs the cache)
        if let Ok(mut g) = self.grids.lock() {
            if g.len() >= GRID_CACHE_ENTRIES {
                g.remove(0);
            }
            g.push(GridHarmonics {
                axis: axis.index(),
                ranges: key,
                harmonics: Arc::clone(&h),
            });
        }
        h
    }

    fn search(
        &self,
        axis: OrientationAxis,
        w: &[f64],
        abs: bool,
        ranges: Option<&[[f64; 2]]>,
    ) -> Result<WorstPose, KinematicsError> {
        self.search_with(axis, w, abs, ranges, false)
    }

    /// Inner maximum at `pose`: [`LinearModel::inner_max`], or with `long_way` the plain
    /// formula on [`LinearModel::harmonics_in`] (the tests check they agree bit for bit).
    #[allow(clippy::too_many_arguments)]
    fn inner_max_with(
        &self,
        axis: OrientationAxis,
        w: &[f64],
        abs: bool,
        pose: &[f64],
        inner: usize,
        range: [f64; 2],
        long_way: bool,
    ) -> (f64, f64) {
        if long_way {
            let h = self.harmonics_in(axis, inner, &Self::sc_of(pose));
            max_harmonic_sum(&h, w, abs, range[0], range[1])
        } else {
            self.inner_max(axis, w, abs, pose, inner, range)
        }
    }

    /// The search; `long_way` turns off the shortcuts (the allocation-free inner maximum, the
    /// reuse of the golden section's last two points and the stop after a sweep that changes
    /// nothing) so the tests can check they change no bit of the result.
    fn search_with(
        &self,
        axis: OrientationAxis,
        w: &[f64],
        abs: bool,
        ranges: Option<&[[f64; 2]]>,
        long_way: bool,
    ) -> Result<WorstPose, KinematicsError> {
        self.check_inputs(w, ranges)?;
        let ranges = self.ranges(ranges);
        let mut pose: Vec<f64> = ranges.iter().map(|r| r[0]).collect();
        let free = self.free_joints().to_vec();
        let Some((&inner, outer)) = free.split_last() else {
            let c = self.coefficients_sc(&Self::sc_of(&pose));
            let v = weighted(&c, w, abs, axis);
            return Ok(WorstPose {
                value: v,
                pose_rad: pose,
                upper_bound: v,
                exact: true,
            });
        };
        if outer.is_empty() {
            let (v, phi) = self.inner_max_with(axis, w, abs, &pose, inner, ranges[inner], long_way);
            pose[inner] = phi;
            return Ok(WorstPose {
                value: v,
                pose_rad: pose,
                upper_bound: v,
                exact: true,
            });
        }
        // Grid over the outer free joints, the first outer joint fastest; the points are
        // independent, so they are evaluated in parallel and kept in grid order (the same
        // list, sort and winner as one by one, for any thread count).
        let per = grid_points_per_joint(outer.len());
        let count = (0..outer.len()).fold(1usize, |c, _| c * per);
        let at_index = |mut flat: usize, pose: &mut [f64]| {
            for &j in outer {
                let [lo, hi] = ranges[j];
                pose[j] = lo + (hi - lo) * ((flat % per) as f64 + 0.5) / per as f64;
                flat /= per;
            }
        };
        // the grid's harmonics do not depend on the weights: shared by every search
        let grid =
            (!long_way).then(|| self.grid_harmonics(axis, &ranges, &pose, inner, count, &at_index));
        let mut best: Vec<(f64, Vec<f64>)> = (0..count)
            .into_par_iter()
            .map(|flat| {
                let mut p = pose.clone();
                at_index(flat, &mut p);
                let (v, phi) = match &grid {
                    Some(h) => {
                        let [lo, hi] = ranges[inner];
                        max_harmonic_sum(&h[flat], w, abs, lo, hi)
                    }
                    None => self.inner_max_with(axis, w, abs, &p, inner, ranges[inner], long_way),
                };
                p[inner] = phi;
                (v, p)
            })
            .collect();
        best.sort_by(|a, b| b.0.total_cmp(&a.0));
        best.truncate(4);
        // the last grid point: the pose kept should no candidate give a value
        at_index(count - 1, &mut pose);
        let refined: Vec<(f64, Vec<f64>)> = best
            .into_par_iter()
            .map(|(v0, p0)| self.refine(axis, w, abs, &ranges, outer, inner, v0, p0, per, long_way))
            .collect();
        let mut winner = (f64::NEG_INFINITY, pose.clone());
        for (v, p) in refined {
            if v > winner.0 {
                winner = (v, p);
            }
        }
        Ok(WorstPose {
            value: winner.0,
            pose_rad: winner.1,
            upper_bound: f64::INFINITY,
            exact: false,
        })
    }

    /// Coordinate-wise golden-section refinement of the outer joints within one grid cell.
    #[allow(clippy::too_many_arguments)]
    fn refine(
        &self,
        axis: OrientationAxis,
        w: &[f64],
        abs: bool,
        ranges: &[[f64; 2]],
        outer: &[usize],
        inner: usize,
        v0: f64,
        p0: Vec<f64>,
        per: usize,
        long_way: bool,
    ) -> (f64, Vec<f64>) {
        let mut best = (v0, p0);
        let eval = |p: &[f64]| -> (f64, f64) {
            self.inner_max_with(axis, w, abs, p, inner, ranges[inner], long_way)
        };
        for _sweep in 0..3 {
            // A sweep is a function of `best` alone (value and pose; the inner joint's entry
            // is overwritten by every evaluation), so a sweep that leaves `best` bit for bit
            // unchanged would be repeated identically by every later one: stop there.
            let before = (
                best.0.to_bits(),
                best.1.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            );
            for &j in outer {
                let [rlo, rhi] = ranges[j];
                let cell = (rhi - rlo) / per as f64;
                let (mut lo, mut hi) = ((best.1[j] - cell).max(rlo), (best.1[j] + cell).min(rhi));
                let g = (5f64.sqrt() - 1.0) / 2.0;
                let mut p = best.1.clone();
                let at = |x: f64, p: &mut Vec<f64>| {
                    p[j] = x;
                    eval(p)
                };
                // (value, inner angle) at x1 and x2: the final candidates reuse them instead of
                // evaluating the same points again
                let mut x1 = hi - g * (hi - lo);
                let mut x2 = lo + g * (hi - lo);
                let mut f1 = at(x1, &mut p);
                let mut f2 = at(x2, &mut p);
                for _ in 0..POSE_REFINE_STEPS {
                    if f1.0 < f2.0 {
                        lo = x1;
                        x1 = x2;
                        f1 = f2;
                        x2 = lo + g * (hi - lo);
                        f2 = at(x2, &mut p);
                    } else {
                        hi = x2;
                        x2 = x1;
                        f2 = f1;
                        x1 = hi - g * (hi - lo);
                        f1 = at(x1, &mut p);
                    }
                }
                let mid = 0.5 * (lo + hi);
                if long_way {
                    f1 = at(x1, &mut p);
                    f2 = at(x2, &mut p);
                }
                let fm = at(mid, &mut p);
                for (x, (v, phi)) in [(x1, f1), (x2, f2), (mid, fm)] {
                    if v > best.0 {
                        let mut q = p.clone();
                        q[j] = x;
                        q[inner] = phi;
                        best = (v, q);
                    }
                }
            }
            let unchanged = best.0.to_bits() == before.0
                && best
                    .1
                    .iter()
                    .map(|x| x.to_bits())
                    .eq(before.1.iter().copied());
            if unchanged && !long_way {
                break;
            }
        }
        best
    }

    /// [`LinearModel::max_abs_weighted`] (or the signed form) with a rigorous upper bound:
    /// branch and bound over the outer free joints until the bound is within
    /// [`CERTIFY_REL_GAP`] of the best value found or [`CERTIFY_MAX_EVALUATIONS`] cells have
    /// been evaluated. Exact searches return their value as the bound.
    ///
    /// # Cell bound
    /// For the cell $\mathbf c \pm \mathbf h$ of the outer joints, each coefficient is
    /// $c_i(\mathbf c + \mathbf d, \phi) = c_i + \nabla c_i\cdot\mathbf d + r_i$ with
    /// $|r_i| \le \tfrac12(\sum_k |d_k|)^2$ (second derivatives of a rotated unit vector's
    /// components are at most 1). With non-negative weights (or the signed sum) the linear
    /// part's weighted sum is convex in $\mathbf d$, so its maximum over the cell is at one of
    /// the $2^m$ corners, and at each corner it is again a first harmonic in the inner joint,
    /// maximised exactly. The bound is that maximum plus $\tfrac12 L(\sum_k h_k)^2$, or the
    /// Lipschitz bound $v(\mathbf c) + L\sum_k h_k$ ($L = \sum_i |w_i|$) when smaller: the
    /// excess over the true maximum shrinks quadratically near a smooth maximiser, so the
    /// target gap is reached in a few thousand cells instead of exhausting the budget.
    ///
    /// # Errors
    /// As [`LinearModel::max_abs_weighted`].
    pub fn worst_pose_certified(
        &self,
        axis: OrientationAxis,
        weights: &[f64],
        abs: bool,
        ranges: Option<&[[f64; 2]]>,
    ) -> Result<WorstPose, KinematicsError> {
        let mut found = self.search(axis, weights, abs, ranges)?;
        if found.exact {
            return Ok(found);
        }
        let ranges = self.ranges(ranges);
        let free = self.free_joints().to_vec();
        let (&inner, outer) = free
            .split_last()
            .unwrap_or_else(|| unreachable!("inexact searches have free joints"));
        let lipschitz: f64 = weights.iter().map(|w| w.abs()).sum();
        // The second-order bound needs a sum that is convex in the outer angles' step.
        let quadratic = !abs || weights.iter().all(|w| *w >= 0.0);
        let base = found.pose_rad.clone();
        let mut heap: std::collections::BinaryHeap<Cell> = std::collections::BinaryHeap::new();
        let evaluate = |centre: Vec<f64>, half: Vec<f64>, found: &mut WorstPose| -> Cell {
            let mut p = base.clone();
            for (k, &j) in outer.iter().enumerate() {
                p[j] = centre[k];
            }
            let sc = Self::sc_of(&p);
            let h = self.harmonics_of(axis, inner, &sc, None);
            let [lo, hi] = ranges[inner];
            let (v, phi) = max_harmonic_sum(&h, weights, abs, lo, hi);
            if v > found.value {
                p[inner] = phi;
                found.value = v;
                found.pose_rad = p;
            }
            let l1: f64 = half.iter().sum();
            let mut bound = v + lipschitz * l1;
            if quadratic {
                // g(c + d) = g(c) + grad g(c) d + r, |r| <= (sum |d_k|)^2 / 2 for every
                // coefficient (a unit vector rotated by joint rotations: second derivatives of
                // norm <= 1); the linear part's weighted sum is convex in d, so its maximum over
                // the cell is at a vertex, and for each vertex it is harmonic in the inner joint.
                let grads: Vec<Vec<[f64; 3]>> = outer
                    .iter()
                    .map(|&j| self.harmonics_of(axis, inner, &sc, Some(j)))
                    .collect();
                let mut vertex_max = f64::NEG_INFINITY;
                let mut hv = h.clone();
                for corner in 0..(1_usize << outer.len()) {
                    for (i, hi_) in hv.iter_mut().enumerate() {
                        *hi_ = h[i];
                        for (k, g) in grads.iter().enumerate() {
                            let d = if corner >> k & 1 == 1 {
                                half[k]
                            } else {
                                -half[k]
                            };
                            for m in 0..3 {
                                hi_[m] += d * g[i][m];
                            }
                        }
                    }
                    vertex_max = vertex_max.max(max_harmonic_sum(&hv, weights, abs, lo, hi).0);
                }
                bound = bound.min(vertex_max + 0.5 * lipschitz * l1 * l1);
            }
            Cell {
                bound,
                centre,
                half,
            }
        };
        let centre: Vec<f64> = outer
            .iter()
            .map(|&j| 0.5 * (ranges[j][0] + ranges[j][1]))
            .collect();
        let half: Vec<f64> = outer
            .iter()
            .map(|&j| 0.5 * (ranges[j][1] - ranges[j][0]))
            .collect();
        heap.push(evaluate(centre, half, &mut found));
        let mut evaluations = 1;
        let bound = loop {
            let Some(top) = heap.pop() else {
                break found.value;
            };
            let tol = CERTIFY_REL_GAP * found.value.abs().max(f64::MIN_POSITIVE);
            if top.bound <= found.value + tol || evaluations >= CERTIFY_MAX_EVALUATIONS {
                break top.bound.max(found.value);
            }
            // split the widest dimension in two
            let d = top
                .half
                .iter()
                .enumerate()
                .fold((0, 0.0), |b, (i, &h)| if h > b.1 { (i, h) } else { b })
                .0;
            for side in [-1.0, 1.0] {
                let mut c = top.centre.clone();
                let mut h = top.half.clone();
                h[d] *= 0.5;
                c[d] += side * h[d];
                let cell = evaluate(c, h, &mut found);
                evaluations += 1;
                if cell.bound > found.value {
                    heap.push(cell);
                }
            }
        };
        found.upper_bound = bound;
        Ok(found)
    }

    /// Average of $|c_{ki}|$ over the free joints' ranges (uniformly; joints that cancel do
    /// not matter): the sensitivities of eq 28 averaged over the rotation angles, the data of
    /// Figure 8. Rows $\psi, \theta, \gamma$.
    ///
    /// # Formula
    /// Per coefficient, exactly over the last free joint: $\int |a\cos\phi + b\sin\phi + c|$
    /// piece by piece between the zeros, with the antiderivative $a\sin\phi - b\cos\phi +
    /// c\phi$. Over a full turn this is $|c|$ if $|c| \ge R = \sqrt{a^2+b^2}$ and
    /// $\tfrac{2}{\pi}(\sqrt{R^2-c^2} + c\arcsin(c/R))$ otherwise: $2/\pi$ for every
    /// $\sin\phi_2$/$\cos\phi_2$ term of eq 26 and 1 for a constant. Other free joints: the
    /// midpoint rule with [`AVERAGE_GRID_POINTS`] points each.
    ///
    /// Computed once per model (the same matrix, bit for bit, on every later call).
    #[must_use]
    pub fn average_abs_coefficients(&self) -> DMatrix<f64> {
        self.average
            .get_or_init(|| self.average_abs_coefficients_uncached())
            .clone()
    }

    fn average_abs_coefficients_uncached(&self) -> DMatrix<f64> {
        let ranges = self.turntable.joint_ranges_rad();
        let n = self.n_errors();
        let mut out = DMatrix::zeros(3, n);
        let base: Vec<f64> = ranges.iter().map(|r| r[0]).collect();
        let free = self.free_joints().to_vec();
        let Some((&inner, outer)) = free.split_last() else {
            let c = self.coefficients_sc(&Self::sc_of(&base));
            for i in 0..n {
                for k in 0..3 {
                    out[(k, i)] = c[i][k].abs();
                }
            }
            return out;
        };
        let per = if outer.is_empty() {
            1
        } else {
            AVERAGE_GRID_POINTS
        };
        let cells = per.pow(outer.len() as u32);
        let mut pose = base;
        for cell in 0..cells {
            let mut rest = cell;
            for &j in outer {
                let [lo, hi] = ranges[j];
                pose[j] = lo + (hi - lo) * ((rest % per) as f64 + 0.5) / per as f64;
                rest /= per;
            }
            let sc = Self::sc_of(&pose);
            for axis in OrientationAxis::ALL {
                let h = self.harmonics_in(axis, inner, &sc);
                let [lo, hi] = ranges[inner];
                for (i, hi_) in h.iter().enumerate() {
                    out[(axis.index(), i)] += mean_abs_harmonic(*hi_, lo, hi);
                }
            }
        }
        out / cells as f64
    }
}

/// A cell of the branch and bound: its bound, centre and half-widths (outer joints).
struct Cell {
    bound: f64,
    centre: Vec<f64>,
    half: Vec<f64>,
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.bound.total_cmp(&other.bound).is_eq()
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Cell {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.bound.total_cmp(&other.bound)
    }
}

fn grid_points_per_joint(outer: usize) -> usize {
    match outer {
        0 | 1 => POSE_GRID_POINTS,
        2 => 64,
        3 => 16,
        _ => 8,
    }
}

fn weighted(c: &[[f64; 3]], w: &[f64], abs: bool, axis: OrientationAxis) -> f64 {
    c.iter()
        .zip(w)
        .map(|(ci, wi)| {
            let v = ci[axis.index()];
            wi * if abs { v.abs() } else { v }
        })
        .sum()
}

/// Push every `base + 2 pi k` that lies in `[lo, hi]`.
fn push_periodic(out: &mut Vec<f64>, base: f64, lo: f64, hi: f64) {
    let k0 = ((lo - base) / TAU).ceil();
    let mut phi = base + k0 * TAU;
    while phi <= hi {
        if phi >= lo {
            out.push(phi);
        }
        phi += TAU;
    }
}

/// $\max_{\phi \in [lo, hi]} \sum_i w_i\,g_i(\phi)$ (or of $|g_i|$), $g_i = a_i\cos\phi +
/// b_i\sin\phi + c_i$, found exactly: the sum is a sinusoid plus a constant between the zero
/// crossings of the $g_i$, so its maximum is at a crossing, an end of the range, or a
/// stationary point $\operatorname{atan2}(B, A)$ of one piece.
#[must_use]
pub fn max_harmonic_sum(h: &[[f64; 3]], w: &[f64], abs: bool, lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let value = |phi: f64| -> f64 {
        let (s, c) = phi.sin_cos();
        h.iter()
            .zip(w)
            .map(|([a, b, k], wi)| {
                let v = a * c + b * s + k;
                wi * if abs { v.abs() } else { v }
            })
            .sum()
    };
    let mut cuts = vec![lo, hi];
    if abs {
        for ([a, b, k], wi) in h.iter().zip(w) {
            let r = a.hypot(*b);
            if *wi == 0.0 || r == 0.0 || k.abs() > r {
                continue;
            }
            let delta = b.atan2(*a);
            let half = (-k / r).clamp(-1.0, 1.0).acos();
            for base in [delta + half, delta - half] {
                push_periodic(&mut cuts, base, lo, hi);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    let mut best = (f64::NEG_INFINITY, lo);
    let mut consider = |phi: f64| {
        let v = value(phi);
        if v > best.0 {
            best = (v, phi);
        }
    };
    let mut stationary = Vec::new();
    for (window, pair) in cuts.windows(2).enumerate() {
        let (p, q) = (pair[0], pair[1]);
        // a later window's p is the previous window's q: considered already, with the same
        // value (so considering it again changes nothing)
        if window == 0 {
            consider(p);
        }
        consider(q);
        if q <= p {
            continue;
        }
        let mid = 0.5 * (p + q);
        let (sm, cm) = mid.sin_cos();
        let (mut big_a, mut big_b) = (0.0, 0.0);
        for ([a, b, k], wi) in h.iter().zip(w) {
            let s = if abs {
                (a * cm + b * sm + k).signum()
            } else {
                1.0
            };
            big_a += s * wi * a;
            big_b += s * wi * b;
        }
        if big_a != 0.0 || big_b != 0.0 {
            stationary.clear();
            push_periodic(&mut stationary, big_b.atan2(big_a), p, q);
            for &phi in &stationary {
                consider(phi);
            }
        }
    }
    best
}

/// Mean of $|a\cos\phi + b\sin\phi + c|$ over $[lo, hi]$, exactly (see
/// [`LinearModel::average_abs_coefficients`]).
#[must_use]
pub fn mean_abs_harmonic([a, b, c]: [f64; 3], lo: f64, hi: f64) -> f64 {
    let anti = |phi: f64| a * phi.sin() - b * phi.cos() + c * phi;
    let r = a.hypot(b);
    let mut cuts = vec![lo, hi];
    if r > 0.0 && c.abs() < r {
        let delta = b.atan2(a);
        let half = (-c / r).clamp(-1.0, 1.0).acos();
        for base in [delta + half, delta - half] {
            push_periodic(&mut cuts, base, lo, hi);
        }
    }
    cuts.sort_by(f64::total_cmp);
    let total: f64 = cuts
        .windows(2)
        .map(|p| (anti(p[1]) - anti(p[0])).abs())
        .sum();
    if hi > lo {
        total / (hi - lo)
    } else {
        (a * lo.cos() + b * lo.sin() + c).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of the rotation vectors: truncation $h^2/6 \approx 2\cdot10^{-11}$
    /// (third derivatives of norm <= 1), rounding $10^{-16}/h = 10^{-11}$.
    const FD_ABS: f64 = 1e-9;

    /// A four-joint chain (more outer free joints than the three-axis table), two errors after
    /// each joint but the second and a fixed 7 deg tilt about z between the second and third.
    fn four_joint_chain() -> Turntable {
        use crate::{FactorSpec, SignedAxis, TurntableDescription};
        let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
        let j = FactorSpec::joint;
        let e = FactorSpec::error;
        Turntable::new(&TurntableDescription::new(vec![
            j("a", z),
            e("ea", x),
            e("ea2", y),
            j("b", x),
            e("eb", z),
            FactorSpec::Fixed {
                angle_rad: 7f64.to_radians(),
                about: z,
            },
            j("c", y),
            e("ec", x),
            e("ec2", z),
            j("d", z),
            e("ed", y),
            e("ed2", x),
        ]))
        .unwrap()
    }

    /// The analytic derivatives of the rotation vectors with respect to every joint (the
    /// gradient terms of the branch and bound's second-order cell bound) equal central
    /// differences, on the three-axis conformance table and a four-joint chain with a fixed
    /// tilt, at scattered poses.
    #[test]
    fn vector_derivatives_equal_central_differences() {
        for t in [crate::conformance::three_axis(), four_joint_chain()] {
            let m = LinearModel::new(&t);
            let h = 1e-5;
            for k in 0..20 {
                let pose: Vec<f64> = (0..t.n_joints())
                    .map(|j| 0.37 * (k * 3 + j) as f64 + 0.1)
                    .collect();
                for j in 0..t.n_joints() {
                    let d = m.vector_derivatives_sc(&LinearModel::sc_of(&pose), j);
                    let mut plus = pose.clone();
                    plus[j] += h;
                    let mut minus = pose.clone();
                    minus[j] -= h;
                    let (vp, vm) = (
                        m.vectors_sc(&LinearModel::sc_of(&plus)),
                        m.vectors_sc(&LinearModel::sc_of(&minus)),
                    );
                    for i in 0..m.n_errors() {
                        let fd = (vp[i] - vm[i]) / (2.0 * h);
                        assert!(
                            (fd - d[i]).amax() < FD_ABS,
                            "joint {j} error {i}: {fd} vs {}",
                            d[i]
                        );
                    }
                }
            }
        }
    }

    /// The search's shortcuts (the allocation-free inner maximum, the reuse of the golden
    /// section's last two points, the stop after a refinement sweep that changes nothing) give
    /// bit for bit the result of the long way, on the three-axis conformance table and a
    /// four-joint chain (more outer free joints), for absolute and signed sums, mixed weights
    /// and partial ranges.
    #[test]
    fn search_shortcuts_equal_the_long_way() {
        for t in [crate::conformance::three_axis(), four_joint_chain()] {
            let m = LinearModel::new(&t);
            let n = m.n_errors();
            let full = t.joint_ranges_rad();
            let part: Vec<[f64; 2]> = (0..t.n_joints())
                .map(|k| [-0.3 - 0.1 * k as f64, 1.1 + 0.2 * k as f64])
                .collect();
            for case in 0..6 {
                let w: Vec<f64> = (0..n)
                    .map(|i| {
                        let v = 1e-4 * (1.0 + ((i * 7 + case * 3) % 5) as f64);
                        if case % 3 == 2 && i % 4 == 1 { -v } else { v }
                    })
                    .collect();
                for axis in OrientationAxis::ALL {
                    for abs in [true, false] {
                        for ranges in [None, Some(part.as_slice())] {
                            let short = m.search_with(axis, &w, abs, ranges, false).unwrap();
                            let long = m.search_with(axis, &w, abs, ranges, true).unwrap();
                            assert_eq!(short.value.to_bits(), long.value.to_bits());
                            assert_eq!(short.exact, long.exact);
                            assert!(
                                short
                                    .pose_rad
                                    .iter()
                                    .zip(&long.pose_rad)
                                    .all(|(a, b)| a.to_bits() == b.to_bits())
                            );
                            // the inner maximum itself, at scattered poses
                            let free = m.free_joints().to_vec();
                            let Some(&inner) = free.last() else { continue };
                            let r = ranges.map_or(full[inner], |r| r[inner]);
                            for k in 0..5 {
                                let pose: Vec<f64> = (0..t.n_joints())
                                    .map(|q| 0.41 * (k * 3 + q + case) as f64 - 1.0)
                                    .collect();
                                let a = m.inner_max_with(axis, &w, abs, &pose, inner, r, false);
                                let b = m.inner_max_with(axis, &w, abs, &pose, inner, r, true);
                                assert_eq!(a.0.to_bits(), b.0.to_bits());
                                assert_eq!(a.1.to_bits(), b.1.to_bits());
                            }
                        }
                    }
                }
            }
        }
    }

    /// The cached average sensitivities are those computed afresh, bit for bit, on every call
    /// and on clones.
    #[test]
    fn cached_average_equals_a_fresh_computation() {
        let m = LinearModel::new(&crate::conformance::three_axis());
        let fresh = m.average_abs_coefficients_uncached();
        let bits = |a: &DMatrix<f64>| a.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for a in [
            m.average_abs_coefficients(),
            m.average_abs_coefficients(),
            m.clone().average_abs_coefficients(),
        ] {
            assert_eq!(bits(&a), bits(&fresh));
        }
    }
}
