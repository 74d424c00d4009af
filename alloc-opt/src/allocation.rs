//! The [`Allocator`] seam, its result [`Allocation`] and the Lemma 1 [`Certificate`].

use crate::error::AllocError;
use crate::problem::{AllocationProblem, Requirement, Weights};
use crate::solver::{Cut, CutOracle};
use std::f64::consts::TAU;
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{CHI_LEN, ErrorComponent, LinearModel, OrientationAxis};

/// A requirement counts as active (tight) when the worst case uses at least
/// $1 - 10^{-9}$ of it (relative; the exchange method ends within $10^{-13}$).
pub const TIGHT_REL: f64 = 1e-9;

/// A requirement counts as satisfied when the worst case exceeds it by at most this
/// (relative): the rounding of the exact worst-case evaluation, a few ulp.
pub const SATISFIED_REL: f64 = 1e-12;

/// Turns an [`AllocationProblem`] into upper bounds $\mathrm{UB}_i$ with a certificate.
///
/// # Example
/// ```
/// use alloc_opt::{Allocator, AllocationProblem, EqualEffects, SensitivityWeighted};
/// let problem = AllocationProblem::paper_example()?;
/// for allocator in [&SensitivityWeighted::paper() as &dyn Allocator, &EqualEffects] {
///     let a = allocator.allocate(&problem)?;
///     assert!(a.certificate.lemma1_holds());
/// }
/// # Ok::<(), alloc_opt::AllocError>(())
/// ```
pub trait Allocator {
    /// A short name of the method (`"sensitivity-weighted"`, `"equal-effects"`).
    fn name(&self) -> &'static str;

    /// Allocate the upper bounds.
    ///
    /// # Errors
    /// [`AllocError`] naming the problem and components when the lower bounds are infeasible,
    /// or when a solver fails.
    fn allocate(&self, problem: &AllocationProblem) -> Result<Allocation, AllocError>;
}

/// The solution of one per-angle problem ((31) $\gamma$, (32) $\theta$, (33) $\psi$).
#[derive(Debug, Clone, PartialEq)]
pub struct Subproblem {
    /// The angle (problem) concerned.
    pub axis: OrientationAxis,
    /// Its components ($\chi_\gamma$, $\chi_\theta$, $\chi_\psi$ of eq 27).
    pub components: Vec<ErrorComponent>,
    /// The optimal $\chi_k^*$ (rad), one per component.
    pub bounds_rad: Vec<f64>,
    /// The pose range $[\text{lo}, \text{hi}]$ of $\phi_2$ (rad) of the constraint.
    pub pose_range_rad: (f64, f64),
    /// $J_k(\chi_k^*)$ (rad$^{-2}$); `NaN` for the equal-effects allocator.
    pub objective: f64,
    /// The angle $\phi_2$ (rad) where the constraint is tight.
    pub worst_phi2_rad: f64,
    /// The constraint's load at the optimum (1 = the whole requirement used).
    pub load: f64,
    /// The requirement's Lagrange multiplier (units of $J$; `NaN` when not computed).
    pub multiplier: f64,
    /// Conic solves done by the exchange method (0 when none was needed).
    pub iterations: usize,
}

/// The certificate of one angle: the worst case over all poses and all admissible errors.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisCertificate {
    /// The angle.
    pub axis: OrientationAxis,
    /// $I_k$ (rad).
    pub requirement_rad: f64,
    /// $\max_{\phi \in [0,2\pi]^2} \max_{\mathrm{LB} \le |\chi| \le \mathrm{UB}} |f_k(\phi,\chi)|
    /// = \max_{\phi_2} \sum_i \mathrm{UB}_i |c_{ki}(\phi_2)|$ (rad).
    pub worst_case_rad: f64,
    /// An inner-axis angle $\phi_2$ (rad) where it is reached ($\phi_1$ is irrelevant).
    pub worst_phi2_rad: f64,
    /// `worst_case_rad / requirement_rad`: the share of the requirement used.
    pub share: f64,
    /// The requirement is active: share $\ge 1 -$ [`TIGHT_REL`].
    pub requirement_active: bool,
    /// The requirement holds: share $\le 1 +$ [`SATISFIED_REL`] (Lemma 1 for this angle).
    pub satisfied: bool,
    /// Involved components whose upper bound equals their positive lower bound.
    pub active_lower_bounds: Vec<ErrorComponent>,
}

/// Lemma 1's certificate for all three angles.
#[derive(Debug, Clone, PartialEq)]
pub struct Certificate {
    /// One per angle, in the order $\psi, \theta, \gamma$.
    pub axes: [AxisCertificate; 3],
}

impl Certificate {
    /// The exact worst cases of `ub_rad` on `model` over the full pose range.
    ///
    /// # Formula
    /// $$\max_{\phi_2\in[0,2\pi]}\sum_i \mathrm{UB}_i\,|c_{ki}(\phi_2)|,$$ found exactly by
    /// [`LinearModel::max_abs_weighted`] (the signs of $\chi$ chosen adversarially; the lower
    /// bounds do not lower the maximum).
    ///
    /// # Reference
    /// Zhao et al. 2017, Lemma 1 and eq 30.
    #[must_use]
    pub fn compute(
        model: &LinearModel,
        requirement: &Requirement,
        lower_bounds_rad: &[f64; CHI_LEN],
        ub_rad: &[f64; CHI_LEN],
    ) -> Self {
        let axes = OrientationAxis::ALL.map(|axis| {
            let involved = model.involved(axis);
            let mut w = [0.0; CHI_LEN];
            for c in &involved {
                w[c.index()] = ub_rad[c.index()];
            }
            let worst = model.max_abs_weighted(axis, &w, 0.0, TAU);
            let i_k = requirement.get(axis);
            let share = worst.value / i_k;
            AxisCertificate {
                axis,
                requirement_rad: i_k,
                worst_case_rad: worst.value,
                worst_phi2_rad: worst.phi2_rad,
                share,
                requirement_active: share >= 1.0 - TIGHT_REL,
                satisfied: share <= 1.0 + SATISFIED_REL,
                active_lower_bounds: involved
                    .into_iter()
                    .filter(|c| {
                        let lb = lower_bounds_rad[c.index()];
                        lb > 0.0 && ub_rad[c.index()] <= lb * (1.0 + 1e-7)
                    })
                    .collect(),
            }
        });
        Self { axes }
    }

