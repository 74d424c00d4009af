//! The optimisation core: minimise a weighted sum of inverse squares under a (possibly
//! semi-infinite) family of linear constraints, with the `clarabel` conic solver.
//!
//! # Formula
//! $$\min_{x}\; J(x) = \sum_{i=1}^{n} \frac{w_i^2}{x_i^2}
//! \quad\text{s.t.}\quad \frac{a(t)^T x}{b(t)} \le 1\;\;\forall t \in T,
//! \qquad x_i \ge \ell_i \ge 0.$$
//!
//! $J$ is convex on $x > 0$ and each constraint is linear, so the problem is convex. Each term
//! is written with an epigraph variable $\tau_i \ge w_i^2/x_i^2$, which is the
//! three-dimensional power cone $(\tau_i, x_i, w_i^{2/3}) \in \mathcal K_{1/3} =
//! \{(u, v, z): u^{1/3} v^{2/3} \ge |z|,\ u, v \ge 0\}$, since
//! $\tau^{1/3} x^{2/3} \ge w^{2/3} \iff \tau x^2 \ge w^2$.
//!
//! When $T$ is infinite (every pose $\phi_2$ of a range) the problem is solved by the exchange
//! (cutting-plane) method: solve with a finite set of rows, ask the [`CutOracle`] for the
//! exact most violated row at the solution, add it, repeat until the relative violation is
//! below [`CUT_TOLERANCE`]. Finally the free components (those not at a lower bound) are
//! rescaled by one factor, found by bisection, so that the exact constraint is met with
//! $\max_t a(t)^T x / b(t) \in [1 - 10^{-13}, 1]$: the returned bounds are feasible and tight.
//!
//! Issue 7 (direct/yield-based allocation) reuses this core with a finite row set
//! ([`FiniteCuts`]): the rate errors are linear in $\chi$ at each calibration position.
//!
//! # Reference
//! Zhao et al. 2017, problems (31)-(33); the power-cone form is ours.

use crate::error::AllocError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

/// Stop the exchange method when the exact constraint exceeds 1 by less than this (relative).
/// The conic solver is run to about $10^{-10}$; the final rescaling removes what is left.
pub const CUT_TOLERANCE: f64 = 1e-9;

/// Maximum number of exchange iterations before [`AllocError::NoConvergence`].
pub const MAX_EXCHANGE_ITERATIONS: usize = 200;

/// Upper guard on each scaled variable (a component 10^4 times larger than the largest value
/// any single start row allows alone), so that every conic subproblem has a solution.
const SCALED_GUARD: f64 = 1e4;

/// A scaled variable above this (100 times what the start rows allow it alone) is reported as
/// unbounded: the rows do not bound it (its coefficients cancel or are never positive), and the
/// interior-point solver leaves it somewhere far up, where the objective is flat.
const SCALED_UNBOUNDED: f64 = 1e2;

/// A component is "at its lower bound" when within this relative distance of it.
const LOWER_ACTIVE_REL: f64 = 1e-7;

/// One linear constraint $a^T x \le b$ with $b > 0$, tagged (for example with its pose
/// $\phi_2$ in radians).
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// The row $a$ (one entry per variable).
    pub coefficients: Vec<f64>,
    /// The right-hand side $b > 0$.
    pub bound: f64,
    /// A label for the row, for example the inner-axis angle $\phi_2$ (rad) it came from.
    pub tag: f64,
}

impl Cut {
    /// $a^T x / b$: the share of the bound used at `x` (1 means tight).
    #[must_use]
    pub fn load(&self, x: &[f64]) -> f64 {
        self.coefficients
            .iter()
            .zip(x)
            .map(|(a, v)| a * v)
            .sum::<f64>()
            / self.bound
    }
}

