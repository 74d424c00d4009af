//! The paper's allocator: sensitivity-weighted per-angle problems (31)-(33) and combination
//! rule (34), for any turntable.

use crate::allocation::{Allocation, Allocator, AxisOracle, Subproblem, finish};
use crate::error::AllocError;
use crate::problem::{AllocationProblem, Weights};
use crate::solver::{InverseSquareProblem, solve_inverse_square};
use std::f64::consts::{FRAC_PI_2, TAU};
use tt_kinematics::{LinearModel, OrientationAxis};

/// The order in which the per-angle problems are solved: (31) $\gamma$, (32) $\theta$,
/// (33) $\psi$.
pub(crate) const PROBLEM_ORDER: [OrientationAxis; 3] = [
    OrientationAxis::Gamma,
    OrientationAxis::Theta,
    OrientationAxis::Psi,
];

/// Which constraint each per-angle problem imposes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConstraintForm {
    /// Problems (31)-(33) as printed: $f_k(\phi_2, \chi_k) \le I_k$ (signed coefficients, no
    /// absolute values, $\chi_k \ge 0$) for the single free joint $\phi_2$ in
    /// $[0, \pi/2]$ for $\gamma$ (31), $[3\pi/2, 2\pi]$ for $\psi$ (33), and the full turn
    /// $[0, 2\pi]$ for $\theta$ (32, which does not depend on the pose in eq 26).
    ///
    /// Valid only for a turntable with exactly one free joint
    /// ([`AllocError::QuarterRangesNeedOneFreeJoint`] otherwise). Lemma 1's proof (35)-(38)
    /// relies on the symmetries of eq 26 to extend these quarter ranges to the full turn; for
    /// another table check [`crate::Certificate::lemma1_holds`], which is always computed
    /// over the turntable's joint ranges.
    #[default]
    PaperQuarterRanges,
    /// The requirement of eq 30 itself, valid for any turntable:
    /// $\sum_i \chi_i |c_{ki}(\phi)| \le I_k$ for every pose $\phi$ in the joint ranges. For
    /// eq 26 it has the same optimum as the paper's form.
    FullRange,
}

impl ConstraintForm {
    /// The joint ranges (rad, one `[lo, hi]` per joint) of the constraint of `axis` on
    /// `model`, and whether absolute coefficients are used.
    ///
    /// # Errors
    /// [`AllocError::QuarterRangesNeedOneFreeJoint`] for the paper's form on a turntable
    /// without exactly one free joint.
    pub fn pose_ranges(
        self,
        model: &LinearModel,
        axis: OrientationAxis,
    ) -> Result<(Vec<[f64; 2]>, bool), AllocError> {
        let mut ranges = model.turntable().joint_ranges_rad();
        match self {
            ConstraintForm::FullRange => Ok((ranges, true)),
            ConstraintForm::PaperQuarterRanges => {
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
                ranges[*j] = match axis {
                    OrientationAxis::Gamma => [0.0, FRAC_PI_2],
                    OrientationAxis::Psi => [3.0 * FRAC_PI_2, TAU],
                    OrientationAxis::Theta => [0.0, TAU],
                };
                Ok((ranges, false))
            }
        }
    }
}

/// Where the weights come from.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum WeightRule {
    /// $W = 1/$average sensitivity of the problem's model (eq 28, Figure 8).
    #[default]
    InverseAverageSensitivity,
    /// Given weights (validated against the model when allocating).
    Explicit(Weights),
}