    /// The certificate of one angle.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> &AxisCertificate {
        &self.axes[axis.index()]
    }

    /// Lemma 1: every angle's worst case is within its requirement.
    #[must_use]
    pub fn lemma1_holds(&self) -> bool {
        self.axes.iter().all(|a| a.satisfied)
    }
}

/// An allocation: upper bounds with their objective, per-problem solutions and certificate.
#[derive(Debug, Clone, PartialEq)]
pub struct Allocation {
    /// The allocator's name.
    pub method: &'static str,
    /// $\mathrm{UB}_i$ (rad, order of eq 25); `INFINITY` for a component no angle depends on.
    pub upper_bounds_rad: [f64; CHI_LEN],
    /// The lower bounds used (rad).
    pub lower_bounds_rad: [f64; CHI_LEN],
    /// The requirement used.
    pub requirement: Requirement,
    /// $J(\mathrm{UB}) = J_\psi + J_\theta + J_\gamma$ (rad$^{-2}$) under [`Allocation::weights`].
    pub objective: f64,
    /// The weights the objective is computed with (the paper's inverse average sensitivities
    /// unless the allocator was given others).
    pub weights: Weights,
    /// The per-angle problems, in the order solved.
    pub subproblems: Vec<Subproblem>,
    /// Worst cases over the full pose range (Lemma 1).
    pub certificate: Certificate,
}

impl Allocation {
    /// $\mathrm{UB}_i$ in arcminutes (for printing).
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> [f64; CHI_LEN] {
        self.upper_bounds_rad.map(|v| v / RAD_PER_ARCMIN)
    }

    /// $J$ with the bounds in arcminutes (unit arcmin$^{-2}$), the scale of Table 4.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        self.objective * RAD_PER_ARCMIN * RAD_PER_ARCMIN
    }

    /// The share of each requirement used, order $\psi, \theta, \gamma$.
    #[must_use]
    pub fn shares(&self) -> [f64; 3] {
        self.certificate.axes.clone().map(|a| a.share)
    }
}

/// The constraint family of one angle's problem as an exact separation oracle: rows
/// $c_{ki}(\phi_2)$ (or $|c_{ki}(\phi_2)|$) for every $\phi_2$ in a range.
#[derive(Debug, Clone)]
pub(crate) struct AxisOracle {
    pub model: LinearModel,
    pub axis: OrientationAxis,
    pub components: Vec<ErrorComponent>,
    pub lo: f64,
    pub hi: f64,
    pub abs: bool,
    pub requirement_rad: f64,
}

impl AxisOracle {
    pub fn row(&self, phi2: f64) -> Cut {
        Cut {
            coefficients: self
                .components
                .iter()
                .map(|&c| {
                    let v = self.model.coefficient(self.axis, c, phi2);
                    if self.abs { v.abs() } else { v }
                })
                .collect(),
            bound: self.requirement_rad,
            tag: phi2,
        }
    }

    /// Whether any involved coefficient depends on $\phi_2$.
    pub fn pose_dependent(&self) -> bool {
        self.components.iter().any(|&c| {
            let (a, b, _) = self.model.harmonics(self.axis, c);
            a != 0.0 || b != 0.0
        })
    }

    /// Start rows: a 17-point grid over the range (one row if nothing depends on the pose).
    pub fn grid(&self) -> Vec<Cut> {
        if !self.pose_dependent() {
            return vec![self.row(self.lo)];
        }
        const N: usize = 17;
        (0..N)
            .map(|j| self.row(self.lo + (self.hi - self.lo) * j as f64 / (N - 1) as f64))
            .collect()
    }

    pub fn full(&self, x: &[f64]) -> [f64; CHI_LEN] {
        let mut w = [0.0; CHI_LEN];
        for (k, c) in self.components.iter().enumerate() {
            w[c.index()] = x[k];
        }
        w
    }

    /// Reject lower bounds that alone exceed the requirement, naming the components.
    pub fn check_lower_bounds(&self, lower: &[f64]) -> Result<(), AllocError> {
        let worst = self.most_violated(lower);
        let load = worst.load(lower);
        if load > 1.0 {
            let components = self
                .components
                .iter()
                .zip(lower)
                .zip(&worst.coefficients)
                .filter(|((_, l), a)| **l > 0.0 && **a > 0.0)
                .map(|((c, _), _)| *c)
                .collect();
            return Err(AllocError::InfeasibleLowerBounds {
                problem: self.axis,
                components,
                worst_case_rad: load * self.requirement_rad,
                requirement_rad: self.requirement_rad,
            });
        }
        Ok(())
    }
}

impl CutOracle for AxisOracle {
    fn most_violated(&self, x: &[f64]) -> Cut {
        let w = self.full(x);
        let wp = if self.abs {
            self.model.max_abs_weighted(self.axis, &w, self.lo, self.hi)
        } else {
            self.model
                .max_signed_weighted(self.axis, &w, self.lo, self.hi)
        };
        self.row(wp.phi2_rad)
    }
}