/// The exact separation oracle of a semi-infinite constraint family.
///
/// # Example
/// ```
/// use alloc_opt::solver::{Cut, CutOracle, FiniteCuts};
/// let rows = FiniteCuts::new(vec![
///     Cut { coefficients: vec![1.0, 0.0], bound: 1.0, tag: 0.0 },
///     Cut { coefficients: vec![1.0, 1.0], bound: 1.0, tag: 1.0 },
/// ]);
/// assert_eq!(rows.most_violated(&[0.5, 0.25]).tag, 1.0);
/// ```
pub trait CutOracle {
    /// The row with the largest load $a^T x / b$ at `x` (found exactly, not on a grid).
    fn most_violated(&self, x: &[f64]) -> Cut;
}

/// A finite set of rows: the oracle scans them all.
#[derive(Debug, Clone, PartialEq)]
pub struct FiniteCuts {
    rows: Vec<Cut>,
}

impl FiniteCuts {
    /// A finite constraint set (it must not be empty when used).
    #[must_use]
    pub fn new(rows: Vec<Cut>) -> Self {
        Self { rows }
    }

    /// The rows.
    #[must_use]
    pub fn rows(&self) -> &[Cut] {
        &self.rows
    }
}

impl CutOracle for FiniteCuts {
    fn most_violated(&self, x: &[f64]) -> Cut {
        let mut best: Option<(f64, &Cut)> = None;
        for r in &self.rows {
            let l = r.load(x);
            if best.is_none_or(|(b, _)| l > b) {
                best = Some((l, r));
            }
        }
        best.map_or_else(
            || Cut {
                coefficients: vec![0.0; x.len()],
                bound: 1.0,
                tag: f64::NAN,
            },
            |(_, r)| r.clone(),
        )
    }
}

/// A problem $\min \sum w_i^2/x_i^2$ s.t. the oracle's rows and $x \ge \ell$.
pub struct InverseSquareProblem<'a> {
    /// A label used in error messages (for example `"gamma"`).
    pub label: String,
    /// Variable names, used in error messages.
    pub names: Vec<String>,
    /// The weights $w_i > 0$.
    pub weights: Vec<f64>,
    /// The lower bounds $\ell_i \ge 0$.
    pub lower: Vec<f64>,
    /// Rows to start from (at least one; a grid of poses is a good start).
    pub initial_cuts: Vec<Cut>,
    /// The exact separation oracle of the whole (possibly infinite) row family.
    pub oracle: &'a dyn CutOracle,
}

impl std::fmt::Debug for InverseSquareProblem<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InverseSquareProblem")
            .field("label", &self.label)
            .field("names", &self.names)
            .field("weights", &self.weights)
            .field("lower", &self.lower)
            .field("initial_cuts", &self.initial_cuts.len())
            .finish_non_exhaustive()
    }
}

/// The optimum of an [`InverseSquareProblem`] and how it was reached.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseSquareSolution {
    /// The optimal $x$ (feasible for the exact row family).
    pub x: Vec<f64>,
    /// $J(x) = \sum w_i^2/x_i^2$.
    pub objective: f64,
    /// The most loaded row at `x` (its `tag` is the worst pose).
    pub worst: Cut,
    /// Its load $\max_t a(t)^T x/b(t)$, in $[1 - 10^{-13}, 1]$ when the constraint is active.
    pub load: f64,
    /// Sum of the conic solver's multipliers of the rows, in units of $J$ (for the
    /// dimensionless constraint $a^T x / b \le 1$): the KKT condition reads
    /// $2 w_i^2 / x_i^3 = \lambda\, a_i / b$ for a free component with one active row.
    pub multiplier: f64,
    /// Which components sit at their (positive) lower bound.
    pub at_lower_bound: Vec<bool>,
    /// Exchange iterations (conic solves).
    pub iterations: usize,
    /// Rows in the last conic problem.
    pub cuts: usize,
    /// Whether the single-active-row KKT polish replaced the interior-point point (it is
    /// kept only when exact and not worse; otherwise the conic solution is returned).
    pub polished: bool,
}

