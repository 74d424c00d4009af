//! How an allocation that is tight on the linear model fares on the exact chain.
//!
//! The allocation is exact for the first-order model; the finite-rotation chain adds terms of
//! second order in the errors (products $\chi_i\chi_j$, about $10^{-7}$ rad for sub-arcminute
//! errors against $I = 4.7\times10^{-4}$ rad for the paper's table). An allocation that uses
//! the whole requirement on the linear model can therefore exceed it on the exact chain by
//! that much. [`exact_chain_check`] hunts for it, and [`allocate_with_exact_margin`] shrinks
//! the requirement by the excess found until the exact chain's worst case found is within the
//! original requirement.
//!
//! This is a search, not a proof: it looks where the linear model is worst (the certificate's
//! worst pose, adversarial signs) and on a grid of poses, which is where the second-order
//! excess matters.

use crate::allocation::{Allocation, Allocator};
use crate::error::{AllocError, length};
use crate::linearised::Linearised;
use crate::model::LinearErrorModel;
use crate::problem::AllocationProblem;
use nalgebra::{DMatrix, Matrix3};
use tt_kinematics::LinearModel;
use tt_kinematics::{
    OrientationAxis, OrientationError, OrientationErrorModel, Pose, Turntable, TurntableErrors,
};

/// Poses per free joint scanned besides each angle's linear worst pose: every 2.5 degrees for
/// one free joint (the paper's table).
const SCAN_POSES_ONE_JOINT: usize = 144;

/// Poses per free joint for two free joints (every 15 degrees of each, 576 poses).
const SCAN_POSES_TWO_JOINTS: usize = 24;

/// Poses per free joint for three or more free joints.
const SCAN_POSES_MORE_JOINTS: usize = 8;

/// Up to this many bounded errors every sign vertex $\chi_i = \pm\mathrm{UB}_i$ is tried
/// ($2^{10} = 1024$ per pose).
pub const FULL_ENUMERATION_MAX_ERRORS: usize = 10;

/// Rounds of [`allocate_with_exact_margin`].
const MARGIN_ROUNDS: usize = 4;

/// The exact chain's worst case found for one angle.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExactAxisCheck {
    /// The angle.
    pub(crate) axis: OrientationAxis,
    /// $I_k$ (rad) of the problem checked against; `None` without a requirement.
    pub(crate) requirement_rad: Option<f64>,
    /// The linear model's worst case (the certificate's, rad).
    pub(crate) linear_worst_rad: f64,
    /// The largest $|f_k|$ of the exact chain found (rad).
    pub(crate) exact_worst_rad: f64,
    /// `exact_worst_rad - requirement_rad` (rad): positive means the exact chain exceeds
    /// $I_k$; `None` without a requirement.
    pub(crate) excess_rad: Option<f64>,
    /// The pose (rad, every joint) of that worst case.
    pub(crate) pose_rad: Vec<f64>,
    /// The error vertex $\chi$ (rad) of that worst case: $\pm\mathrm{UB}_i$, and 0 for the
    /// unconstrained errors (infinite bound).
    pub(crate) chi_rad: Vec<f64>,
    /// Exact-chain evaluations done for this angle.
    pub(crate) evaluations: usize,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ExactAxisCheck {
    /// The angle.
    #[must_use]
    pub fn axis(&self) -> OrientationAxis {
        self.axis
    }

    /// $I_k$ (rad) of the problem checked against; `None` without a requirement.
    #[must_use]
    pub fn requirement_rad(&self) -> Option<f64> {
        self.requirement_rad
    }

    /// The linear model's worst case (the certificate's, rad).
    #[must_use]
    pub fn linear_worst_rad(&self) -> f64 {
        self.linear_worst_rad
    }

    /// The largest $|f_k|$ of the exact chain found (rad).
    #[must_use]
    pub fn exact_worst_rad(&self) -> f64 {
        self.exact_worst_rad
    }

    /// `exact_worst_rad - requirement_rad` (rad): positive means the exact chain exceeds
    /// $I_k$; `None` without a requirement.
    #[must_use]
    pub fn excess_rad(&self) -> Option<f64> {
        self.excess_rad
    }

    /// The pose (rad, every joint) of that worst case.
    #[must_use]
    pub fn pose_rad(&self) -> &[f64] {
        &self.pose_rad
    }

    /// The error vertex $\chi$ (rad) of that worst case: $\pm\mathrm{UB}_i$, and 0 for the
    /// unconstrained errors (infinite bound).
    #[must_use]
    pub fn chi_rad(&self) -> &[f64] {
        &self.chi_rad
    }

    /// Exact-chain evaluations done for this angle.
    #[must_use]
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }
}

