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
//! When $T$ is infinite (every pose $\phi$ in the joint ranges of a turntable) the problem is
//! solved by the exchange (cutting-plane) method: solve with a finite set of rows, ask the
//! [`CutOracle`] for the most violated row at the solution, add it, repeat until the relative
//! violation is below [`CUT_TOLERANCE`]. The allocators' oracle is the worst pose of the
//! linear model ([`tt_kinematics::LinearModel::max_signed_weighted`] /
//! [`tt_kinematics::LinearModel::max_abs_weighted`]): exact for at most one free joint, a
//! grid-and-refine search otherwise (the allocators then make the final bounds safe with a
//! rigorous bound, see [`crate::Certificate`]). Then the free components (those not at a
//! lower bound) are rescaled by one factor, found by bisection, so that the constraint is met
//! with $\max_t a(t)^T x / b(t) \in [1 - 10^{-13}, 1]$: the returned bounds are feasible and
//! tight.
//!
//! The interior-point $x$ is accurate only to about the square root of its duality gap
//! ($\sim 10^{-6}$: $J$ is flat at the optimum), so a KKT polish follows: exact for one active
//! row, and for several an active-set Newton method on the KKT system whose rows the oracle
//! moves to their exact worst poses. A polished point replaces the interior-point one only
//! when it is not worse ([`InverseSquareSolution::polished`]).
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
pub(crate) const CUT_TOLERANCE: f64 = 1e-9;

/// Maximum number of exchange iterations before [`AllocError::NoConvergence`].
pub(crate) const MAX_EXCHANGE_ITERATIONS: usize = 200;

/// Upper guard on each scaled variable (a component 10^4 times larger than the largest value
/// any single start row allows alone), so that every conic subproblem has a solution.
const SCALED_GUARD: f64 = 1e4;

/// A scaled variable above this (100 times what the start rows allow it alone) is reported as
/// unbounded: the rows do not bound it (its coefficients cancel or are never positive), and the
/// interior-point solver leaves it somewhere far up, where the objective is flat.
const SCALED_UNBOUNDED: f64 = 1e2;

/// A component is "at its lower bound" when within this relative distance of it.
const LOWER_ACTIVE_REL: f64 = 1e-7;

/// One linear constraint $a^T x \le b$ with $b > 0$, tagged with a scalar label (the
/// allocators' rows carry the angle of the turntable's last free joint, $\phi_2$ for the
/// paper's table; a finite row set can carry its row index).
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// The row $a$ (one entry per variable).
    pub coefficients: Vec<f64>,
    /// The right-hand side $b > 0$.
    pub bound: f64,
    /// A label for the row, for example the angle (rad) of the last free joint of the pose
    /// it came from, or a row index.
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