/// Solve an [`InverseSquareProblem`] to the optimum (see the module documentation).
///
/// # Errors
/// [`AllocError::Malformed`] for inconsistent lengths or an empty start set,
/// [`AllocError::NonFinite`]/[`AllocError::NotPositive`]/[`AllocError::Negative`] for bad
/// weights, bounds or rows, [`AllocError::Unbounded`] when the rows do not bound a component,
/// [`AllocError::Solver`] when clarabel fails, [`AllocError::NoConvergence`] when the exchange
/// method stalls. Lower bounds that violate the rows give [`AllocError::Malformed`]; the
/// allocators check them first and report [`AllocError::InfeasibleLowerBounds`].
pub fn solve_inverse_square(
    p: &InverseSquareProblem<'_>,
) -> Result<InverseSquareSolution, AllocError> {
    use crate::error::{finite, non_negative, positive};
    let n = p.weights.len();
    let malformed = |reason: String| AllocError::Malformed {
        problem: p.label.clone(),
        reason,
    };
    if n == 0 || p.lower.len() != n || p.names.len() != n {
        return Err(malformed(format!(
            "{} weights, {} lower bounds, {} names",
            n,
            p.lower.len(),
            p.names.len()
        )));
    }
    if p.initial_cuts.is_empty() {
        return Err(malformed("no initial rows".into()));
    }
    for i in 0..n {
        positive(format!("weights.{}", p.names[i]), p.weights[i])?;
        non_negative(format!("lower_bounds.{}", p.names[i]), p.lower[i])?;
    }
    for c in &p.initial_cuts {
        if c.coefficients.len() != n {
            return Err(malformed(
                "row length differs from the variable count".into(),
            ));
        }
        positive(format!("{}.row_bound", p.label), c.bound)?;
        for &a in &c.coefficients {
            finite(format!("{}.row_coefficient", p.label), a)?;
        }
    }
    let lower_load = p.oracle.most_violated(&p.lower).load(&p.lower);
    if lower_load > 1.0 {
        return Err(malformed(format!(
            "the lower bounds alone load the constraint to {lower_load}"
        )));
    }

    // Variable scaling: sigma_i = 1 / (largest a_i/b of the start rows), so each scaled
    // column has largest entry 1; objective scaled so its largest weight is 1.
    let mut sigma = vec![f64::NAN; n];
    for (i, s) in sigma.iter_mut().enumerate() {
        let m = p
            .initial_cuts
            .iter()
            .map(|c| c.coefficients[i] / c.bound)
            .fold(0.0_f64, f64::max);
        if m > 0.0 {
            *s = 1.0 / m;
        }
    }
    let fallback = sigma
        .iter()
        .copied()
        .filter(|s| s.is_finite())
        .fold(f64::NAN, f64::max);
    let fallback = if fallback.is_finite() { fallback } else { 1.0 };
    for s in &mut sigma {
        if !s.is_finite() {
            *s = fallback;
        }
    }
    let scaled_w: Vec<f64> = (0..n).map(|i| p.weights[i] / sigma[i]).collect();
    let wmax = scaled_w.iter().copied().fold(0.0_f64, f64::max);
    let cone_const: Vec<f64> = scaled_w
        .iter()
        .map(|w| (w / wmax).powf(2.0 / 3.0))
        .collect();
    let lower_scaled: Vec<f64> = (0..n).map(|i| p.lower[i] / sigma[i]).collect();

    let mut cuts: Vec<Cut> = p.initial_cuts.clone();
    let mut iterations = 0;
    let (x, multiplier) = loop {
        iterations += 1;
        let (y, duals) = conic_solve(&p.label, &cuts, &sigma, &cone_const, &lower_scaled)?;
        let unbounded: Vec<String> = (0..n)
            .filter(|&i| y[i] > SCALED_UNBOUNDED)
            .map(|i| p.names[i].clone())
            .collect();
        if !unbounded.is_empty() {
            return Err(AllocError::Unbounded {
                problem: p.label.clone(),
                components: unbounded,
            });
        }
        let x: Vec<f64> = (0..n).map(|i| (y[i] * sigma[i]).max(p.lower[i])).collect();
        let worst = p.oracle.most_violated(&x);
        let load = worst.load(&x);
        let lambda = duals.iter().sum::<f64>() * wmax * wmax;
        if load <= 1.0 + CUT_TOLERANCE {
            break (x, lambda);
        }
        if iterations >= MAX_EXCHANGE_ITERATIONS {
            return Err(AllocError::NoConvergence {
                problem: p.label.clone(),
                iterations,
                violation: load - 1.0,
            });
        }
        cuts.push(worst);
    };

    let x = restore_tightness(p, x);
    let objective_of = |x: &[f64]| -> f64 { (0..n).map(|i| (p.weights[i] / x[i]).powi(2)).sum() };
    let (x, multiplier, polished) = match polish_single_row(p, &x) {
        Some((xp, lambda)) if objective_of(&xp) <= objective_of(&x) * (1.0 + POLISH_ACCEPT_REL) => {
            (xp, lambda, true)
        }
        _ => (x, multiplier, false),
    };
    let worst = p.oracle.most_violated(&x);
    let load = worst.load(&x);
    let objective = (0..n).map(|i| (p.weights[i] / x[i]).powi(2)).sum();
    let at_lower_bound = (0..n)
        .map(|i| p.lower[i] > 0.0 && x[i] <= p.lower[i] * (1.0 + LOWER_ACTIVE_REL))
        .collect();
    Ok(InverseSquareSolution {
        x,
        objective,
        worst,
        load,
        multiplier,
        at_lower_bound,
        iterations,
        cuts: cuts.len(),
        polished,
    })
}

