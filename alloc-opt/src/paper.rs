//! The paper's allocator: sensitivity-weighted problems (31)-(33) and combination rule (34).

use crate::allocation::{Allocation, Allocator, AxisOracle, Certificate, Subproblem};
use crate::error::AllocError;
use crate::problem::{AllocationProblem, Weights};
use crate::solver::{InverseSquareProblem, solve_inverse_square};
use std::f64::consts::{FRAC_PI_2, TAU};
use tt_kinematics::{CHI_LEN, OrientationAxis};

/// Which constraint each per-angle problem imposes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConstraintForm {
    /// As printed: $f_k(\phi_2, \chi_k) \le I_k$ (no absolute values, $\chi_k \ge 0$) for
    /// $\phi_2 \in [0, \pi/2]$ for $\gamma$ (31), $\phi_2 \in [3\pi/2, 2\pi]$ for $\psi$ (33),
    /// and all $\phi_2$ for $\theta$ (32, which does not depend on the pose in eq 26).
    /// Lemma 1's proof (35)-(38) relies on the symmetries of eq 26 to extend these quarter
    /// ranges to the full circle; for another model check
    /// [`Certificate::lemma1_holds`].
    #[default]
    PaperQuarterRanges,
    /// The requirement of eq 30 itself, valid for any linear model:
    /// $\sum_i \chi_i |c_{ki}(\phi_2)| \le I_k$ for every $\phi_2 \in [0, 2\pi]$. For eq 26 it has
    /// the same optimum as the paper's form.
    FullRange,
}

impl ConstraintForm {
    /// The pose range of $\phi_2$ (rad) and whether absolute coefficients are used.
    #[must_use]
    pub fn range(self, axis: OrientationAxis) -> (f64, f64, bool) {
        match self {
            ConstraintForm::PaperQuarterRanges => match axis {
                OrientationAxis::Gamma => (0.0, FRAC_PI_2, false),
                OrientationAxis::Psi => (3.0 * FRAC_PI_2, TAU, false),
                OrientationAxis::Theta => (0.0, TAU, false),
            },
            ConstraintForm::FullRange => (0.0, TAU, true),
        }
    }
}

/// Where the weights come from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum WeightRule {
    /// $W = 1/$average sensitivity of the problem's model (eq 28, Figure 8).
    #[default]
    InverseAverageSensitivity,
    /// Given weights (validated against the model when allocating).
    Explicit(Weights),
}

/// The paper's sensitivity-weighted allocation (§4.2).
///
/// # Formula
/// For each angle $k \in \{\gamma, \theta, \psi\}$ (problems 31, 32, 33):
/// $$\min_{\chi_k} J_k = \sum_i \frac{W_{ki}^2}{\chi_{ki}^2}\quad\text{s.t.}\quad
/// f_k(\phi_2, \chi_k) \le I_k\ \ \forall \phi_2 \in \Phi_k,\qquad \chi_{ki} \ge \mathrm{LB}_i,$$
/// solved to the optimum by [`solve_inverse_square`] (clarabel power cones plus the exact
/// worst angle); then (34): $\mathrm{UB}_i = \min_k \chi^*_{ki}$ over the problems that
/// contain component $i$.
///
/// For eq 26 with $\mathrm{LB} = 0$ the optimum is known in closed form:
/// $\max_{\phi_2 \in [0,\pi/2]} f_\gamma = \sqrt{(x_1+x_5)^2 + (x_2+x_4)^2} + x_3$, and
/// $x_3 = I/(1 + \sqrt2\,(2\sqrt2\pi^2)^{1/3})$, $x_{1,2,4,5} = x_3 (\sqrt2\pi^2/4)^{1/3}$.
///
/// # Reference
/// Zhao et al. 2017, eq 28, problems (31)-(33), rule (34), Lemma 1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensitivityWeighted {
    /// The weights.
    pub weights: WeightRule,
    /// The constraint form.
    pub form: ConstraintForm,
}

impl SensitivityWeighted {
    /// The paper's method exactly as stated: inverse average sensitivities, quarter ranges.
    #[must_use]
    pub fn paper() -> Self {
        Self::default()
    }

    /// The weights this allocator uses on `problem`.
    #[must_use]
    pub fn weights_for(&self, problem: &AllocationProblem) -> Weights {
        match self.weights {
            WeightRule::InverseAverageSensitivity => {
                Weights::inverse_average_sensitivity(problem.model())
            }
            WeightRule::Explicit(w) => w,
        }
    }
}

impl Allocator for SensitivityWeighted {
    fn name(&self) -> &'static str {
        "sensitivity-weighted"
    }

    fn allocate(&self, problem: &AllocationProblem) -> Result<Allocation, AllocError> {
        let model = problem.model();
        let weights = match self.weights {
            WeightRule::InverseAverageSensitivity => Weights::inverse_average_sensitivity(model),
            WeightRule::Explicit(w) => Weights::new(model, w.matrix())?,
        };
        let lb = problem.lower_bounds_rad();
        let mut ub = [f64::INFINITY; CHI_LEN];
        let mut subproblems = Vec::new();
        for axis in [
            OrientationAxis::Gamma,
            OrientationAxis::Theta,
            OrientationAxis::Psi,
        ] {
            let components = model.involved(axis);
            if components.is_empty() {
                continue;
            }
            let (lo, hi, abs) = self.form.range(axis);
            let oracle = AxisOracle {
                model: *model,
                axis,
                components: components.clone(),
                lo,
                hi,
                abs,
                requirement_rad: problem.requirement().get(axis),
            };
            let lower: Vec<f64> = components.iter().map(|c| lb[c.index()]).collect();
            oracle.check_lower_bounds(&lower)?;
            let sub = InverseSquareProblem {
                label: axis.name().to_string(),
                names: components.iter().map(|c| c.name().to_string()).collect(),
                weights: components.iter().map(|&c| weights.get(axis, c)).collect(),
                lower,
                initial_cuts: oracle.grid(),
                oracle: &oracle,
            };
            let sol = solve_inverse_square(&sub)?;
            for (k, c) in components.iter().enumerate() {
                let u = &mut ub[c.index()];
                *u = u.min(sol.x[k]);
            }
            subproblems.push(Subproblem {
                axis,
                components,
                bounds_rad: sol.x,
                pose_range_rad: (lo, hi),
                objective: sol.objective,
                worst_phi2_rad: sol.worst.tag,
                load: sol.load,
                multiplier: sol.multiplier,
                iterations: sol.iterations,
            });
        }
        let certificate = Certificate::compute(model, &problem.requirement(), &lb, &ub);
        Ok(Allocation {
            method: self.name(),
            upper_bounds_rad: ub,
            lower_bounds_rad: lb,
            requirement: problem.requirement(),
            objective: weights.objective(&ub),
            weights,
            subproblems,
            certificate,
        })
    }
}