/// The paper's sensitivity-weighted allocation (§4.2), for any turntable.
///
/// # Formula
/// For each angle $k$ with a requirement (problems 31, 32, 33 for $\gamma, \theta, \psi$):
/// $$\min_{\chi_k} J_k = \sum_i \frac{W_{ki}^2}{\chi_{ki}^2}\quad\text{s.t.}\quad
/// \sum_i \chi_{ki}\,c_{ki}(\phi) \le I_k\ \ \forall \phi \in \Phi_k,\qquad
/// \chi_{ki} \ge \mathrm{LB}_i,$$
/// ($|c_{ki}|$ in the full-range form), solved to the optimum by [`solve_inverse_square`]
/// (clarabel power cones plus the worst pose of [`LinearModel::max_signed_weighted`] /
/// [`LinearModel::max_abs_weighted`]); then (34) generalised:
/// $\mathrm{UB}_i = \min_k \chi^*_{ki}$ over the problems that contain error $i$. An error no
/// angle with a requirement depends on gets $\mathrm{UB}_i = +\infty$ and is listed in
/// [`Allocation::unconstrained`].
///
/// For eq 26 with $\mathrm{LB} = 0$ the optimum is known in closed form:
/// $\max_{\phi_2 \in [0,\pi/2]} f_\gamma = \sqrt{(x_1+x_5)^2 + (x_2+x_4)^2} + x_3$, and
/// $x_3 = I/(1 + \sqrt2\,(2\sqrt2\pi^2)^{1/3})$, $x_{1,2,4,5} = x_3 (\sqrt2\pi^2/4)^{1/3}$.
///
/// # Reference
/// Zhao et al. 2017, eq 28, problems (31)-(33), rule (34), Lemma 1.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensitivityWeighted {
    /// The weights.
    pub weights: WeightRule,
    /// The constraint form.
    pub form: ConstraintForm,
}

impl SensitivityWeighted {
    /// The paper's method exactly as stated: inverse average sensitivities, quarter ranges
    /// (only for a turntable with one free joint).
    #[must_use]
    pub fn paper() -> Self {
        Self::default()
    }

    /// The method for any turntable: inverse average sensitivities, the full-range
    /// constraint of eq 30.
    #[must_use]
    pub fn general() -> Self {
        Self {
            weights: WeightRule::InverseAverageSensitivity,
            form: ConstraintForm::FullRange,
        }
    }

    /// The weights this allocator uses on `problem`.
    ///
    /// # Errors
    /// As [`Weights::new`] for explicit weights that do not fit the model.
    pub fn weights_for(&self, problem: &AllocationProblem) -> Result<Weights, AllocError> {
        match &self.weights {
            WeightRule::InverseAverageSensitivity => {
                Ok(Weights::inverse_average_sensitivity(problem.model()))
            }
            WeightRule::Explicit(w) => Weights::new(problem.model(), w.matrix().clone()),
        }
    }
}

impl Allocator for SensitivityWeighted {
    fn name(&self) -> &'static str {
        "sensitivity-weighted"
    }

    fn allocate(&self, problem: &AllocationProblem) -> Result<Allocation, AllocError> {
        let model = problem.model();
        let weights = self.weights_for(problem)?;
        let names = problem.error_names();
        let lb = problem.lower_bounds_rad();
        let mut ub = vec![f64::INFINITY; model.n_errors()];
        let mut subproblems = Vec::new();
        for axis in PROBLEM_ORDER {
            let Some(requirement_rad) = problem.requirement().get(axis) else {
                continue;
            };
            let components = model.involved(axis);
            if components.is_empty() {
                continue;
            }
            let (ranges, abs) = self.form.pose_ranges(model, axis)?;
            let oracle = AxisOracle::new(
                model,
                axis,
                components.clone(),
                ranges.clone(),
                abs,
                requirement_rad,
            )?;
            let lower: Vec<f64> = components.iter().map(|&i| lb[i]).collect();
            oracle.check_lower_bounds(&lower, &names)?;
            oracle.check_each_bounded(&names)?;
            let sub = InverseSquareProblem {
                label: axis.name().to_string(),
                names: components.iter().map(|&i| names[i].clone()).collect(),
                weights: components.iter().map(|&i| weights.get(axis, i)).collect(),
                lower,
                initial_cuts: oracle.grid(),
                oracle: &oracle,
            };
            let sol = solve_inverse_square(&sub)?;
            let worst = oracle.search(&sol.x)?;
            for (k, &i) in components.iter().enumerate() {
                ub[i] = ub[i].min(sol.x[k]);
            }
            subproblems.push(Subproblem {
                axis,
                components,
                bounds_rad: sol.x,
                pose_ranges_rad: ranges,
                objective: Some(sol.objective),
                worst_pose_rad: worst.pose_rad,
                load: sol.load,
                multiplier: Some(sol.multiplier),
                iterations: sol.iterations,
                exact_oracle: oracle.exact(),
            });
        }
        finish(self.name(), problem, weights, ub, subproblems)
    }
}