/// A polished point is kept when its objective is not above the interior-point one by more
/// than this (relative): the polish is exact where it applies, so it only ever gains.
const POLISH_ACCEPT_REL: f64 = 1e-12;

/// Polish for the common case of one active pose: solve the KKT conditions of the single
/// most loaded row exactly and repeat with the new worst row.
///
/// # Formula
/// With one active row $a$, stationarity gives $x_i(\lambda) = \max\big(\ell_i,
/// (2 w_i^2 b / (\lambda a_i))^{1/3}\big)$; $a^T x(\lambda)$ decreases in $\lambda$, so
/// $a^T x(\lambda) = b$ is solved by bisection on $\ln\lambda$. The interior-point solution
/// is accurate only to about the square root of its duality gap in $x$ (the objective is flat
/// at the optimum); this brings $x$ to rounding accuracy. Returns `None` (keep the
/// interior-point point) when a free component has $a_i \le 0$ or the iteration does not
/// settle, which happens when several poses are active.
fn polish_single_row(p: &InverseSquareProblem<'_>, x0: &[f64]) -> Option<(Vec<f64>, f64)> {
    let n = x0.len();
    let mut x = x0.to_vec();
    let mut lambda = f64::NAN;
    for _ in 0..60 {
        let row = p.oracle.most_violated(&x);
        let a = &row.coefficients;
        let b = row.bound;
        let at = |lam: f64| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    if a[i] > 0.0 {
                        (2.0 * p.weights[i].powi(2) * b / (lam * a[i]))
                            .cbrt()
                            .max(p.lower[i])
                    } else {
                        p.lower[i]
                    }
                })
                .collect()
        };
        // A component with a_i <= 0 at the active row is bounded only by other rows.
        if (0..n).any(|i| a[i] <= 0.0 && x[i] > p.lower[i] * (1.0 + LOWER_ACTIVE_REL)) {
            return None;
        }
        let load = |lam: f64| row.load(&at(lam));
        let (mut lo, mut hi) = (-300.0_f64, 300.0_f64);
        if load(lo.exp()) < 1.0 || load(hi.exp()) > 1.0 {
            return None;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            // load decreases with lambda: keep load(exp(hi)) <= 1.
            if load(mid.exp()) > 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lambda = hi.exp();
        let next = at(lambda);
        let change = (0..n)
            .map(|i| ((next[i] - x[i]) / x[i]).abs())
            .fold(0.0_f64, f64::max);
        x = next;
        if change <= 4.0 * f64::EPSILON {
            let x = restore_tightness(p, x);
            return Some((x, lambda));
        }
    }
    let _ = lambda;
    None
}

