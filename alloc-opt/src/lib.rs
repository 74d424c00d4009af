//! Tolerance allocation for the errors of a two-axis turntable (Zhao, Zhao, Huo and Yao 2017,
//! §4.1-4.2, eq 28-38, Lemma 1, Table 4), solved to the true optimum.
//!
//! Given an orientation-error model linear in the turntable errors $\chi$ with
//! first-harmonic coefficients in $\phi_2$ ([`tt_kinematics::LinearModel`], eq 26 is one), the
//! requirement $(I_\psi, I_\theta, I_\gamma)$ and lower bounds $\mathrm{LB}_i$, an
//! [`Allocator`] returns upper bounds $\mathrm{UB}_i$ with a [`Certificate`]: the exact worst
//! case of each $|f_k|$ over every pose $\phi \in [0, 2\pi]^2$ and every $\chi$ with
//! $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$ (any signs), the worst pose, the share of the
//! requirement used, and which constraints are active.
//!
//! | allocator | what it does |
//! |---|---|
//! | [`SensitivityWeighted`] | the paper's method: weights $W = 1/$average sensitivity (eq 28), problems (31)-(33) with their pose ranges, combination (34) |
//! | [`EqualEffects`] | the traditional method (refs 20-21): every error contributes equally to the worst case, same guarantee |
//!
//! # How the optimum is found
//! Each problem $\min \sum W_i^2/\chi_i^2$ subject to a constraint for every pose is solved
//! by the exchange method ([`solver`]): the `clarabel` interior-point solver handles a finite
//! set of poses (the objective as power cones), the exact worst pose of the current solution
//! ([`tt_kinematics::LinearModel::max_signed_weighted`]) is added, and so on until the violation
//! is below $10^{-9}$; a final one-factor rescaling makes the bounds feasible and tight to
//! $10^{-13}$. Tests check the optimum independently (closed form, KKT conditions,
//! perturbations).
//!
//! # Lower bounds
//! The paper gives none (NOTES item 11). [`AllocationProblem::paper_example`] uses
//! $\mathrm{LB} = 0$ (as does the NumPy Monte Carlo anchor); given bounds are honoured, and
//! bounds that alone violate a requirement give [`AllocError::InfeasibleLowerBounds`] naming the
//! problem and the components.
//!
//! # The paper's example and Table 4
//! With $I = 0.027^\circ = 1.62'$ and $\mathrm{LB} = 0$, the weights are $\pi/2$ for the
//! $\sin\phi_2$/$\cos\phi_2$ terms and 1 for the constant ones; on $[0, \pi/2]$,
//! $\max f_\gamma = \sqrt{(x_1+x_5)^2+(x_2+x_4)^2} + x_3$, and the optimum is
//! $x_3 = I/(1+\sqrt2(2\sqrt2\pi^2)^{1/3}) = 0.3062'$ ($\Delta\alpha_{x2}$, $\Delta\alpha_{y2}$),
//! $0.4645'$ for the four shared components, and $0.81'$ for $\Delta\phi_{z2}, \Delta\alpha_{z1}$,
//! each using 100% of its requirement. Table 4 ([`PAPER_TABLE4_ARCMIN`]) prints
//! 0.4235/0.2825 and 0.78, which use 91.4% ($\psi$, $\gamma$) and 96.3% ($\theta$) of the
//! requirement, so they are not the optimum of the stated problem: scaling them up to the
//! requirement lowers $J$. See the crate README for the numbers and the hypotheses tested.
//!
//! # The exact chain
//! Tight on the linear model means up to about $10^{-7}$ rad over $I$ on the exact chain
//! (second-order terms). [`exact_chain_check`] measures it; [`allocate_with_exact_margin`] and
//! [`AllocationProblem::with_safety_margin`] keep room for it.
//!
//! # Example
//! ```
//! use alloc_opt::{Allocator, AllocationProblem, SensitivityWeighted, PAPER_TABLE4_ARCMIN};
//! use tt_kinematics::{ErrorComponent, OrientationAxis};
//!
//! let problem = AllocationProblem::paper_example()?;
//! let a = SensitivityWeighted::paper().allocate(&problem)?;
//! let ub = a.upper_bounds_arcmin();
//! // The inner-axis wobbles get the tightest bounds (the paper's conclusion 1).
//! assert!((ub[ErrorComponent::DalphaX2.index()] - 0.3062).abs() < 1e-4);
//! assert!(ub[ErrorComponent::DalphaX2.index()] < PAPER_TABLE4_ARCMIN[0]);
//! // Lemma 1, with the whole requirement used.
//! assert!(a.certificate.lemma1_holds());
//! assert!(a.certificate.get(OrientationAxis::Gamma).share > 1.0 - 1e-9);
//! # Ok::<(), alloc_opt::AllocError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782.
#![forbid(unsafe_code)]

mod allocation;
mod equal;
mod error;
mod exact;
mod paper;
mod problem;
pub mod solver;
mod table4;

pub use allocation::{
    Allocation, Allocator, AxisCertificate, Certificate, SATISFIED_REL, Subproblem, TIGHT_REL,
};
pub use equal::EqualEffects;
pub use error::AllocError;
pub use exact::{
    ExactAxisCheck, ExactSafeAllocation, allocate_with_exact_margin, exact_chain_check,
};
pub use paper::{ConstraintForm, SensitivityWeighted, WeightRule};
pub use problem::{AllocationProblem, Requirement, Weights};
pub use table4::{PAPER_REQUIREMENT_DEG, PAPER_TABLE4_ARCMIN, paper_table4_rad};