/// Hunt the exact chain's worst case (finite rotations, eq 17-24 for the paper's table) of
/// `allocation` on `problem`'s turntable, checked against `problem`'s requirement.
///
/// # Method
/// For each angle $k$, at the certificate's worst pose and on a grid over the free joints'
/// ranges (every 2.5° for one free joint, 24 x 24 poses for two, 8 per joint for more), the
/// errors are put on the vertices of the box $|\chi_i| = \mathrm{UB}_i$ with adversarial
/// signs: all $2^n$ vertices when $n \le$ [`FULL_ENUMERATION_MAX_ERRORS`]; otherwise the signs
/// $s_i = \operatorname{sign} c_{ki}(\phi)$ of the linear coefficients at that pose, their
/// negation, and every single and double flip of both. The largest $|f_k|$ is reported.
///
/// Unconstrained errors (infinite bound) are held at zero: the exact chain needs a finite
/// box, and at second order they would make every angle unbounded.
///
/// This is a search, not a proof; the linear certificate ([`crate::Certificate`]) is the
/// proof for the first-order model.
///
/// # Errors
/// [`AllocError::Field`] (wrong length) when the allocation does not fit the problem's turntable;
/// [`AllocError::Kinematics`] if the chain rejects an input.
pub fn exact_chain_check<L: ExactChainModel>(
    problem: &AllocationProblem<L>,
    allocation: &Allocation,
) -> Result<[ExactAxisCheck; 3], AllocError> {
    L::hunt_exact_chain(problem, allocation)
}

/// A first-order model with an exact chain behind it, which [`exact_chain_check`] hunts and
/// [`allocate_with_exact_margin`] keeps room for: a turntable's [`LinearModel`] (its exact
/// chain, evaluated by segments) and any model written once ([`Linearised`], its
/// [`OrientationErrorModel::orientation_error`]).
pub trait ExactChainModel: LinearErrorModel + Clone + Sized {
    /// The hunt of [`exact_chain_check`] on this model.
    ///
    /// # Errors
    /// As [`exact_chain_check`].
    fn hunt_exact_chain(
        problem: &AllocationProblem<Self>,
        allocation: &Allocation,
    ) -> Result<[ExactAxisCheck; 3], AllocError>;
}

impl ExactChainModel for LinearModel {
    fn hunt_exact_chain(
        problem: &AllocationProblem<Self>,
        allocation: &Allocation,
    ) -> Result<[ExactAxisCheck; 3], AllocError> {
        turntable_check(problem, allocation)
    }
}

/// The hunt on any model's exact orientation error: the same poses (the certificate's worst
/// pose and a grid over the moving joints) and sign vertices as a turntable's, each
/// evaluated by the model (translations zero).
impl<M: OrientationErrorModel + Clone> ExactChainModel for Linearised<M> {
    fn hunt_exact_chain(
        problem: &AllocationProblem<Self>,
        allocation: &Allocation,
    ) -> Result<[ExactAxisCheck; 3], AllocError> {
        let lin = problem.model();
        let model = lin.model();
        let n = lin.n_errors();
        let (ub, boxed) = finite_box(n, allocation)?;
        let ranges = lin.joint_ranges_rad();
        let moving: Vec<usize> = (0..ranges.len())
            .filter(|&j| ranges[j][1] > ranges[j][0])
            .collect();
        let grid = pose_grid_in(ranges, &moving);
        let full = boxed.len() <= FULL_ENUMERATION_MAX_ERRORS;
        let vertices = if full {
            all_vertices(&ub, &boxed)
        } else {
            Vec::new()
        };
        let n_tr = model.n_translation_errors();
        hunt_axes(problem, allocation, &grid, n, |axis, pose, consider| {
            let tried = if full {
                vertices.clone()
            } else {
                let c = model.first_order(pose, &TurntableErrors::zero(n, n_tr))?;
                adversarial_vertices(&ub, &boxed, &signs(&c, axis))
            };
            let count = tried.len();
            for chi in tried {
                let errors = TurntableErrors::new(chi, vec![0.0; n_tr])?;
                let f = model.orientation_error(pose, &errors)?.get(axis).abs();
                consider(f, errors.chi_rad());
            }
            Ok(count)
        })
    }
}

