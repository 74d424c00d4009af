//! The seam every allocator is written over: [`LinearErrorModel`], a first-order model of
//! constrained quantities in the errors over a domain of points.

use crate::error::AllocError;
use nalgebra::DMatrix;
use std::f64::consts::{FRAC_PI_2, TAU};
use tt_kinematics::{LinearModel, OrientationAxis, Pose, WorstPose};

/// The worst point of a weighted coefficient sum $\sum_j w_j\,|c_{kj}(p)|$ (or, for a
/// method's own constraint family, the signed sum) over a model's domain.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WorstRow {
    /// The largest value found (unit of the weights: rad for error bounds).
    pub(crate) value: f64,
    /// A rigorous upper bound on the maximum (`value` when the search is exact).
    pub(crate) upper_bound: f64,
    /// Whether `value` is the exact maximum.
    pub(crate) exact: bool,
    /// The maximiser's coordinates (for a turntable: every joint angle, rad).
    pub(crate) point: Vec<f64>,
    /// A scalar label of the maximiser (for a turntable: the angle of its last free joint).
    pub(crate) tag: f64,
    /// The coefficients at the maximiser, one per error ($|c_{kj}(p)|$ for the worst case;
    /// the method's own row for a constraint search): the cut of the exchange method.
    pub(crate) row: Vec<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl WorstRow {
    /// Whether `value` is the exact maximum (else only `upper_bound` is rigorous).
    #[must_use]
    pub fn is_exact(&self) -> bool {
        self.exact
    }
}

impl WorstRow {
    /// The largest value found (unit of the weights: rad for error bounds).
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// A rigorous upper bound on the maximum (`value` when the search is exact).
    #[must_use]
    pub fn upper_bound(&self) -> f64 {
        self.upper_bound
    }

    /// The maximiser's coordinates (for a turntable: every joint angle, rad).
    #[must_use]
    pub fn point(&self) -> &[f64] {
        &self.point
    }

    /// A scalar label of the maximiser (for a turntable: the angle of its last free joint).
    #[must_use]
    pub fn tag(&self) -> f64 {
        self.tag
    }

    /// The coefficients at the maximiser, one per error ($|c_{kj}(p)|$ for the worst case;
    /// the method's own row for a constraint search): the cut of the exchange method.
    #[must_use]
    pub fn row(&self) -> &[f64] {
        &self.row
    }
}

impl WorstRow {
    /// The same row with the scalar label `tag` (for a turntable: the angle of its last free
    /// joint; a position index for a schedule's rows).
    #[must_use]
    pub fn with_tag(mut self, tag: f64) -> Self {
        self.tag = tag;
        self
    }

    /// An exact maximum `value` at `point` with coefficient row `row` (tag 0).
    #[must_use]
    pub fn exact(value: f64, point: Vec<f64>, row: Vec<f64>) -> Self {
        Self {
            value,
            upper_bound: value,
            exact: true,
            point,
            tag: 0.0,
            row,
        }
    }
}

/// A first-order model of constrained quantities $q_k$ (the three orientation angles of a
/// turntable; one per sensor output at the schedule positions end to end) in the errors
/// $\chi_j$ over a domain of points $p$ (poses in the joint ranges; schedule positions):
/// $q_k(p, \chi) = \sum_j c_{kj}(p)\,\chi_j$. Every allocator of this crate is written over it.
///
/// # Example: a model defined outside the crate
/// ```
/// use alloc_opt::{AllocationProblem, Allocator, EqualEffects, LinearErrorModel, WorstRow, AllocError};
/// use nalgebra::DMatrix;
///
/// /// q(p) = x0 + p x1 on p in {0, 0.5, 1}: one quantity, two errors.
/// struct Ramp;
/// impl LinearErrorModel for Ramp {
///     fn n_errors(&self) -> usize { 2 }
///     fn n_quantities(&self) -> usize { 1 }
///     fn quantity_name(&self, _k: usize) -> String { "q".into() }
///     fn error_name(&self, j: usize) -> String { ["x0", "x1"][j].into() }
///     fn worst_case(&self, _k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
///         // Σ w|c| is largest at p = 1, the end of the domain.
///         Ok(WorstRow::exact(w[0] + w[1], vec![1.0], vec![1.0, 1.0]))
///     }
///     fn average_abs_coefficients(&self) -> DMatrix<f64> {
///         DMatrix::from_row_slice(1, 2, &[1.0, 0.5])
///     }
/// }
/// let problem = AllocationProblem::with_limits(Ramp, vec![Some(1.0)], vec![0.0, 0.0])?;
/// let b = EqualEffects.allocate(&problem)?;
/// // Equal effects: each error takes half of the limit at p = 1.
/// assert!((b.upper_bounds_rad()[0] - 0.5).abs() < 1e-12);
/// assert!(b.certificate().lemma1_holds());
/// # Ok::<(), AllocError>(())
/// ```
pub trait LinearErrorModel {
    /// Number of errors $\chi_j$.
    fn n_errors(&self) -> usize;
    /// Number of constrained quantities $q_k$.
    fn n_quantities(&self) -> usize;
    /// The name of quantity `k` (`psi`, `theta`, `gamma` for a turntable).
    fn quantity_name(&self, k: usize) -> String;
    /// The name of error `j`.
    fn error_name(&self, j: usize) -> String;

