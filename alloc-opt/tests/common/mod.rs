//! Named tolerances and shared fixtures of the alloc-opt tests.
#![allow(dead_code)]

use alloc_opt::{
    Allocation, AllocationProblem, Allocator, EqualEffects, Requirement, SensitivityWeighted, paper,
};
use std::sync::OnceLock;
use tt_core::units::arcmin_to_rad;
use tt_kinematics::LinearModel;

/// Tightness claim of the issue: each requirement is reached to 1e-9 relative (exact worst
/// case, one free joint).
pub(crate) const TIGHT_REL: f64 = 1e-9;

/// Agreement of the optimum with a closed form or a KKT identity, relative. The interior-point
/// bounds alone are accurate to ~1e-6 (the objective is flat at the optimum: x error ~ sqrt of
/// the gap); the single-active-pose KKT polish brings them to rounding (cube roots, bisection
/// to one ulp), so 1e-10 leaves a wide margin.
pub(crate) const OPTIMUM_REL: f64 = 1e-10;

/// Objective comparisons between an optimum and other feasible points, relative: J at the
/// optimum is accurate to ~1e-10 (second order in the bound error).
pub(crate) const OBJECTIVE_REL: f64 = 1e-9;

/// Lemma 1 slack for rounding in the evaluation of f (relative): a few ulp of sums of 5-13
/// terms.
pub(crate) const LEMMA1_REL: f64 = 1e-12;

/// The agreement of the general code with the pre-change (paper-only) allocation of
/// the paper's table, relative.
pub(crate) const PIN_REL: f64 = 1e-9;

/// Printed precision of Table 4 (arcmin): 4 decimals.
pub(crate) const TABLE4_PRINT_ARCMIN: f64 = 5e-5;

/// The shares of Table 4 are quoted to 4 decimals in the docs.
pub(crate) const SHARE_QUOTE: f64 = 5e-5;

/// Objectives quoted in the README to 6 significant digits (115.867, 124.458, 138.467),
/// relative.
pub(crate) const README_J_REL: f64 = 1e-5;

/// Closed-form constants written to 5 significant digits in the tests (0.30623, 0.46450),
/// relative.
pub(crate) const CLOSED_FORM_QUOTE_REL: f64 = 1e-4;

/// A closed-form expression evaluated two ways (an exact integral or a cube root against
/// pi/2, pi/sqrt2, I/(1 + 2 sqrt2)): a few ulp, relative.
pub(crate) const FORMULA_REL: f64 = 1e-12;

/// One product of a few numbers computed two ways (a scale times a bound, a share applied
/// twice): one or two ulp, relative.
pub(crate) const ULP_REL: f64 = 1e-15;

/// The exact chain evaluated twice at the same pose and vertex, by the segmented product of
/// `exact_chain_check` and by `ExactChain` (the matrix chain): equal to rounding of a product
/// of about ten 3x3 matrices, read as a ~1e-4 rad entry, relative.
pub(crate) const CHAIN_REPRODUCE_REL: f64 = 1e-12;

/// A worst pose located by the exact one-joint search, relative (rad): the maximum of a
/// smooth sum is flat, so its argument is found to about sqrt(epsilon).
pub(crate) const WORST_POSE_REL: f64 = 1e-6;

/// Rounding of a weighted sum of 13 unit-size coefficients times bounds of ~1e-4 rad,
/// evaluated two ways (chain product versus harmonic form), rad.
pub(crate) const ROUNDING_RAD: f64 = 1e-15;

/// The second-order remainder of the exact chain against the linear model, rad, for error
/// rotations of total size $s = \sum_i |\chi_i|$ (entrywise, eq 24 read-out).
///
/// $\Delta\mathbf R$ is a product of the error rotations $e^{[u_k]_\times}$ conjugated by
/// nominal rotations (which preserve norms), $|u_k| = |\chi_k|$, and the linear model is
/// exactly $\mathbf I + \sum_k [u_k]_\times$ read out the same way. Writing
/// $e^{[u_k]_\times} = \mathbf I + \mathbf A_k$ with $\|\mathbf A_k\| \le e^{|u_k|} - 1$ and
/// expanding the product, every term of degree two or more in the $\mathbf A_k$ and the
/// remainders $e^{[u]} - \mathbf I - [u]$ add up to at most $e^{s} - 1 - s$ in operator norm,
/// which bounds every entry.
pub(crate) fn second_order_bound_rad(chi_rad: &[f64]) -> f64 {
    let s: f64 = chi_rad.iter().map(|x| x.abs()).sum();
    s.exp_m1() - s
}

pub(crate) fn paper_problem() -> AllocationProblem {
    paper::example_problem().expect("paper example is valid")
}

/// The paper's problem (its model and eq 16's requirement) with the lower bounds `lb_rad`.
pub(crate) fn paper_problem_with_lower_bounds(lb_rad: Vec<f64>) -> AllocationProblem {
    let requirement = Requirement::uniform_deg(paper::REQUIREMENT_DEG).expect("eq 16");
    AllocationProblem::new(paper_model(), requirement, lb_rad).expect("valid problem")
}

pub(crate) fn paper_model() -> LinearModel {
    LinearModel::new(&tt_kinematics::paper::table3())
}

/// Index of a named error of the paper's table in chi (eq 25).
pub(crate) fn idx(name: &str) -> usize {
    tt_kinematics::paper::chi_index(name)
}

pub(crate) fn paper_allocation() -> &'static Allocation {
    static A: OnceLock<Allocation> = OnceLock::new();
    A.get_or_init(|| {
        SensitivityWeighted::paper()
            .allocate(&paper_problem())
            .expect("paper allocation solves")
    })
}

pub(crate) fn equal_allocation() -> &'static Allocation {
    static A: OnceLock<Allocation> = OnceLock::new();
    A.get_or_init(|| {
        EqualEffects
            .allocate(&paper_problem())
            .expect("equal-effects allocation")
    })
}

/// The three-axis table of tt-kinematics' conformance suite (outer z, middle x, inner y;
/// 13 rotation errors, free joints phi_m and phi_i).
#[allow(unused_imports)] // each test binary uses a part of this module
pub(crate) use tt_kinematics::conformance::{three_axis, three_axis_description};

/// The three-axis problem of the tests and README: 1.62 arcmin (eq 16's 0.027 deg) on every
/// angle, no lower bounds.
pub(crate) fn three_axis_problem() -> AllocationProblem {
    let model = LinearModel::new(&three_axis());
    let i = arcmin_to_rad(1.62);
    AllocationProblem::new(model, Requirement::new(i, i, i).unwrap(), vec![0.0; 13])
        .expect("valid problem")
}

/// The three-axis full-range allocation (computed once: about 3 s in the test profile).
pub(crate) fn three_axis_allocation() -> &'static Allocation {
    static A: OnceLock<Allocation> = OnceLock::new();
    A.get_or_init(|| {
        SensitivityWeighted::general()
            .allocate(&three_axis_problem())
            .expect("three-axis allocation solves")
    })
}