/// The hunt of every angle: at the certificate's worst pose, then at each pose of `grid`,
/// `at_pose(axis, pose, consider)` hands each vertex's |f| (rad) and $\chi$ to `consider`
/// and returns how many it evaluated; the largest |f| found, with its pose and $\chi$ (of
/// `n` errors), is the angle's [`ExactAxisCheck`].
fn hunt_axes<L: LinearErrorModel>(
    problem: &AllocationProblem<L>,
    allocation: &Allocation,
    grid: &[Vec<f64>],
    n: usize,
    mut at_pose: impl FnMut(
        OrientationAxis,
        &Pose,
        &mut dyn FnMut(f64, &[f64]),
    ) -> Result<usize, AllocError>,
) -> Result<[ExactAxisCheck; 3], AllocError> {
    let mut out = Vec::with_capacity(3);
    for axis in OrientationAxis::ALL {
        let cert = allocation.certificate.get(axis);
        let mut poses = vec![cert.worst_pose_rad.clone()];
        poses.extend(grid.iter().cloned());
        let mut best = (f64::NEG_INFINITY, poses[0].clone(), vec![0.0; n]);
        let mut evaluations = 0;
        for pose in &poses {
            let pose_v = Pose::new(pose.clone())?;
            evaluations += at_pose(axis, &pose_v, &mut |f, chi| {
                if f > best.0 {
                    best = (f, pose.clone(), chi.to_vec());
                }
            })?;
        }
        out.push(axis_check(
            problem,
            axis,
            cert.worst_case_rad,
            best,
            evaluations,
        ));
    }
    Ok(three(out))
}

/// The sign of each error's first-order coefficient in `axis`'s row of `c` (+1 for zero):
/// the vertex that drives the angle's first order up.
fn signs(c: &DMatrix<f64>, axis: OrientationAxis) -> Vec<f64> {
    c.row(axis.index())
        .iter()
        .map(|&v| if v < 0.0 { -1.0 } else { 1.0 })
        .collect()
}

/// One angle's result of a hunt: `best` is (largest |f|, its pose, its chi).
fn axis_check<L: LinearErrorModel>(
    problem: &AllocationProblem<L>,
    axis: OrientationAxis,
    linear_worst_rad: f64,
    best: (f64, Vec<f64>, Vec<f64>),
    evaluations: usize,
) -> ExactAxisCheck {
    let requirement_rad = problem.requirement().get(axis);
    ExactAxisCheck {
        axis,
        requirement_rad,
        linear_worst_rad,
        exact_worst_rad: best.0,
        excess_rad: requirement_rad.map(|i| best.0 - i),
        pose_rad: best.1,
        chi_rad: best.2,
        evaluations,
    }
}

fn three(out: Vec<ExactAxisCheck>) -> [ExactAxisCheck; 3] {
    let [psi, theta, gamma]: [ExactAxisCheck; 3] = out
        .try_into()
        .unwrap_or_else(|_| unreachable!("three angles"));
    [psi, theta, gamma]
}

/// [`exact_chain_check`] of a turntable's linear model, by segments.
fn turntable_check(
    problem: &AllocationProblem,
    allocation: &Allocation,
) -> Result<[ExactAxisCheck; 3], AllocError> {
    let model = problem.model();
    let turntable = model.turntable();
    let n = model.n_errors();
    let (ub, boxed) = finite_box(n, allocation)?;
    let grid = pose_grid(turntable);
    let full = boxed.len() <= FULL_ENUMERATION_MAX_ERRORS;
    // Every vertex's error-segment rotations, once (they do not depend on the pose).
    let vertices: Vec<(Vec<f64>, Vec<Matrix3<f64>>)> = if full {
        all_vertices(&ub, &boxed)
            .into_iter()
            .map(|chi| {
                let e = segments(turntable, &chi)?;
                Ok((chi, e))
            })
            .collect::<Result<_, AllocError>>()?
    } else {
        Vec::new()
    };
    hunt_axes(problem, allocation, &grid, n, |axis, pose, consider| {
        let frames = turntable.pose_frames(pose)?;
        let f_of = |e: &[Matrix3<f64>]| {
            OrientationError::from_matrix_elements(&frames.delta_r(e))
                .get(axis)
                .abs()
        };
        if full {
            for (chi, e) in &vertices {
                consider(f_of(e), chi);
            }
            Ok(vertices.len())
        } else {
            let c = model.coefficients(pose)?;
            let tried = adversarial_vertices(&ub, &boxed, &signs(&c, axis));
            for chi in &tried {
                let e = segments(turntable, chi)?;
                consider(f_of(&e), chi);
            }
            Ok(tried.len())
        }
    })
}

/// The allocation's bounds checked against `n` errors, with every unconstrained error
/// (infinite bound) held at 0, and the errors with a positive bound.
fn finite_box(n: usize, allocation: &Allocation) -> Result<(Vec<f64>, Vec<usize>), AllocError> {
    length("upper_bounds", n, allocation.upper_bounds_rad.len())?;
    let ub: Vec<f64> = allocation
        .upper_bounds_rad
        .iter()
        .map(|&u| if u.is_finite() { u } else { 0.0 })
        .collect();
    let boxed = (0..n).filter(|&i| ub[i] > 0.0).collect();
    Ok((ub, boxed))
}