    /// The rigorous worst case of quantity `k` over the domain for non-negative weights `w`
    /// (one per error): $\max_p \sum_j w_j |c_{kj}(p)|$ with an upper bound that is proven
    /// (the certificate and the safety shrink use it), its maximiser and $|c_k(p)|$ there.
    ///
    /// # Errors
    /// [`AllocError`] for weights of the wrong length, or when the model fails.
    fn worst_case(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError>;

    /// The mean over the domain of $|c_{kj}|$, a `n_quantities` × `n_errors` matrix (eq 28's
    /// sensitivities; the default weights are their inverses).
    fn average_abs_coefficients(&self) -> DMatrix<f64>;

    /// The errors quantity `k` depends on; default: those with a positive average
    /// coefficient.
    fn involved(&self, k: usize) -> Vec<usize> {
        let avg = self.average_abs_coefficients();
        (0..self.n_errors())
            .filter(|&j| avg[(k, j)] > 0.0)
            .collect()
    }

    /// The most loaded row of the constraint family a per-quantity method imposes on `k`
    /// at `w` (the exchange method's separation oracle; a search, need not be rigorous).
    /// Default: [`LinearErrorModel::worst_case`].
    ///
    /// # Errors
    /// As [`LinearErrorModel::worst_case`].
    fn search(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        self.worst_case(k, w)
    }

    /// Rows to start the exchange method from (a grid over the domain); default: none (the
    /// method starts from the search at equal weights).
    fn start_rows(&self, k: usize) -> Vec<WorstRow> {
        let _ = k;
        Vec::new()
    }
}

fn axis(k: usize) -> OrientationAxis {
    OrientationAxis::ALL[k]
}

/// Start-grid points per free joint: 17 for one free joint (the paper's), fewer for more.
fn start_points(free: usize) -> usize {
    match free {
        0 => 1,
        1 => 17,
        2 => 9,
        _ => 5,
    }
}

/// The row of a turntable's linear model at `pose` for quantity `k` ($|c|$ or signed), with
/// the tag of the last free joint.
fn turntable_row(model: &LinearModel, k: usize, pose: &[f64], abs: bool) -> (Vec<f64>, f64) {
    let c = Pose::new(pose.to_vec())
        .ok()
        .and_then(|p| model.coefficients(&p).ok());
    let row = (0..model.n_errors())
        .map(|i| {
            let v = c.as_ref().map_or(0.0, |c| c[(k, i)]);
            if abs { v.abs() } else { v }
        })
        .collect();
    (row, model.free_joints().last().map_or(0.0, |&j| pose[j]))
}

fn to_row(model: &LinearModel, k: usize, wp: WorstPose, abs: bool) -> WorstRow {
    let (row, tag) = turntable_row(model, k, wp.pose_rad(), abs);
    WorstRow {
        value: wp.value(),
        upper_bound: wp.upper_bound(),
        exact: wp.exact(),
        point: wp.pose_rad().to_vec(),
        tag,
        row,
    }
}

/// The grid of `per` points per joint over the joints `free` of `ranges` (the others at the
/// lower end of their range), the first free joint varying fastest. A joint's points include
/// both ends of its range, except over a full turn when `open_full_turns` (the end is the
/// start: `per` points, the end left out).
pub(crate) fn joint_grid<'a>(
    ranges: &'a [[f64; 2]],
    free: &'a [usize],
    per: usize,
    open_full_turns: bool,
) -> impl Iterator<Item = Vec<f64>> + 'a {
    let base: Vec<f64> = ranges.iter().map(|r| r[0]).collect();
    let total = per.pow(free.len() as u32);
    (0..total).map(move |cell| {
        let mut pose = base.clone();
        let mut rest = cell;
        for &j in free {
            let [lo, hi] = ranges[j];
            let k = (rest % per) as f64;
            rest /= per;
            pose[j] = if per == 1 {
                lo
            } else if open_full_turns && hi - lo >= TAU * (1.0 - 1e-12) {
                lo + (hi - lo) * k / per as f64
            } else {
                lo + (hi - lo) * k / (per - 1) as f64
            };
        }
        pose
    })
}

