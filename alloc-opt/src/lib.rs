//! Tolerance allocation for the rotation errors of any serial turntable described as data
//! (Zhao, Zhao, Huo and Yao 2017, §4.1-4.2, eq 28-38, Lemma 1, Table 4), solved to the true
//! optimum, with a certificate.
//!
//! Given the first-order orientation-error model of a turntable
//! ([`tt_kinematics::LinearModel`] of a [`tt_kinematics::Turntable`]; for the paper's table it
//! is eq 26), $f_k(\phi, \chi) = \sum_i c_{ki}(\phi)\,\chi_i$ for $k \in \{\psi, \theta,
//! \gamma\}$, the requirement $(I_\psi, I_\theta, I_\gamma)$ (any of them may be absent) and
//! lower bounds $\mathrm{LB}_i$, an [`Allocator`] returns upper bounds $\mathrm{UB}_i$ with a
//! [`Certificate`]: the worst case of each $|f_k|$ over every pose $\phi$ in the joint ranges
//! and every $\chi$ with $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$ (any signs), a rigorous
//! upper bound on it, the worst pose, the share of the requirement used, and which
//! constraints are active.
//!
//! | allocator | what it does |
//! |---|---|
//! | [`SensitivityWeighted::paper`] | the paper's method: weights $W = 1/$average sensitivity (eq 28), problems (31)-(33) with their quarter ranges of $\phi_2$, combination (34); tables with one free joint |
//! | [`SensitivityWeighted::general`] | the same weights and combination with the constraint of eq 30 itself over every pose in the joint ranges: any table |
//! | [`EqualEffects`] | the traditional method (refs 20-21): every error contributes equally to the worst case, same guarantee |
//!
//! Combination rule (34), generalised: $\mathrm{UB}_i = \min_k \chi^*_{ki}$ over the angles
//! with a requirement that depend on error $i$; an error that none of them depends on is
//! unconstrained ($\mathrm{UB}_i = +\infty$, listed in [`Allocation::unconstrained`]).
//!
//! # How the optimum is found
//! Each problem $\min \sum W_i^2/\chi_i^2$ subject to a constraint for every pose is solved
//! by the exchange method ([`solver`]): the `clarabel` interior-point solver handles a finite
//! set of poses (the objective as power cones), the worst pose of the current solution
//! ([`tt_kinematics::LinearModel::max_signed_weighted`] /
//! [`tt_kinematics::LinearModel::max_abs_weighted`]) is added, and so on until the violation
//! is below $10^{-9}$; a final one-factor rescaling makes the bounds feasible and tight to
//! $10^{-13}$, and a KKT polish brings a single-active-pose optimum to rounding accuracy.
//! Tests check the optimum independently (closed form, KKT conditions, perturbations, a dense
//! grid).
//!
//! # What is exact and what is a search
//! - **At most one free joint** (the paper's table; any two-axis table whose outer joint comes
//!   first, since the outer joint cancels from the orientation error): the worst pose is found
//!   exactly (the coefficients are first harmonics of the free joint, maximised piece by piece
//!   between their zeros). The optimum, the tightness and the certificate are exact to
//!   rounding.
//! - **Two or more free joints** (a three-axis table): the worst pose is searched (a grid over
//!   the outer free joints refined by golden sections, exact in the last joint). The exchange
//!   method converges to the optimum *of the poses found*; then the certificate bounds the
//!   worst case rigorously by branch and bound with a second-order cell bound
//!   ([`tt_kinematics::LinearModel::worst_pose_certified`], relative gap $10^{-9}$), and where that bound exceeds the
//!   requirement the free bounds are shrunk until it does not ([`Allocation::safety_scale`],
//!   by the bound's gap). So **Lemma 1 is guaranteed** for the linear model (the rigorous
//!   bound is within $I$), while **optimality is not**: it holds up to the search's miss and
//!   the bound's gap, which the tests measure against a dense grid.
//! - **The exact chain** (finite rotations) is never covered by the certificate: tight on the
//!   linear model means up to second order (about $10^{-7}$ rad) over $I$ on the exact chain.
//!   [`exact_chain_check`] hunts it (adversarial sign vertices at the worst pose and on a
//!   grid; a search, not a proof); [`allocate_with_exact_margin`] and
//!   [`AllocationProblem::with_safety_margin`] keep room for it.
//!
//! # Lower bounds
//! The paper gives none (NOTES item 11). `paper::example_problem` uses $\mathrm{LB} = 0$
//! (as does the NumPy Monte Carlo anchor); given bounds are honoured, and bounds that alone
//! violate a requirement give [`AllocError::InfeasibleLowerBounds`] naming the problem and the
//! errors.
//!
//! # The paper's example and Table 4
//! With $I = 0.027^\circ = 1.62'$ and $\mathrm{LB} = 0$, the weights are $\pi/2$ for the
//! $\sin\phi_2$/$\cos\phi_2$ terms and 1 for the constant ones; on $[0, \pi/2]$,
//! $\max f_\gamma = \sqrt{(x_1+x_5)^2+(x_2+x_4)^2} + x_3$, and the optimum is
//! $x_3 = I/(1+\sqrt2(2\sqrt2\pi^2)^{1/3}) = 0.3062'$ ($\Delta\alpha_{x2}$, $\Delta\alpha_{y2}$),
//! $0.4645'$ for the four shared errors, and $0.81'$ for $\Delta\phi_{z2}, \Delta\alpha_{z1}$,
//! each using 100% of its requirement ($J = 115.867$ arcmin$^{-2}$; equal effects 124.458).
//! Table 4 (`paper::TABLE4_ARCMIN`) prints 0.4235/0.2825 and 0.78, which use 91.4% ($\psi$,
//! $\gamma$) and 96.3% ($\theta$) of the requirement, so they are not the optimum of the
//! stated problem: scaling them up to the requirement lowers $J$. See the crate README for the
//! numbers and the hypotheses tested.
//!
//! # Example: the paper's table
//! ```
//! use alloc_opt::{Allocator, SensitivityWeighted, paper};
//! use tt_kinematics::OrientationAxis;
//!
//! let problem = paper::example_problem()?;
//! let a = SensitivityWeighted::paper().allocate(&problem)?;
//! let x2 = a.upper_bound_rad("dalpha_x2").unwrap().to_degrees() * 60.0;
//! // The inner-axis wobbles get the tightest bounds (the paper's conclusion 1).
//! assert!((x2 - 0.3062).abs() < 1e-4);
//! assert!(x2 < paper::TABLE4_ARCMIN[0]);
//! // Lemma 1, with the whole requirement used.
//! assert!(a.certificate().lemma1_holds());
//! assert!(a.certificate().get(OrientationAxis::Gamma).share().unwrap() > 1.0 - 1e-9);
//! # Ok::<(), alloc_opt::AllocError>(())
//! ```
//!
//! # Example: your own table
//! ```
//! use alloc_opt::{AllocationProblem, Allocator, Requirement, SensitivityWeighted};
//! use tt_kinematics::{FactorSpec, LinearModel, SignedAxis, Turntable, TurntableDescription};
//!
//! let j = FactorSpec::joint;
//! let e = FactorSpec::error;
//! // A two-axis table: outer joint about z, inner about x, a position error and a wobble each.
//! let table = Turntable::new(&TurntableDescription::new(vec![
//!     j("outer", SignedAxis::Z), e("d_outer", SignedAxis::Z), e("wobble_o", SignedAxis::X),
//!     j("inner", SignedAxis::X), e("d_inner", SignedAxis::X), e("wobble_i", SignedAxis::Y),
//! ]))?;
//! let model = LinearModel::new(&table);
//! let n = model.n_errors();
//! // 1 arcmin on every angle; no lower bounds.
//! let i = 1.0_f64.to_radians() / 60.0;
//! let problem = AllocationProblem::new(model, Requirement::new(i, i, i)?, vec![0.0; n])?;
//! let a = SensitivityWeighted::general().allocate(&problem)?;
//! assert!(a.certificate().lemma1_holds());
//! assert!(a.upper_bounds_rad().iter().all(|u| u.is_finite() && *u > 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782.
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod allocation;
mod equal;
mod error;
mod exact;
mod linearised;
mod model;
#[cfg(feature = "paper")]
pub mod paper;
mod problem;
pub mod solver;
mod weighted;

pub use allocation::{
    Allocation, Allocator, AxisCertificate, Certificate, MethodDetails, SATISFIED_REL,
    SEARCHED_TIGHT_REL, Subproblem, TIGHT_REL, ToleranceBox, combine_rule_34, finish,
};
pub use equal::EqualEffects;
pub use error::AllocError;
pub use exact::{
    ExactAxisCheck, ExactChainModel, ExactSafeAllocation, FULL_ENUMERATION_MAX_ERRORS,
    allocate_with_exact_margin, exact_chain_check,
};
pub use linearised::{LINEARISED_MAX_POSES, Linearised};
pub use model::{LinearErrorModel, WorstRow};
pub use problem::{AllocationProblem, Weights};
/// The requirement of eq 15-16 ([`tt_core::Requirement`]), re-exported.
pub use tt_core::Requirement;
pub use weighted::{ConstraintForm, SensitivityWeighted, WeightRule};
