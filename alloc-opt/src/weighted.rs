//! The paper's allocator: sensitivity-weighted per-angle problems (31)-(33) and combination
//! rule (34), for any turntable.

use crate::allocation::{
    Allocator, AxisOracle, MethodDetails, Subproblem, ToleranceBox, combine_rule_34, finish,
};
use crate::error::AllocError;
use crate::model::{LinearErrorModel, QuarterRanges};
use crate::problem::{AllocationProblem, Weights, error_names};
use crate::solver::{InverseSquareProblem, solve_inverse_square};
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
    /// Valid only for a turntable's [`LinearModel`] with exactly one free joint
    /// ([`AllocError::QuarterRangesNeedOneFreeJoint`] otherwise,
    /// [`AllocError::NotApplicable`] for another model). Lemma 1's proof (35)-(38) relies on
    /// the symmetries of eq 26 to extend these quarter ranges to the full turn; for another
    /// table check [`crate::Certificate::lemma1_holds`], which is always computed over the
    /// turntable's joint ranges. Implemented as a wrapper model around the turntable's
    /// (its constraint search), not as a branch of the general method.
    #[default]
    PaperQuarterRanges,
    /// The requirement of eq 30 itself, valid for any model:
    /// $\sum_i \chi_i |c_{ki}(p)| \le I_k$ for every point $p$ of the model's domain (every
    /// pose in the joint ranges). For eq 26 it has the same optimum as the paper's form.
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
        match self {
            ConstraintForm::FullRange => Ok((model.turntable().joint_ranges_rad(), true)),
            ConstraintForm::PaperQuarterRanges => {
                Ok((QuarterRanges::new(model)?.ranges(axis.index()), false))
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
/// [`ToleranceBox::unconstrained`].
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
    pub(crate) fn weights_for<M: LinearErrorModel>(
        &self,
        problem: &AllocationProblem<M>,
    ) -> Result<Weights, AllocError> {
        match &self.weights {
            WeightRule::InverseAverageSensitivity => {
                Ok(Weights::inverse_average_sensitivity(problem.model()))
            }
            WeightRule::Explicit(w) => Weights::new(problem.model(), w.matrix().clone()),
        }
    }
}

/// The per-quantity order of the two-step methods: (31) $\gamma$, (32) $\theta$, (33)
/// $\psi$ for a model of the three angles, the model's order reversed in general.
pub(crate) fn problem_order(n_quantities: usize) -> Vec<usize> {
    if n_quantities == 3 {
        PROBLEM_ORDER.iter().map(|a| a.index()).collect()
    } else {
        (0..n_quantities).rev().collect()
    }
}

/// The sensitivity-weighted per-quantity problems over `search` (the model itself, or the
/// paper's quarter-range wrapper).
fn two_step<S: LinearErrorModel + ?Sized>(
    search: &S,
    limits: &[Option<f64>],
    lb: &[f64],
    weights: &Weights,
) -> Result<Vec<Subproblem>, AllocError> {
    let names = error_names(search);
    let mut subproblems = Vec::new();
    for_each_axis(
        search,
        limits,
        lb,
        &names,
        |k, components, oracle, lower| {
            oracle.check_each_bounded(&names)?;
            let sub = InverseSquareProblem {
                label: oracle.name.clone(),
                names: components.iter().map(|&i| names[i].clone()).collect(),
                weights: components.iter().map(|&i| weights.of(k, i)).collect(),
                lower,
                initial_cuts: oracle.grid(),
                oracle: &oracle,
            };
            let sol = solve_inverse_square(&sub)?;
            let worst = oracle.search(&sol.x)?;
            subproblems.push(Subproblem {
                quantity: k,
                name: oracle.name.clone(),
                components,
                bounds_rad: sol.x,
                objective: Some(sol.objective),
                worst_pose_rad: worst.point,
                load: sol.load,
                multiplier: Some(sol.multiplier),
                iterations: sol.iterations,
                exact_oracle: oracle.exact(),
            });
            Ok(())
        },
    )?;
    Ok(subproblems)
}

/// For each quantity with a requirement and errors involved, in [`problem_order`]: its
/// oracle over `search` and its errors' lower bounds (checked to leave room in the
/// requirement), handed to `each(quantity, components, oracle, lower)`.
pub(crate) fn for_each_axis<'m, S: LinearErrorModel + ?Sized>(
    search: &'m S,
    limits: &[Option<f64>],
    lb: &[f64],
    names: &[String],
    mut each: impl FnMut(usize, Vec<usize>, AxisOracle<'m, S>, Vec<f64>) -> Result<(), AllocError>,
) -> Result<(), AllocError> {
    for k in problem_order(search.n_quantities()) {
        let Some(requirement_rad) = limits[k] else {
            continue;
        };
        let components = search.involved(k);
        if components.is_empty() {
            continue;
        }
        let oracle = AxisOracle::new(search, k, components.clone(), requirement_rad)?;
        let lower: Vec<f64> = components.iter().map(|&i| lb[i]).collect();
        oracle.check_lower_bounds(&lower, names)?;
        each(k, components, oracle, lower)?;
    }
    Ok(())
}

/// The end of a two-step method: the per-quantity bounds of `subproblems` combined by rule
/// (34) over the model's errors (`+inf` for an error no subproblem bounds), then [`finish`].
pub(crate) fn finish_two_step<M: LinearErrorModel>(
    problem: &AllocationProblem<M>,
    method: &str,
    weights: Weights,
    subproblems: Vec<Subproblem>,
) -> Result<ToleranceBox, AllocError> {
    let solutions: Vec<(&[usize], &[f64])> = subproblems
        .iter()
        .map(|s| (s.components.as_slice(), s.bounds_rad.as_slice()))
        .collect();
    let ub = combine_rule_34(problem.model().n_errors(), &solutions);
    finish(
        problem,
        method,
        weights,
        ub,
        MethodDetails::TwoStep { subproblems },
    )
}

impl<M: LinearErrorModel + 'static> Allocator<M> for SensitivityWeighted {
    fn name(&self) -> &'static str {
        "sensitivity-weighted"
    }

    fn allocate(&self, problem: &AllocationProblem<M>) -> Result<ToleranceBox, AllocError> {
        let weights = self.weights_for(problem)?;
        let subproblems = match self.form {
            ConstraintForm::FullRange => two_step(
                problem.model(),
                problem.limits(),
                problem.lower_bounds_rad(),
                &weights,
            )?,
            ConstraintForm::PaperQuarterRanges => {
                let any: &dyn std::any::Any = problem.model();
                let Some(model) = any.downcast_ref::<LinearModel>() else {
                    return Err(AllocError::NotApplicable {
                        method: "sensitivity-weighted (paper's quarter ranges)".into(),
                        reason: "the quarter ranges of problems (31)-(33) are ranges of a \
                                 turntable's free joint; use the full-range form"
                            .into(),
                    });
                };
                // As before the wrapper: only a constrained quantity needs the ranges.
                let constrained =
                    problem.limits().iter().enumerate().any(|(k, l)| {
                        l.is_some() && !LinearErrorModel::involved(model, k).is_empty()
                    });
                if constrained {
                    two_step(
                        &QuarterRanges::new(model)?,
                        problem.limits(),
                        problem.lower_bounds_rad(),
                        &weights,
                    )?
                } else {
                    // every bound +inf (rule (34) over no subproblem)
                    Vec::new()
                }
            }
        };
        finish_two_step(problem, Allocator::<M>::name(self), weights, subproblems)
    }
}