/// Every sign vertex $\chi_i = \pm\mathrm{UB}_i$ of the `boxed` errors (others 0), the bit
/// order of the enumeration as before.
fn all_vertices(ub: &[f64], boxed: &[usize]) -> Vec<Vec<f64>> {
    (0u32..(1 << boxed.len()))
        .map(|signs| {
            let mut chi = vec![0.0; ub.len()];
            for (b, &i) in boxed.iter().enumerate() {
                chi[i] = if signs & (1 << b) == 0 { ub[i] } else { -ub[i] };
            }
            chi
        })
        .collect()
}

/// The error-segment rotations of the exact chain for $\chi$.
fn segments(turntable: &Turntable, chi: &[f64]) -> Result<Vec<Matrix3<f64>>, AllocError> {
    let mut e = vec![Matrix3::identity(); turntable.n_segments()];
    turntable.segment_rotations(chi, &mut e)?;
    Ok(e)
}

/// The sign vertices tried when there are too many errors to enumerate: $s$, $-s$, and every
/// single and double flip of both.
fn adversarial_vertices(ub: &[f64], boxed: &[usize], s: &[f64]) -> Vec<Vec<f64>> {
    let at = |signs: &[f64]| -> Vec<f64> {
        let mut chi = vec![0.0; ub.len()];
        for &i in boxed {
            chi[i] = signs[i] * ub[i];
        }
        chi
    };
    let mut out = Vec::new();
    for base in [s.to_vec(), s.iter().map(|v| -v).collect::<Vec<f64>>()] {
        out.push(at(&base));
        for (a, &i) in boxed.iter().enumerate() {
            let mut one = base.clone();
            one[i] = -one[i];
            out.push(at(&one));
            for &j in &boxed[a + 1..] {
                let mut two = one.clone();
                two[j] = -two[j];
                out.push(at(&two));
            }
        }
    }
    out
}

/// The scan grid over the free joints (other joints at the lower end of their range).
fn pose_grid(turntable: &Turntable) -> Vec<Vec<f64>> {
    pose_grid_in(&turntable.joint_ranges_rad(), turntable.free_joints())
}

/// The scan grid over the joints `free` of `ranges` (the others at the lower end).
fn pose_grid_in(ranges: &[[f64; 2]], free: &[usize]) -> Vec<Vec<f64>> {
    let per = match free.len() {
        0 => 1,
        1 => SCAN_POSES_ONE_JOINT,
        2 => SCAN_POSES_TWO_JOINTS,
        _ => SCAN_POSES_MORE_JOINTS,
    };
    crate::model::joint_grid(ranges, free, per, true).collect()
}

/// An allocation whose exact-chain worst case (as found by [`exact_chain_check`]) is within
/// the original requirement, with the relative safety margin that achieved it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ExactSafeAllocation {
    /// The allocation (its `requirement` is the shrunk one).
    pub(crate) allocation: Allocation,
    /// The relative margin $m$: the allocation was made for $(1-m)I$.
    pub(crate) margin: f64,
    /// The exact-chain check against the original requirement.
    pub(crate) check: [ExactAxisCheck; 3],
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ExactSafeAllocation {
    /// The allocation (its `requirement` is the shrunk one).
    #[must_use]
    pub fn allocation(&self) -> &Allocation {
        &self.allocation
    }

    /// The relative margin $m$: the allocation was made for $(1-m)I$.
    #[must_use]
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// The exact-chain check against the original requirement.
    #[must_use]
    pub fn check(&self) -> &[ExactAxisCheck; 3] {
        &self.check
    }
}

/// Allocate, hunt the exact chain's excess, and shrink every requirement by the largest
/// relative excess (plus 1%), up to four times, until the exact chain's worst case found
/// stays within the original requirement.
///
/// # Errors
/// Those of the allocator and of [`exact_chain_check`]; [`AllocError::NoConvergence`] if four
/// rounds do not suffice.
pub fn allocate_with_exact_margin<L: ExactChainModel>(
    allocator: &dyn Allocator<L>,
    problem: &AllocationProblem<L>,
) -> Result<ExactSafeAllocation, AllocError> {
    let mut margin = 0.0_f64;
    let mut last_violation = f64::NAN;
    for _ in 0..MARGIN_ROUNDS {
        let shrunk = problem.with_safety_margin(margin)?;
        let allocation = allocator.allocate(&shrunk)?;
        let check = exact_chain_check(problem, &allocation)?;
        let worst_rel = check
            .iter()
            .filter_map(|c| c.excess_rad.zip(c.requirement_rad).map(|(e, i)| e / i))
            .fold(f64::NEG_INFINITY, f64::max);
        if worst_rel <= 0.0 {
            return Ok(ExactSafeAllocation {
                allocation,
                margin,
                check,
            });
        }
        last_violation = worst_rel;
        margin += worst_rel * 1.01;
    }
    Err(AllocError::NoConvergence {
        problem: "exact-chain margin".into(),
        iterations: MARGIN_ROUNDS,
        violation: last_violation,
    })
}