/// Rescale the free components by one factor $s$ (bisection on the exact load) so that the
/// load lies in $[1 - 10^{-13}, 1]$; components at a lower bound stay put.
fn restore_tightness(p: &InverseSquareProblem<'_>, x: Vec<f64>) -> Vec<f64> {
    let n = x.len();
    let free: Vec<bool> = (0..n)
        .map(|i| x[i] > p.lower[i] * (1.0 + LOWER_ACTIVE_REL))
        .collect();
    if !free.iter().any(|&f| f) {
        return x;
    }
    let at = |s: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                if free[i] {
                    (x[i] * s).max(p.lower[i])
                } else {
                    x[i]
                }
            })
            .collect()
    };
    let load = |s: f64| {
        let v = at(s);
        p.oracle.most_violated(&v).load(&v)
    };
    let g1 = load(1.0);
    let (mut lo, mut hi) = if g1 > 1.0 {
        (0.0, 1.0)
    } else {
        let hi = 1.0 + 16.0 * (1.0 - g1) + 1e-12;
        if load(hi) <= 1.0 {
            return x;
        }
        (1.0, hi)
    };
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
    at(lo)
}

/// One conic solve with a finite row set. Returns the scaled solution $y$ and the duals of
/// the rows (in the normalised objective's units).
fn conic_solve(
    label: &str,
    cuts: &[Cut],
    sigma: &[f64],
    cone_const: &[f64],
    lower_scaled: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), AllocError> {
    let n = sigma.len();
    let m_cuts = cuts.len();
    // Variables: y_0..y_{n-1}, tau_0..tau_{n-1}.
    let nv = 2 * n;
    let (mut ri, mut ci, mut vals, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut row = 0;
    for c in cuts {
        for (i, (coef, sig)) in c.coefficients.iter().zip(sigma).enumerate() {
            let a = coef * sig / c.bound;
            if a != 0.0 {
                ri.push(row);
                ci.push(i);
                vals.push(a);
            }
        }
        b.push(1.0);
        row += 1;
    }
    for (i, &l) in lower_scaled.iter().enumerate() {
        // -y_i + s = -l  =>  s = y_i - l >= 0
        ri.push(row);
        ci.push(i);
        vals.push(-1.0);
        b.push(-l);
        row += 1;
    }
    for i in 0..n {
        // y_i + s = guard
        ri.push(row);
        ci.push(i);
        vals.push(1.0);
        b.push(SCALED_GUARD);
        row += 1;
    }
    let nonneg = row;
    for (i, &k) in cone_const.iter().enumerate() {
        // (tau_i, y_i, k) in K_{1/3}: s = b - A z.
        ri.push(row);
        ci.push(n + i);
        vals.push(-1.0);
        b.push(0.0);
        ri.push(row + 1);
        ci.push(i);
        vals.push(-1.0);
        b.push(0.0);
        b.push(k);
        row += 3;
    }
    let a = CscMatrix::new_from_triplets(row, nv, ri, ci, vals);
    let pm = CscMatrix::zeros((nv, nv));
    let mut q = vec![0.0; nv];
    for v in q.iter_mut().skip(n) {
        *v = 1.0;
    }
    let mut cones = vec![SupportedConeT::NonnegativeConeT(nonneg)];
    cones.extend((0..n).map(|_| SupportedConeT::PowerConeT(1.0 / 3.0)));
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 200,
        tol_gap_abs: 1e-11,
        tol_gap_rel: 1e-11,
        tol_feas: 1e-11,
        tol_ktratio: 1e-8,
        ..DefaultSettings::default()
    };
    let mut solver =
        DefaultSolver::new(&pm, &q, &a, &b, &cones, settings).map_err(|e| AllocError::Solver {
            problem: label.to_string(),
            status: e.to_string(),
        })?;
    solver.solve();
    let sol = &solver.solution;
    match sol.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        other => {
            return Err(AllocError::Solver {
                problem: label.to_string(),
                status: format!("{other:?}"),
            });
        }
    }
    let y = sol.x[..n].to_vec();
    if y.iter().any(|v| !v.is_finite()) {
        return Err(AllocError::Solver {
            problem: label.to_string(),
            status: "non-finite solution".into(),
        });
    }
    Ok((y, sol.z[..m_cuts].to_vec()))
}