/// Start rows: a grid over the free joints' `ranges`.
fn turntable_grid(model: &LinearModel, k: usize, ranges: &[[f64; 2]], abs: bool) -> Vec<WorstRow> {
    let free = model.free_joints().to_vec();
    let per = start_points(free.len());
    joint_grid(ranges, &free, per, false)
        .map(|pose| {
            let (row, tag) = turntable_row(model, k, &pose, abs);
            WorstRow {
                value: f64::NAN,
                upper_bound: f64::NAN,
                exact: false,
                point: pose,
                tag,
                row,
            }
        })
        .collect()
}

/// A turntable's first-order model (eq 26 for the paper's table): the quantities are the
/// three angles $\psi, \theta, \gamma$, the domain every pose in the joint ranges. The worst
/// case is exact for at most one free joint and proven by branch and bound otherwise
/// ([`LinearModel::worst_pose_certified`]).
impl LinearErrorModel for LinearModel {
    fn n_errors(&self) -> usize {
        LinearModel::n_errors(self)
    }
    fn n_quantities(&self) -> usize {
        3
    }
    fn quantity_name(&self, k: usize) -> String {
        axis(k).name().to_string()
    }
    fn error_name(&self, j: usize) -> String {
        self.turntable().rotation_error_names()[j].to_string()
    }
    fn worst_case(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        let wp = self.worst_pose_certified(axis(k), w, true, None)?;
        Ok(to_row(self, k, wp, true))
    }
    fn average_abs_coefficients(&self) -> DMatrix<f64> {
        LinearModel::average_abs_coefficients(self)
    }
    fn involved(&self, k: usize) -> Vec<usize> {
        LinearModel::involved(self, axis(k))
    }
    fn search(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        let wp = self.max_abs_weighted(axis(k), w, None)?;
        Ok(to_row(self, k, wp, true))
    }
    fn start_rows(&self, k: usize) -> Vec<WorstRow> {
        turntable_grid(self, k, &self.turntable().joint_ranges_rad(), true)
    }
}

/// The paper's problems (31)-(33) as printed, as a model: the constraint of each angle is the
/// signed sum $\sum_i \chi_i c_{ki}(\phi_2) \le I_k$ over the quarter ranges of the single
/// free joint ($[0, \pi/2]$ for $\gamma$, $[3\pi/2, 2\pi]$ for $\psi$, the full turn for
/// $\theta$), while the worst case (certificate, safety) stays the full-range one of the
/// wrapped [`LinearModel`]. Built by [`crate::SensitivityWeighted::paper`] for a turntable
/// with exactly one free joint.
#[derive(Debug, Clone, Copy)]
pub(crate) struct QuarterRanges<'m> {
    model: &'m LinearModel,
    free: usize,
}

impl<'m> QuarterRanges<'m> {
    /// The wrapper, or the names of the free joints when there is not exactly one.
    pub(crate) fn new(model: &'m LinearModel) -> Result<Self, AllocError> {
        let [j] = model.free_joints() else {
            let names = model.turntable().joint_names();
            return Err(AllocError::QuarterRangesNeedOneFreeJoint {
                free_joints: model
                    .free_joints()
                    .iter()
                    .map(|&j| names[j].to_string())
                    .collect(),
            });
        };
        Ok(Self { model, free: *j })
    }

    pub(crate) fn ranges(&self, k: usize) -> Vec<[f64; 2]> {
        let mut ranges = self.model.turntable().joint_ranges_rad();
        ranges[self.free] = match axis(k) {
            OrientationAxis::Gamma => [0.0, FRAC_PI_2],
            OrientationAxis::Psi => [3.0 * FRAC_PI_2, TAU],
            OrientationAxis::Theta => [0.0, TAU],
        };
        ranges
    }
}

impl LinearErrorModel for QuarterRanges<'_> {
    fn n_errors(&self) -> usize {
        LinearModel::n_errors(self.model)
    }
    fn n_quantities(&self) -> usize {
        3
    }
    fn quantity_name(&self, k: usize) -> String {
        self.model.quantity_name(k)
    }
    fn error_name(&self, j: usize) -> String {
        self.model.error_name(j)
    }
    fn worst_case(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        LinearErrorModel::worst_case(self.model, k, w)
    }
    fn average_abs_coefficients(&self) -> DMatrix<f64> {
        LinearModel::average_abs_coefficients(self.model)
    }
    fn involved(&self, k: usize) -> Vec<usize> {
        LinearModel::involved(self.model, axis(k))
    }
    fn search(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        let wp = self
            .model
            .max_signed_weighted(axis(k), w, Some(&self.ranges(k)))?;
        Ok(to_row(self.model, k, wp, false))
    }
    fn start_rows(&self, k: usize) -> Vec<WorstRow> {
        turntable_grid(self.model, k, &self.ranges(k), false)
    }
}