/// The separation oracle of a semi-infinite constraint family.
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
    /// The row with the largest load $a^T x / b$ at `x` (exactly where possible; an inexact
    /// oracle makes the solution feasible only for the rows it finds).
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
    /// The separation oracle of the whole (possibly infinite) row family.
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
#[non_exhaustive]
pub struct InverseSquareSolution {
    /// The optimal $x$ (feasible for the exact row family).
    pub(crate) x: Vec<f64>,
    /// $J(x) = \sum w_i^2/x_i^2$.
    pub(crate) objective: f64,
    /// The most loaded row at `x` (its `tag` labels the worst pose).
    pub(crate) worst: Cut,
    /// Its load $\max_t a(t)^T x/b(t)$, in $[1 - 10^{-13}, 1]$ when the constraint is active.
    pub(crate) load: f64,
    /// Sum of the conic solver's multipliers of the rows, in units of $J$ (for the
    /// dimensionless constraint $a^T x / b \le 1$): the KKT condition reads
    /// $2 w_i^2 / x_i^3 = \lambda\, a_i / b$ for a free component with one active row.
    pub(crate) multiplier: f64,
    /// Which components sit at their (positive) lower bound.
    pub(crate) at_lower_bound: Vec<bool>,
    /// Exchange iterations (conic solves).
    pub(crate) iterations: usize,
    /// Rows in the last conic problem.
    pub(crate) cuts: usize,
    /// Whether a KKT polish (one active row, or an active set of rows refined by the oracle)
    /// replaced the interior-point point (it is kept only when exact and not worse;
    /// otherwise the conic solution is returned).
    pub(crate) polished: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl InverseSquareSolution {
    /// The optimal $x$ (feasible for the exact row family).
    #[must_use]
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// $J(x) = \sum w_i^2/x_i^2$.
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The most loaded row at `x` (its `tag` labels the worst pose).
    #[must_use]
    pub fn worst(&self) -> &Cut {
        &self.worst
    }

    /// Its load $\max_t a(t)^T x/b(t)$, in $[1 - 10^{-13}, 1]$ when the constraint is active.
    #[must_use]
    pub fn load(&self) -> f64 {
        self.load
    }

    /// Sum of the conic solver's multipliers of the rows, in units of $J$ (for the
    /// dimensionless constraint $a^T x / b \le 1$): the KKT condition reads
    /// $2 w_i^2 / x_i^3 = \lambda\, a_i / b$ for a free component with one active row.
    #[must_use]
    pub fn multiplier(&self) -> f64 {
        self.multiplier
    }

    /// Which components sit at their (positive) lower bound.
    #[must_use]
    pub fn at_lower_bound(&self) -> &[bool] {
        &self.at_lower_bound
    }

    /// Exchange iterations (conic solves).
    #[must_use]
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Rows in the last conic problem.
    #[must_use]
    pub fn cuts(&self) -> usize {
        self.cuts
    }

    /// Whether a KKT polish (one active row, or an active set of rows refined by the oracle)
    /// replaced the interior-point point (it is kept only when exact and not worse;
    /// otherwise the conic solution is returned).
    #[must_use]
    pub fn polished(&self) -> bool {
        self.polished
    }
}

/// Solve an [`InverseSquareProblem`] to the optimum (see the module documentation).
///
/// # Errors
/// [`AllocError::Malformed`] for inconsistent lengths or an empty start set,
/// [`AllocError::Field`] (not finite, not positive, negative) for bad
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
    let (x, multiplier, duals) = loop {
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
            break (x, lambda, duals);
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
    let polish = polish_single_row(p, &x).or_else(|| {
        // Rows with a multiplier, largest first, without near-copies (the exchange method
        // leaves successive refinements of the same active pose).
        let max_dual = duals.iter().copied().fold(0.0_f64, f64::max);
        let mut order: Vec<usize> = (0..cuts.len())
            .filter(|&r| duals[r] > ACTIVE_DUAL_REL * max_dual)
            .collect();
        order.sort_by(|&a, &b| duals[b].total_cmp(&duals[a]));
        let mut active: Vec<Cut> = Vec::new();
        for r in order {
            if !active.iter().any(|c| same_row(c, &cuts[r])) {
                active.push(cuts[r].clone());
            }
        }
        polish_active_rows(p, &x, active)
    });
    let (x, multiplier, polished) = match polish {
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

/// A row of the last conic problem starts the active-set polish when its multiplier is above
/// this fraction of the largest one.
const ACTIVE_DUAL_REL: f64 = 1e-6;

/// Rounds of the active-set polish (one oracle call each).
const ACTIVE_SET_ROUNDS: usize = 40;

/// Newton steps on the KKT system of one active set (quadratic convergence from the
/// interior-point point takes a handful).
const NEWTON_STEPS: usize = 60;

/// A point of the active-set polish is accepted when the oracle's most loaded row exceeds the
/// constraint by at most this (relative); the one-factor rescaling then moves it by as much.
const POLISH_LOAD_REL: f64 = 1e-12;

/// The active-set polish stops refining the poses when the excess is at most this (relative,
/// a few ulp of a load of 1): the rows are then at the worst poses to within rounding (the
/// excess is second order in the pose error, so the poses are within about $10^{-8}$ rad).
const POLISH_LOAD_TARGET: f64 = 4.0 * f64::EPSILON;

/// The oracle's row replaces an active row (it is that row's refinement, at a nearby pose)
/// when their normalised coefficients differ by less than this, relative to the largest.
const SAME_ROW_REL: f64 = 1e-3;

/// Polish for several active rows (poses): an active-set method on the KKT conditions.
///
/// # Formula
/// With active rows $a_r$ (normalised by $b_r$) and free components $F$, the optimum of
/// $\min \sum_{i \in F} w_i^2/x_i^2$ s.t. $\sum_i a_{ri} x_i / b_r = 1$ satisfies
/// $2 w_i^2 / x_i^3 = \sum_r \lambda_r a_{ri}/b_r$; Newton's method on these equations
/// (in the variables $x_i / x_i^{(0)}$, so that the system is well scaled) converges
/// quadratically from the interior-point point. Rows with a negative multiplier are dropped;
/// then the oracle's most loaded row at the new point replaces the row it refines (or joins
/// the set), until no row exceeds the constraint by more than [`POLISH_LOAD_TARGET`]. For a
/// semi-infinite family this moves each active pose to its maximiser (linearly, by a factor
/// of about ten per round on the three-axis example). Returns the best point within
/// [`POLISH_LOAD_REL`], or `None` (keep the interior-point point) when there is none: the
/// system is singular, a free component would reach its lower bound, or the rounds run out.
fn polish_active_rows(
    p: &InverseSquareProblem<'_>,
    x0: &[f64],
    mut active: Vec<Cut>,
) -> Option<(Vec<f64>, f64)> {
    let n = x0.len();
    let free: Vec<usize> = (0..n)
        .filter(|&i| x0[i] > p.lower[i] * (1.0 + LOWER_ACTIVE_REL))
        .collect();
    if free.is_empty() {
        return None;
    }
    let mut x = x0.to_vec();
    // The best point whose load is within POLISH_LOAD_REL, with its multiplier sum.
    let mut accepted: Option<(f64, Vec<f64>, f64)> = None;
    for _ in 0..ACTIVE_SET_ROUNDS {
        if active.is_empty() {
            break;
        }
        let Some((xn, lambda)) = newton_kkt(p, &x, &free, &active) else {
            break;
        };
        if let Some((r, _)) = lambda
            .iter()
            .enumerate()
            .filter(|(_, l)| **l < 0.0)
            .min_by(|a, b| a.1.total_cmp(b.1))
        {
            active.remove(r);
            continue;
        }
        x = xn;
        let row = p.oracle.most_violated(&x);
        let excess = row.load(&x) - 1.0;
        if excess <= POLISH_LOAD_REL && accepted.as_ref().is_none_or(|(e, _, _)| excess < *e) {
            accepted = Some((excess, x.clone(), lambda.iter().sum()));
        }
        if excess <= POLISH_LOAD_TARGET {
            break;
        }
        match active.iter().position(|c| same_row(c, &row)) {
            Some(k) => active[k] = row,
            None => active.push(row),
        }
    }
    accepted.map(|(_, x, lambda)| (restore_tightness(p, x), lambda))
}

/// Whether two rows are the same constraint up to [`SAME_ROW_REL`]: their normalised
/// coefficients $a/b$ differ by less than that fraction of the largest.
fn same_row(a: &Cut, b: &Cut) -> bool {
    let u: Vec<f64> = a.coefficients.iter().map(|v| v / a.bound).collect();
    let v: Vec<f64> = b.coefficients.iter().map(|v| v / b.bound).collect();
    let scale = u.iter().chain(&v).map(|x| x.abs()).fold(0.0_f64, f64::max);
    u.iter()
        .zip(&v)
        .all(|(p, q)| (p - q).abs() <= SAME_ROW_REL * scale)
}

/// Newton's method on the KKT conditions of $\min \sum_{i\in F} w_i^2/x_i^2$ subject to the
/// given rows as equalities (the other components fixed). Returns the point and the rows'
/// multipliers (units of $J$), or `None` when it does not converge.
fn newton_kkt(
    p: &InverseSquareProblem<'_>,
    x0: &[f64],
    free: &[usize],
    rows: &[Cut],
) -> Option<(Vec<f64>, Vec<f64>)> {
    use nalgebra::{DMatrix, DVector};
    let (nf, m) = (free.len(), rows.len());
    if m == 0 || m > nf {
        return None;
    }
    // Scaled variables y_i = x_i / x0_i: objective sum c_i / y_i^2, rows A y = rhs.
    let c: Vec<f64> = free
        .iter()
        .map(|&i| (p.weights[i] / x0[i]).powi(2))
        .collect();
    let a = DMatrix::from_fn(m, nf, |r, k| {
        rows[r].coefficients[free[k]] * x0[free[k]] / rows[r].bound
    });
    let rhs = DVector::from_fn(m, |r, _| {
        let fixed: f64 = (0..x0.len())
            .filter(|i| !free.contains(i))
            .map(|i| rows[r].coefficients[i] * x0[i] / rows[r].bound)
            .sum();
        1.0 - fixed
    });
    let floor: Vec<f64> = free.iter().map(|&i| p.lower[i] / x0[i]).collect();
    let mut y: DVector<f64> = DVector::from_element(nf, 1.0);
    for _ in 0..NEWTON_STEPS {
        let mut k: DMatrix<f64> = DMatrix::zeros(nf + m, nf + m);
        let mut b: DVector<f64> = DVector::zeros(nf + m);
        for j in 0..nf {
            k[(j, j)] = 6.0 * c[j] / y[j].powi(4);
            b[j] = 2.0 * c[j] / y[j].powi(3);
        }
        k.view_mut((0, nf), (nf, m)).copy_from(&a.transpose());
        k.view_mut((nf, 0), (m, nf)).copy_from(&a);
        let residual = &rhs - &a * &y;
        b.rows_mut(nf, m).copy_from(&residual);
        let sol = k.lu().solve(&b)?;
        let dy = sol.rows(0, nf).into_owned();
        let lambda = sol.rows(nf, m).into_owned();
        let mut t = 1.0;
        while (0..nf).any(|j| y[j] + t * dy[j] <= floor[j].max(0.5 * y[j])) {
            t *= 0.5;
            if t < 1e-6 {
                return None;
            }
        }
        y += t * &dy;
        let step = (0..nf)
            .map(|j| (t * dy[j] / y[j]).abs())
            .fold(0.0, f64::max);
        if !step.is_finite() || lambda.iter().any(|l| !l.is_finite()) {
            return None;
        }
        if step <= 8.0 * f64::EPSILON && residual.amax() <= 1e-14 {
            let mut x = x0.to_vec();
            for (j, &i) in free.iter().enumerate() {
                x[i] = x0[i] * y[j];
            }
            return Some((x, lambda.iter().copied().collect()));
        }
    }
    None
}

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
    let (lo, hi) = if g1 > 1.0 {
        (0.0, 1.0)
    } else {
        let hi = 1.0 + 16.0 * (1.0 - g1) + 1e-12;
        if load(hi) <= 1.0 {
            return x;
        }
        (1.0, hi)
    };
    at(largest_within(lo, hi, 200, load))
}

/// Bisection of `[lo, hi]` for `load(s) = 1`, `load` increasing in `s`: `steps` halvings at
/// most (fewer once the interval cannot halve), each keeping the half whose lower end has
/// `load <= 1`; the lower end of the last bracket.
pub(crate) fn largest_within(
    mut lo: f64,
    mut hi: f64,
    steps: usize,
    load: impl Fn(f64) -> f64,
) -> f64 {
    for _ in 0..steps {
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
    lo
}

/// Settings of one conic solve attempt.
#[derive(Debug, Clone, Copy)]
struct ConicAttempt {
    /// Ruiz equilibration of the problem data.
    equilibrate: bool,
    /// Largest fraction of the step to the cone boundary.
    max_step_fraction: f64,
}

/// The attempts of [`conic_solve`], in order: clarabel's defaults, then without
/// equilibration, then with shorter steps. The interior-point method on power cones can stall
/// (`InsufficientProgress`) where the same problem solves with the other path (the direct
/// allocations of issue 19 did, on schedules with identical error columns); a solution of
/// any attempt is checked the same way afterwards (the exchange method asks the oracle for the
/// most loaded row, the final rescaling makes the bounds feasible and tight, the polish
/// verifies the KKT conditions), so the answer does not depend on which attempt gave it
/// beyond the solver's tolerance.
const CONIC_ATTEMPTS: [ConicAttempt; 3] = [
    ConicAttempt {
        equilibrate: true,
        max_step_fraction: 0.99,
    },
    ConicAttempt {
        equilibrate: false,
        max_step_fraction: 0.99,
    },
    ConicAttempt {
        equilibrate: false,
        max_step_fraction: 0.9,
    },
];

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
    let mut last = String::new();
    for attempt in CONIC_ATTEMPTS {
        let settings = DefaultSettings {
            verbose: false,
            max_iter: 200,
            tol_gap_abs: 1e-11,
            tol_gap_rel: 1e-11,
            tol_feas: 1e-11,
            tol_ktratio: 1e-8,
            equilibrate_enable: attempt.equilibrate,
            max_step_fraction: attempt.max_step_fraction,
            ..DefaultSettings::default()
        };
        let mut solver = DefaultSolver::new(&pm, &q, &a, &b, &cones, settings).map_err(|e| {
            AllocError::Solver {
                problem: label.to_string(),
                status: e.to_string(),
            }
        })?;
        solver.solve();
        let sol = &solver.solution;
        match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            other => {
                last = format!("{other:?}");
                continue;
            }
        }
        let y = sol.x[..n].to_vec();
        if y.iter().any(|v| !v.is_finite()) {
            last = "non-finite solution".into();
            continue;
        }
        return Ok((y, sol.z[..m_cuts].to_vec()));
    }
    Err(AllocError::Solver {
        problem: label.to_string(),
        status: last,
    })
}
