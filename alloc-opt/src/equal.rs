//! The traditional equal-effects allocation (the paper's comparison, its refs 20-21).

use crate::allocation::{Allocator, AxisOracle, Subproblem, ToleranceBox};
use crate::error::AllocError;
use crate::model::LinearErrorModel;
use crate::problem::{AllocationProblem, Weights};
use crate::solver::CutOracle;
use crate::weighted::{finish_two_step, for_each_axis};

/// Bisection steps on the common effect (the bracket shrinks to one ulp well before this).
const SHARE_BISECTION_STEPS: usize = 200;

/// Equal effects: every error of an angle contributes the same amount to its worst case.
///
/// # Formula
/// For angle $k$ with errors $\chi_k$, let $M_{ki} = \max_{\phi}|c_{ki}(\phi)|$ over the joint
/// ranges (the largest effect of a unit error). Equal effects means $x_{ki} M_{ki} = s_k$ for
/// all free errors; $s_k$ is the largest value that keeps the worst case
/// $\max_{\phi} \sum_i x_{ki}|c_{ki}(\phi)|$ within $I_k$, so the method gives the same
/// guarantee (Lemma 1) as the weighted allocator and uses the whole requirement. Errors whose
/// share falls below their lower bound are held at it and the others re-shared (water
/// filling). Then $\mathrm{UB}_i = \min_k x_{ki}$ as in (34); an error no angle with a
/// requirement depends on is unconstrained ($+\infty$).
///
/// For eq 26 with $\mathrm{LB} = 0$: every bound is $I/(1 + 2\sqrt 2)$ for $\gamma, \psi$ and
/// $I/2$ for $\theta$.
///
/// The reported objective is $J$ with the paper's weights (inverse average sensitivities)
/// so the two methods can be compared (the paper's conclusion 2).
///
/// # Reference
/// Zhao et al. 2017, §1 (refs 20-21) and conclusion 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EqualEffects;

impl<M: LinearErrorModel> Allocator<M> for EqualEffects {
    fn name(&self) -> &'static str {
        "equal-effects"
    }

    fn allocate(&self, problem: &AllocationProblem<M>) -> Result<ToleranceBox, AllocError> {
        let model = problem.model();
        let names = problem.error_names();
        let lb = problem.lower_bounds_rad();
        let mut subproblems = Vec::new();
        for_each_axis(
            model,
            problem.limits(),
            lb,
            &names,
            |k, components, oracle, lower| {
                let requirement_rad = oracle.requirement_rad;
                let x = share_equally(&oracle, &lower)?;
                let worst = oracle.search(&x)?;
                subproblems.push(Subproblem {
                    quantity: k,
                    name: oracle.name.clone(),
                    components,
                    bounds_rad: x,
                    objective: None,
                    load: worst.value / requirement_rad,
                    worst_pose_rad: worst.point,
                    multiplier: None,
                    iterations: 0,
                    exact_oracle: oracle.exact(),
                });
                Ok(())
            },
        )?;
        let weights = Weights::inverse_average_sensitivity(model);
        finish_two_step(problem, Allocator::<M>::name(self), weights, subproblems)
    }
}

/// Water filling: equal effects for the free errors, lower bounds held.
fn share_equally<M: LinearErrorModel + ?Sized>(
    oracle: &AxisOracle<'_, M>,
    lower: &[f64],
) -> Result<Vec<f64>, AllocError> {
    let n = lower.len();
    // Largest effect of a unit error of each component.
    let mut effect = Vec::with_capacity(n);
    for k in 0..n {
        let mut unit = vec![0.0; n];
        unit[k] = 1.0;
        let e = oracle.search(&unit)?.value;
        if !(e > 0.0 && e.is_finite()) {
            return Err(AllocError::NonFiniteResult {
                what: format!("largest effect of error {k} on {}", oracle.name),
                value: 1.0 / e,
            });
        }
        effect.push(e);
    }
    let mut fixed = vec![false; n];
    loop {
        let at = |s: f64| -> Vec<f64> {
            (0..n)
                .map(|i| if fixed[i] { lower[i] } else { s / effect[i] })
                .collect()
        };
        let load = |s: f64| {
            let v = at(s);
            oracle.most_violated(&v).load(&v)
        };
        // The load is increasing in s (non-negative coefficients); bisection for load = 1.
        let mut hi = oracle.requirement_rad;
        while load(hi) < 1.0 && hi < 1e6 * oracle.requirement_rad {
            hi *= 2.0;
        }
        let x = at(crate::solver::largest_within(
            0.0,
            hi,
            SHARE_BISECTION_STEPS,
            load,
        ));
        let newly: Vec<usize> = (0..n).filter(|&i| !fixed[i] && x[i] < lower[i]).collect();
        if newly.is_empty() || fixed.iter().all(|&f| f) {
            return Ok(x);
        }
        for i in newly {
            fixed[i] = true;
        }
        if fixed.iter().all(|&f| f) {
            return Ok(lower.to_vec());
        }
    }
}
