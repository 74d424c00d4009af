//! The traditional equal-effects allocation (the paper's comparison, its refs 20-21).

use crate::allocation::{Allocation, Allocator, AxisOracle, Certificate, Subproblem};
use crate::error::AllocError;
use crate::problem::{AllocationProblem, Weights};
use std::f64::consts::TAU;
use tt_kinematics::{CHI_LEN, ErrorComponent, OrientationAxis};

/// Equal effects: every error of an angle contributes the same amount to its worst case.
///
/// # Formula
/// For angle $k$ with components $\chi_k$, let $M_{ki} = \max_{\phi_2}|c_{ki}(\phi_2)|$ (the
/// largest effect of a unit error). Equal effects means $x_{ki} M_{ki} = s_k$ for all free
/// components; $s_k$ is the largest value that keeps the exact worst case
/// $\max_{\phi_2 \in [0, 2\pi]} \sum_i x_{ki}|c_{ki}(\phi_2)|$ within $I_k$, so the method gives
/// the same guarantee (Lemma 1) as the weighted allocator and uses the whole requirement.
/// Components whose share falls below their lower bound are held at it and the others
/// re-shared (water filling). Then $\mathrm{UB}_i = \min_k x_{ki}$ as in (34).
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

impl Allocator for EqualEffects {
    fn name(&self) -> &'static str {
        "equal-effects"
    }

    fn allocate(&self, problem: &AllocationProblem) -> Result<Allocation, AllocError> {
        let model = problem.model();
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
            let oracle = AxisOracle {
                model: *model,
                axis,
                components: components.clone(),
                lo: 0.0,
                hi: TAU,
                abs: true,
                requirement_rad: problem.requirement().get(axis),
            };
            let lower: Vec<f64> = components.iter().map(|c| lb[c.index()]).collect();
            oracle.check_lower_bounds(&lower)?;
            let x = share_equally(&oracle, &components, &lower);
            let worst = {
                use crate::solver::CutOracle;
                let w = oracle.most_violated(&x);
                (w.tag, w.load(&x))
            };
            for (k, c) in components.iter().enumerate() {
                let u = &mut ub[c.index()];
                *u = u.min(x[k]);
            }
            subproblems.push(Subproblem {
                axis,
                components,
                bounds_rad: x,
                pose_range_rad: (0.0, TAU),
                objective: f64::NAN,
                worst_phi2_rad: worst.0,
                load: worst.1,
                multiplier: f64::NAN,
                iterations: 0,
            });
        }
        let weights = Weights::inverse_average_sensitivity(model);
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

/// Water filling: equal effects for the free components, lower bounds held.
fn share_equally(oracle: &AxisOracle, components: &[ErrorComponent], lower: &[f64]) -> Vec<f64> {
    use crate::solver::CutOracle;
    let n = components.len();
    // Largest effect of a unit error of each component.
    let effect: Vec<f64> = components
        .iter()
        .map(|&c| {
            let mut w = [0.0; CHI_LEN];
            w[c.index()] = 1.0;
            oracle
                .model
                .max_abs_weighted(oracle.axis, &w, 0.0, TAU)
                .value
        })
        .collect();
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
        let mut lo = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if load(mid) <= 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let x = at(lo);
        let newly: Vec<usize> = (0..n).filter(|&i| !fixed[i] && x[i] < lower[i]).collect();
        if newly.is_empty() || fixed.iter().all(|&f| f) {
            return x;
        }
        for i in newly {
            fixed[i] = true;
        }
        if fixed.iter().all(|&f| f) {
            return lower.to_vec();
        }
    }
}
