//! Calibration schedule design: choose the test positions that let the cheapest turntable
//! meet every output's accuracy.
//!
//! The paper takes the test positions as given, yet the schedule decides how much each
//! turntable error matters. This crate chooses $N$ positions from a candidate set (by default
//! the joint-angle grid, [`grid_positions_deg`]) to minimise the objective $J$ of the direct
//! allocation ([`e2e_verify::EndToEnd::allocate_direct`]): the cost of the loosest turntable that
//! meets every output's accuracy end to end, under the study's reading of eq 13, subject to
//! every output being identifiable with a condition number at most $\kappa_{max}$.
//!
//! # Formula
//! For a schedule $S$ (candidate indices) let $\mathbf A_k(S)$ be output $k$'s regression
//! matrix and $\mathbf M(S)$ the first-order error rows ([`e2e_verify::Linearization`]):
//! $$J(S) = \min_{\mathrm{UB} \ge \mathrm{LB}} \sum_j \frac{w_j^2}{\mathrm{UB}_j^2}
//! \quad\text{s.t.}\quad \sum_j \frac{|M_{rj}(S)|}{\omega_{m,k}}\,\mathrm{UB}_j \le 1
//! \ \ \forall r = (k, i),\ i \in S,$$
//! and the design problem is
//! $$\min_{S \subset \mathcal C,\ |S| = N} J(S) \quad\text{s.t.}\quad
//! \operatorname{rank}\mathbf A_k(S) = p_k,\ \ \kappa(\mathbf A_k(S)) \le \kappa_{max}\ \ \forall k.$$
//!
//! ## What is precomputed per candidate
//! The first-order rotation vector of every error $\mathbf v_{cj}$, the nominal inputs
//! $\mathbf u_c$, the regressor rows $\mathbf a_{kc}$ and the derivative blocks
//! $d\mathbf e_{kc}$, $d\mathbf g_{kc}$ (first variations of the known and estimated parts,
//! see [`e2e_verify::EndToEnd::linearization`]). For every reading of eq 13 the error rows are
//! affine in them:
//! $$\mathbf M_k(S) = c_g\,d\mathbf G_k + c_e\,d\mathbf E_k + d\;\mathbf P_k\,(d\mathbf G_k +
//! d\mathbf E_k),\qquad \mathbf P_k = \mathbf A_k\mathbf A_k^+,$$
//! with three scalars $(c_g, c_e, d)$ read off [`calib_lsq::Reading::error_vector`] on a
//! two-position probe. For [`calib_lsq::Reading::PAPER`] $d = 0$: every position's rows are
//! fixed and $J$ can only grow when positions are added ("static rows"). For
//! [`calib_lsq::Reading::USER`] $d = -1$: the rows depend on the whole schedule through
//! $\mathbf P_k$.
//!
//! ## Exact evaluation
//! [`DesignProblem::evaluate`] factors $\mathbf A_k(S)$ exactly as
//! [`calib_lsq::Calibration`] does (same matrix, QR, condition number by the SVD of
//! $\mathbf R$), forms $\mathbf M(S)$ through the same dispatch as
//! [`e2e_verify::EndToEnd::linearization`] and solves the allocation with the same core, so its
//! $J$ is bit-identical to `cargo xtask end-to-end`'s `direct_objective` on the same
//! schedule. One evaluation costs one conic solve (about a millisecond).
//!
//! ## Screening a swap in microseconds
//! A swap replaces candidate $i$ by $c$. With $\mathbf G = (\mathbf A^T\mathbf A)^{-1}$ and
//! $\mathbf H = \mathbf A^+\mathbf C_1$ ($\mathbf C_1 = d\,(d\mathbf G + d\mathbf E)$), the
//! Woodbury formula with $\mathbf U = (\mathbf a_c, \mathbf a_i)$,
//! $\mathbf D = \operatorname{diag}(1, -1)$ gives $\mathbf H' = \mathbf T - \mathbf G\mathbf U
//! \mathbf K^{-1}\mathbf U^T\mathbf T$ with $\mathbf T = \mathbf H + \mathbf G\mathbf a_c
//! \mathbf c_{1c}^T - \mathbf G\mathbf a_i\mathbf c_{1i}^T$ and $\mathbf K = \mathbf D^{-1} +
//! \mathbf U^T\mathbf G\mathbf U$ in $O(pm)$; a row is then $\mathbf c_{0q} + \mathbf a_q^T
//! \mathbf H'$, and $-\det\mathbf K = (1 + d_{cc})(1 - d_{ii}) + d_{ic}^2$ is Fedorov's
//! determinant ratio (a swap that makes it $\le 10^{-10}$ is rank deficient).
//!
//! Bounds on $J(S')$ then come from the Lagrangian dual of the allocation. For multipliers
//! $\mu_r \ge 0$ on rows of $S'$, with $c_j = \sum_r \mu_r |M_{rj}(S')|/\omega$ and
//! $\Lambda = \sum_r\mu_r$,
//! $$J(S') \ge \max_{t \ge 0}\ \Big[\sum_j \min_{x \ge \ell_j}\Big(\frac{w_j^2}{x^2} +
//! t c_j x\Big) \;-\; t\Lambda\Big],$$
//! which for $\ell = 0$ is $\big(\sum_j (w_j c_j)^{2/3}\big)^3/\Lambda^2$. So $J(S') =
//! \max_{\mu \in \Delta} G(\mu)^3$ with the concave $G(\mu) = \sum_j (w_j c_j(\mu))^{2/3}$
//! on the simplex (strong duality), every $\mu$ gives the lower bound $G(\mu)^3$, and the
//! Frank-Wolfe gap gives the upper bound $(G(\mu) + \max_r\nabla_r G - \mu\cdot\nabla G)^3$.
//! The screening takes, in order:
//! 1. the multipliers of $S$ (fitted to its KKT conditions), the swapped-out rows dropped:
//!    one closed form, no iteration; most swaps stop here;
//! 2. for static rows, $J(S') \ge J(S \setminus \{i\})$: one solve per slot rules out every
//!    swap of a slot whose position is not needed;
//! 3. pairwise Frank-Wolfe steps on the dual from those multipliers (at most
//!    200, stopping as soon as the lower bound rules the swap out or the
//!    gap is $10^{-9}$): bounds tight enough to rank the remaining swaps.
//!
//! Every bound is rigorous up to rounding (the tests check that it brackets the exact $J$ of
//! every swap); an allocation with positive lower bounds $\ell$ uses step 1 only.
//!
//! # The search
//! - **Level set** ([`StartKind::LevelSet`]): the candidates ordered by their own cost
//!   $\max_k \big(\sum_j (w_j |c_{0,kj}|)^{2/3}\big)^3$ (the $J$ of that position's rows
//!   alone), and the shortest prefix (bisection on its length) from which the greedy
//!   D-optimal construction of $N$ positions meets the condition bound.
//! - **Greedy construction** ([`DesignProblem::greedy`]): the shortest prefix of that
//!   construction that meets the bound (else that identifies every output), then one
//!   candidate at a time, the one with the smallest fixed-shape estimate $J L^2$ ($L$ the
//!   largest load of the new rows at the current bounds; ties: the largest information gain
//!   $\sum_k\ln(1 + \mathbf a_c^T\mathbf G_k\mathbf a_c)$) that keeps the condition numbers
//!   within the bound, evaluated exactly; a second variant starts from the shortest prefix
//!   that identifies every output and takes the smallest estimate regardless of the bound
//!   (repaired afterwards): neither dominates the other on the shipped studies.
//! - **Exchange** ([`DesignProblem::exchange`], after Fedorov 1972 and Cook and Nachtsheim
//!   1980): for each slot in turn, screen all $C - N$ swaps, drop those whose lower bound is
//!   not below $J(1 - \epsilon)$ ($\epsilon$ = [`SearchParams::improvement_rel`]), evaluate the rest exactly
//!   in the order of their upper bound and take the first that meets the condition bound and
//!   improves $J$ by more than $\epsilon$. A pass over every slot without an exchange ends
//!   the search. The order is found lazily: the screening stops a swap's solver once its
//!   upper bound is below $J(1 - \epsilon)$ (the swap is kept whatever follows), and the
//!   solver runs on to its final upper bound only when the swap could be evaluated next (its
//!   lower bound, which the final upper bound is at least, not above the smallest final
//!   upper bound known): the same order, and a slot whose first evaluations find an
//!   exchange ranks only a few swaps.
//! - **Restarts** ([`DesignProblem::restarts`]): the given starts (the study's schedule),
//!   the greedy construction, the level set and seeded random feasible schedules (ChaCha8
//!   streams $(\text{seed}, 2^{32} + r)$), each exchanged; restarts run in parallel and the
//!   best is chosen by $(J, \text{restart index})$, so the result does not depend on the
//!   number of threads. A start whose condition numbers exceed $\kappa_{max}$ is first
//!   repaired by D-optimal exchange until it meets the bound.
//! - **Coarse to fine** ([`design_on_grid`]): on a grid of step $s$, the best design of every
//!   coarser grid it contains (steps $Ms$, $M \ge 2$, up to [`MAX_COARSE_STEP_DEG`]; each
//!   designed as it would be on its own, coarsest first) is one more start: a coarse grid is
//!   a subset of the fine one, small enough to search well, and its optimum is usually near a
//!   good fine one. Since the exchange never loses on a start, a finer grid is never worse
//!   than a coarser one it contains. (Measured: for the IMU example the 15 deg restarts alone
//!   stop at $J = 241$ arcmin$^{-2}$ or worse; from its coarser grids' best design the 15 deg
//!   search reaches 6.67.) Each level costs a design: 23 of them for the paper's 15 deg grid,
//!   most of its 7.5 s of CPU.
//!
//! A conic solve that fails on a candidate schedule (the core's solver reports no progress on
//! a few ill-scaled row sets) makes that swap unavailable, never an error of the whole
//! design; it is counted ([`ExchangeOutcome::unevaluated_swaps`]).
//!
//! ## What is guaranteed, and what is not
//! - The exchange never returns a schedule worse than its (feasible) start: it only takes
//!   exchanges that improve the exactly evaluated $J$. So the designed schedule is never worse
//!   than the study's own when the study's schedule is a start (same $N$, its positions among
//!   the candidates, condition numbers within the bound), and a grid design is never worse
//!   than the design of a coarser grid it contains (its step a whole multiple of the fine one;
//!   exactly so when the multiples are exact in binary, e.g. integer steps).
//! - When it ends by every slot screened once in a row without an exchange
//!   ([`ExchangeStop::local_optimum`] of [`ExchangeOutcome::stop`]), no
//!   single exchange of a position for a candidate gives a feasible schedule with $J$ lower
//!   by more than $\epsilon$: every swap was either bounded below rigorously or evaluated
//!   exactly. It is a local optimum with respect to single exchanges. (A swap the conic
//!   solver cannot evaluate is never taken; if one occurs in those last slots the claim is
//!   withheld.)
//! - It is **not** a global optimum: the problem is combinatorial ($\binom{C}{N}$
//!   schedules, $10^{52}$ for the paper's 15 deg grid) and nonconvex; restarts only make a poor local
//!   optimum less likely. The exchange also stops (without the local-optimality claim) after
//!   [`SearchParams::max_exchanges_per_position`] $\times N$ exchanges.
//!
//! # Baselines
//! Computed over the same candidates with the same $N$: the study's schedule; the
//! D-optimal schedule, $\max\sum_k\ln\det(\mathbf A_k^T\mathbf A_k)$ by Fedorov's exchange
//! from the greedy D-optimal construction and seeded random starts (no condition bound: the
//! classical design); and the best of $K$ random schedules (uniform $N$-subsets, ChaCha8
//! streams $(\text{seed}, 2^{33} + r)$) that meet the condition bound.
//!
//! # Why a crate of its own
//! The objective is e2e-verify's direct allocation on its linearisation $\mathbf M$; the
//! designer reuses both (the dispatch of the readings and the allocation core, through
//! e2e-verify's hidden `internals` for the per-candidate pieces), while a project that only
//! checks or allocates a turntable compiles none of the design.
//!
//! # Example
//! ```
//! use schedule_design::{DesignProblem, grid_positions_deg};
//! use calib_lsq::Reading;
//! let table = tt_kinematics::paper::table3();
//! let sensor = gw_model::paper::gyrowheel();
//! // a coarse grid (60 deg: 36 candidates) keeps the example quick
//! let grid = grid_positions_deg(&table, 60.0)?;
//! let problem = DesignProblem::new(&table, &sensor, &gw_model::paper::site(), Reading::PAPER, &[0.0; 8], grid)?;
//! let start = problem.greedy(10, 100.0)?;
//! let out = problem.exchange(&start.schedule(), 100.0)?;
//! assert!(out.evaluation().objective() <= start.objective()); // never worse than its start
//! # Ok::<(), e2e_verify::E2eError>(())
//! ```
//!
//! # Reference
//! V. V. Fedorov, *Theory of Optimal Experiments*, Academic Press 1972 (the exchange
//! algorithm and the determinant ratio of a rank-two update); R. D. Cook and C. J.
//! Nachtsheim, "A comparison of algorithms for constructing exact D-optimal designs",
//! Technometrics 22 (1980) 315-324 (the per-point exchange). The objective is the direct
//! allocation of e2e-verify, an extension of Zhao et al. 2017, problems (31)-(33).
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod budget;
mod dopt;
mod dual;
mod problem;
mod search;
mod spec;
mod tally;

pub use budget::{
    BudgetDesign, BudgetPoint, ScheduleOrigin, TimeBudget, budget_counts, check_budget_affords,
    design_with_budget, pareto_front, shortest_test_s, total_test_s,
};

pub use budget::{BudgetParams, DEFAULT_REDUNDANCY, fewest_proposed};
pub use problem::DesignProblem;
pub use spec::SpecObjective;

use calib_lsq::{CalibError, Calibration, OrientationRequirement, RequirementProblem, Schedule};
use e2e_verify::DirectAllocation;
use e2e_verify::E2eError;
use e2e_verify::EndToEnd;
use e2e_verify::{Linearization, OutputWorstCase};
use rand_core::Rng;
use rayon::prelude::*;
use search::Search;
use tt_core::DeltaRKind;

/// The default grid step of the candidates (deg).
pub const DEFAULT_STEP_DEG: f64 = 15.0;

/// The default bound on every output's condition number $\kappa(\mathbf A_k)$
/// (dimensionless, unscaled columns as [`calib_lsq::Regression::condition_number`]): a
/// calibration that amplifies relative noise at most tenfold. The shipped studies' own
/// schedules have 1.7 to 5.9.
pub const DEFAULT_MAX_CONDITION: f64 = 10.0;

/// Restarts of the exchange by default: the given starts (the study's schedule, the coarse
/// grid's design), the two greedy constructions, the level set, the rest seeded random
/// feasible schedules. (On the shipped studies the random restarts never gave the best
/// schedule and cost most of the time on large grids: two are kept as a check.)
const DEFAULT_RESTARTS: usize = 7;

/// Random schedules of the random baseline by default.
const DEFAULT_RANDOM_SCHEDULES: usize = 256;

/// Starts of the D-optimal exchange by default (the greedy construction, then random).
const DEFAULT_D_OPTIMAL_RESTARTS: usize = 8;

/// A swap whose determinant ratio $\det\mathbf A'^T\mathbf A'/\det\mathbf A^T\mathbf A$ is at
/// most this is treated as rank deficient (dimensionless; a feasible schedule's ratio is of
/// order $\kappa_{max}^{-2p}$ at worst).
const SINGULAR_RATIO: f64 = 1e-10;

/// Sweeps of the coordinate descent fitting the rows' multipliers to the KKT conditions.
const DUAL_SWEEPS: usize = 500;

/// The exchange's knobs (see the [crate] docs, "The search"); [`SearchParams::default`] gives
/// the documented values. Set on a problem with [`DesignProblem::with_search_params`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchParams {
    /// An exchange is taken only when it lowers $J$ by more than this fraction
    /// (dimensionless; default $10^{-6}$): far above the allocation's accuracy
    /// ($\sim 10^{-12}$ relative), far below any saving worth a turntable. The D-optimal
    /// exchange takes a swap when it raises $\sum_k \ln\det$ by more than this.
    pub improvement_rel: f64,
    /// The exchange stops after this many exchanges per position of the schedule (then
    /// without the local-optimality claim; default 20).
    pub max_exchanges_per_position: usize,
    /// Random draws tried for a feasible random start before repairing one (default 200;
    /// restart $r$'s draw $t$ comes from ChaCha8 stream $2^{32} + 200 r + t$ at the default).
    pub random_start_draws: usize,
}

impl Default for SearchParams {
    fn default() -> Self {
        Self {
            improvement_rel: 1e-6,
            max_exchanges_per_position: 20,
            random_start_draws: 200,
        }
    }
}

/// Largest candidate set accepted: the precomputed blocks take about
/// $4 \cdot 8\,\text{bytes} \times$ candidates $\times$ outputs $\times$ errors (130 MB for
/// 50,000 candidates of a six-output sensor on a 13-error table), and do not grow during the
/// search.
pub(crate) const MAX_CANDIDATES: usize = 50_000;

/// ChaCha8 stream offsets: restart $r$ draws from stream `STREAM_RESTARTS + r`, random
/// schedule $r$ of the baseline from `STREAM_RANDOM + r`, D-optimal start $r$ from
/// `STREAM_D_OPTIMAL + r`.
const STREAM_RESTARTS: u64 = 1 << 32;
/// See [`STREAM_RESTARTS`].
const STREAM_RANDOM: u64 = 1 << 33;
/// See [`STREAM_RESTARTS`].
const STREAM_D_OPTIMAL: u64 = 3 << 32;

/// The joint-angle grid with step `step_deg` over every joint's range (deg, joint order,
/// the last joint varying fastest): $\min, \min + s, \dots \le \max$; for a full turn the end
/// point (the start again) is left out.
///
/// # Errors
/// [`E2eError::Field`] (out of range) naming `step_deg` unless $0 < s \le 360$;
/// [`E2eError::GridTooLarge`] above [`MAX_CANDIDATES`] grid positions (counted before any
/// is built, in checked arithmetic).
pub fn grid_positions_deg(
    turntable: &tt_kinematics::Turntable,
    step_deg: f64,
) -> Result<Vec<Vec<f64>>, E2eError> {
    if !(step_deg > 0.0 && step_deg <= 360.0) {
        return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
            field: "step_deg".into(),
            value: step_deg,
            range: "(0, 360] deg".into(),
        }));
    }
    // count first (no allocation): a tiny step would otherwise build axes of any length
    let ranges: Vec<(f64, f64)> = turntable
        .joint_ranges_rad()
        .iter()
        .map(|[lo, hi]| (lo.to_degrees(), hi.to_degrees()))
        .collect();
    let counts: Vec<f64> = ranges
        .iter()
        .map(|&(lo, hi)| axis_count(lo, hi, step_deg))
        .collect();
    let exact = counts
        .iter()
        .try_fold(1_u64, |acc, &c| {
            if c <= u64::MAX as f64 {
                acc.checked_mul(c as u64)
            } else {
                None
            }
        })
        .filter(|&c| c <= MAX_CANDIDATES as u64);
    let Some(count) = exact else {
        return Err(E2eError::GridTooLarge {
            step_deg,
            per_joint_log10: ranges
                .iter()
                .zip(&counts)
                .map(|(&(lo, hi), c)| {
                    if c.is_finite() {
                        c.log10()
                    } else {
                        (hi - lo + 1e-9).log10() - step_deg.log10()
                    }
                })
                .collect(),
            max: MAX_CANDIDATES,
        });
    };
    let axes: Vec<Vec<f64>> = ranges
        .iter()
        .zip(&counts)
        .map(|(&(lo, hi), &n)| {
            (0..n as u32)
                .map(|k| (lo + f64::from(k) * step_deg).min(hi))
                .collect()
        })
        .collect();
    debug_assert_eq!(axes.iter().map(Vec::len).product::<usize>() as u64, count);
    let mut out = vec![Vec::new()];
    for axis in &axes {
        out = out
            .iter()
            .flat_map(|p| {
                axis.iter().map(move |a| {
                    let mut q = p.clone();
                    q.push(*a);
                    q
                })
            })
            .collect();
    }
    Ok(out)
}

/// The number of grid angles of one joint: $\min, \min + s, \dots \le \max$ (to 1e-9 deg),
/// the start again left out for a full turn; computed, not enumerated (an approximation
/// beyond $2^{52}$, where only its size matters).
fn axis_count(lo: f64, hi: f64, step_deg: f64) -> f64 {
    let full = hi - lo >= 360.0 - 1e-9;
    let stop = |k: f64| {
        let a = lo + k * step_deg;
        a > hi + 1e-9 || (full && a >= lo + 360.0 - 1e-9)
    };
    let estimate = ((hi - lo + 1e-9) / step_deg).floor() + 1.0;
    // beyond 2^52 (or NaN-free infinity for a step of 1e-308) only the size matters
    if estimate.is_nan() || estimate >= 4_503_599_627_370_496.0 {
        return estimate;
    }
    // the first k that stops (stop is monotone in k): the count
    let mut k = estimate.max(0.0);
    while k > 0.0 && stop(k - 1.0) {
        k -= 1.0;
    }
    while !stop(k) {
        k += 1.0;
    }
    k
}

/// `grid` followed by the positions of `extra` that are not already in it (exact equality
/// of the angles): the candidate set that contains a given schedule.
#[must_use]
pub fn candidates_with(grid: Vec<Vec<f64>>, extra: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out = grid;
    for p in extra {
        if !out.iter().any(|q| q == p) {
            out.push(p.clone());
        }
    }
    out
}

/// The exact evaluation of one schedule ([`DesignProblem::evaluate`]).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Evaluation {
    /// The schedule (candidate indices, in order).
    pub(crate) schedule: Vec<usize>,
    /// Every output's condition number (`+inf` when the schedule does not identify it).
    pub(crate) condition_numbers: Vec<f64>,
    /// The first output the schedule does not identify, with its coefficients.
    pub(crate) unidentifiable: Option<(String, Vec<String>)>,
    /// $J$ of the direct allocation (rad$^{-2}$); `+inf` when unidentifiable or when the
    /// lower bounds alone break an accuracy.
    pub(crate) objective: f64,
    /// The direct allocation, when it exists.
    pub(crate) allocation: Option<DirectAllocation>,
    /// $\mathbf M$, when the schedule identifies every output.
    pub(crate) linear: Option<Linearization>,
    /// What the screening needs of the schedule answered against the specifications (`None`
    /// without specifications or when the schedule is not answered).
    pub(crate) spec_screen: Option<std::sync::Arc<spec::SpecScreen>>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Evaluation {
    /// The schedule (candidate indices, in order).
    #[must_use]
    pub fn schedule(&self) -> &[usize] {
        &self.schedule
    }

    /// Every output's condition number (`+inf` when the schedule does not identify it).
    #[must_use]
    pub fn condition_numbers(&self) -> &[f64] {
        &self.condition_numbers
    }

    /// The first output the schedule does not identify, with its coefficients.
    #[must_use]
    pub fn unidentified_output(&self) -> Option<&(String, Vec<String>)> {
        self.unidentifiable.as_ref()
    }

    /// $J$ of the direct allocation (rad$^{-2}$); `+inf` when unidentifiable or when the
    /// lower bounds alone break an accuracy.
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The direct allocation, when it exists.
    #[must_use]
    pub fn allocation(&self) -> Option<&DirectAllocation> {
        self.allocation.as_ref()
    }

    /// $\mathbf M$, when the schedule identifies every output.
    #[must_use]
    pub fn linear(&self) -> Option<&Linearization> {
        self.linear.as_ref()
    }
}

impl Evaluation {
    pub(crate) fn unidentifiable(
        s: &[usize],
        output: String,
        coefficients: Vec<String>,
        outputs: usize,
    ) -> Self {
        Self {
            schedule: s.to_vec(),
            condition_numbers: vec![f64::INFINITY; outputs],
            unidentifiable: Some((output, coefficients)),
            objective: f64::INFINITY,
            allocation: None,
            linear: None,
            spec_screen: None,
        }
    }

    /// The largest condition number of the outputs.
    #[must_use]
    pub fn max_condition(&self) -> f64 {
        self.condition_numbers.iter().copied().fold(0.0, f64::max)
    }

    /// Identifiable, every condition number at most `max_condition`, and an allocation.
    #[must_use]
    pub fn is_feasible(&self, max_condition: f64) -> bool {
        self.unidentifiable.is_none()
            && self.max_condition() <= max_condition
            && self.objective.is_finite()
    }

    /// $J$ in arcmin$^{-2}$ (as `end-to-end --json` reports `direct_objective`).
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        tt_core::units::objective_to_arcmin(self.objective)
    }
}

/// The result of one exchange run.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ExchangeOutcome {
    /// $J$ of the start (rad$^{-2}$).
    pub(crate) start_objective: f64,
    /// The final schedule, evaluated exactly ($J$ never above `start_objective`).
    pub(crate) evaluation: Evaluation,
    /// Exchanges taken, passes, and whether it ended at a local optimum: every slot screened
    /// once in a row without an exchange (against the final schedule), every swap bounded or
    /// evaluated.
    pub(crate) stop: ExchangeStop,
    /// Exact evaluations (conic solves) of candidate swaps.
    pub(crate) exact_evaluations: usize,
    /// Swaps screened (bounds computed).
    pub(crate) screened_swaps: usize,
    /// Swaps the allocation core could not solve (conic solver failure): never taken.
    pub(crate) unevaluated_swaps: usize,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ExchangeOutcome {
    /// $J$ of the start (rad$^{-2}$).
    #[must_use]
    pub fn start_objective(&self) -> f64 {
        self.start_objective
    }

    /// The final schedule, evaluated exactly ($J$ never above `start_objective`).
    #[must_use]
    pub fn evaluation(&self) -> &Evaluation {
        &self.evaluation
    }

    /// Exchanges taken, passes, and whether it ended by every slot screened once in a row
    /// without an exchange (against the final schedule), every swap bounded or evaluated:
    /// then no single exchange gives a feasible schedule better by more than
    /// [`SearchParams::improvement_rel`].
    #[must_use]
    pub fn stop(&self) -> &ExchangeStop {
        &self.stop
    }

    /// Exact evaluations (conic solves) of candidate swaps.
    #[must_use]
    pub fn exact_evaluations(&self) -> usize {
        self.exact_evaluations
    }

    /// Swaps screened (bounds computed).
    #[must_use]
    pub fn screened_swaps(&self) -> usize {
        self.screened_swaps
    }

    /// Swaps the allocation core could not solve (conic solver failure): never taken.
    #[must_use]
    pub fn unevaluated_swaps(&self) -> usize {
        self.unevaluated_swaps
    }
}

/// How an exchange (of [`ExchangeOutcome`] or [`DOptimalOutcome`]) ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct ExchangeStop {
    /// Exchanges taken.
    pub(crate) exchanges: usize,
    /// Passes over the slots.
    pub(crate) passes: usize,
    /// Whether it ended at a local optimum: no single exchange improves its criterion by more
    /// than [`SearchParams::improvement_rel`] (what each exchange checks is said at its
    /// `stop()`).
    pub(crate) local_optimum: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ExchangeStop {
    /// Exchanges taken.
    #[must_use]
    pub fn exchanges(&self) -> usize {
        self.exchanges
    }

    /// Passes over the slots.
    #[must_use]
    pub(crate) fn passes(&self) -> usize {
        self.passes
    }

    /// Whether it ended at a local optimum: no single exchange improves its criterion by more
    /// than [`SearchParams::improvement_rel`] (what each exchange checks is said at its
    /// `stop()`).
    #[must_use]
    pub fn local_optimum(&self) -> bool {
        self.local_optimum
    }
}

/// The D-optimal exchange's result.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DOptimalOutcome {
    /// The schedule (candidate indices).
    pub(crate) schedule: Vec<usize>,
    /// $\sum_k \ln\det(\mathbf A_k^T\mathbf A_k)$.
    pub(crate) log_det: f64,
    /// Exchanges taken, passes, and whether no single exchange raises the criterion by more
    /// than [`SearchParams::improvement_rel`].
    pub(crate) stop: ExchangeStop,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl DOptimalOutcome {
    /// The schedule (candidate indices).
    #[must_use]
    pub fn schedule(&self) -> &[usize] {
        &self.schedule
    }

    /// $\sum_k \ln\det(\mathbf A_k^T\mathbf A_k)$.
    #[must_use]
    pub fn log_det(&self) -> f64 {
        self.log_det
    }

    /// Exchanges taken, passes, and whether no single exchange raises the criterion by more
    /// than [`SearchParams::improvement_rel`].
    #[must_use]
    pub fn stop(&self) -> &ExchangeStop {
        &self.stop
    }
}

/// How a restart started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartKind {
    /// The study's own schedule.
    Study,
    /// The best design of the coarser grids the fine grid contains (each started from its own
    /// coarser grids, and so on): coarse to fine ([`design_on_grid`]).
    Coarse,
    /// Another given schedule, by its index among the given starts.
    Given(usize),
    /// The greedy construction, keeping the condition bound once met.
    Greedy,
    /// The greedy construction by $J$ alone (repaired afterwards if it breaks the bound).
    GreedyUnconstrained,
    /// The level set's greedy D-optimal schedule (meets the condition bound by construction).
    LevelSet,
    /// A seeded random feasible schedule (ChaCha8 streams from $2^{32}$,
    /// [`SearchParams::random_start_draws`] per restart).
    Random(u64),
}

/// One restart of the design search.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RestartOutcome {
    /// Its start.
    pub(crate) start: StartKind,
    /// $J$ of the start (rad$^{-2}$; `+inf` when the start was infeasible and repaired).
    pub(crate) start_objective: f64,
    /// The exchange, or `None` when no feasible start could be made.
    pub(crate) exchange: Option<ExchangeOutcome>,
    /// The smallest largest condition number of the identifiable schedules this restart met
    /// (its start and the start's repair; `+inf` when none was identifiable): what the
    /// search could reach when no restart meets the bound.
    pub(crate) best_condition: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RestartOutcome {
    /// Its start.
    #[must_use]
    pub fn start(&self) -> StartKind {
        self.start
    }

    /// $J$ of the start (rad$^{-2}$; `+inf` when the start was infeasible and repaired).
    #[must_use]
    pub fn start_objective(&self) -> f64 {
        self.start_objective
    }

    /// The exchange, or `None` when no feasible start could be made.
    #[must_use]
    pub fn exchange(&self) -> Option<&ExchangeOutcome> {
        self.exchange.as_ref()
    }

    /// The smallest largest condition number of the identifiable schedules this restart met
    /// (its start and the start's repair; `+inf` when none was identifiable): what the
    /// search could reach when no restart meets the bound.
    #[must_use]
    pub fn best_condition(&self) -> f64 {
        self.best_condition
    }
}

/// Settings of the design search.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSettings {
    /// Number of positions $N$.
    pub positions: usize,
    /// Bound $\kappa_{max}$ on every output's condition number.
    pub max_condition: f64,
    /// Seed of every random choice.
    pub seed: u64,
    /// Restarts of the exchange (given starts and the greedy construction included).
    pub restarts: usize,
    /// $K$ of the random baseline.
    pub random_schedules: usize,
    /// Starts of the D-optimal exchange.
    pub d_optimal_restarts: usize,
}

impl DesignSettings {
    /// Settings with the defaults: [`DEFAULT_MAX_CONDITION`], 7 restarts (the given starts,
    /// the two greedy constructions, the level set, the rest seeded random feasible
    /// schedules; on the shipped studies the random restarts never gave the best schedule and
    /// cost most of the time on large grids: two are kept as a check), 256 random schedules
    /// and 8 D-optimal starts (the greedy construction, then random).
    #[must_use]
    pub fn new(positions: usize, seed: u64) -> Self {
        Self {
            positions,
            max_condition: DEFAULT_MAX_CONDITION,
            seed,
            restarts: DEFAULT_RESTARTS,
            random_schedules: DEFAULT_RANDOM_SCHEDULES,
            d_optimal_restarts: DEFAULT_D_OPTIMAL_RESTARTS,
        }
    }

    /// Units of work reported to a progress callback by [`DesignProblem::design`].
    #[must_use]
    pub fn work_units(&self) -> u64 {
        (self.restarts + self.d_optimal_restarts + self.random_schedules) as u64
    }
}

/// The whole search: the best exchange, every restart, the baselines.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct DesignSearch {
    /// The designed schedule: the best restart's result.
    pub(crate) designed: ExchangeOutcome,
    /// Index of the best restart in `restarts`.
    pub(crate) best_restart: usize,
    /// Every restart, in order.
    pub(crate) restarts: Vec<RestartOutcome>,
    /// The D-optimal baseline (best of its starts).
    pub(crate) d_optimal: DOptimalOutcome,
    /// The best feasible random schedule, if any.
    pub(crate) random_best: Option<Evaluation>,
    /// Random schedules drawn.
    pub(crate) random_drawn: usize,
    /// Of those, feasible (identifiable, condition bound, allocation exists).
    pub(crate) random_feasible: usize,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl DesignSearch {
    /// The designed schedule: the best restart's result.
    #[must_use]
    pub fn designed(&self) -> &ExchangeOutcome {
        &self.designed
    }

    /// Index of the best restart in `restarts`.
    #[must_use]
    pub fn best_restart(&self) -> usize {
        self.best_restart
    }

    /// Every restart, in order.
    #[must_use]
    pub fn restarts(&self) -> &[RestartOutcome] {
        &self.restarts
    }

    /// The D-optimal baseline (best of its starts).
    #[must_use]
    pub fn d_optimal(&self) -> &DOptimalOutcome {
        &self.d_optimal
    }

    /// The best feasible random schedule, if any.
    #[must_use]
    pub fn random_best(&self) -> Option<&Evaluation> {
        self.random_best.as_ref()
    }

    /// Random schedules drawn.
    #[must_use]
    pub fn random_drawn(&self) -> usize {
        self.random_drawn
    }

    /// Of those, feasible (identifiable, condition bound, allocation exists).
    #[must_use]
    pub fn random_feasible(&self) -> usize {
        self.random_feasible
    }
}

fn random_schedule(n_candidates: usize, n: usize, seed: u64, stream: u64) -> Vec<usize> {
    let mut rng = mc_verify::chunk_rng(seed, stream);
    let mut idx: Vec<usize> = (0..n_candidates).collect();
    for i in 0..n {
        // uniform in i..C by a 64x64 -> 128 bit multiply (bias below 2^-40 for C < 2^24)
        let span = (n_candidates - i) as u128;
        let j = i + ((u128::from(rng.next_u64()) * span) >> 64) as usize;
        idx.swap(i, j);
    }
    idx.truncate(n);
    idx
}

impl DesignProblem {
    fn check_settings(&self, s: &DesignSettings) -> Result<(), E2eError> {
        let n = s.positions;
        let (k, o) = self
            .outputs
            .iter()
            .enumerate()
            .max_by_key(|(k, o)| (o.p, std::cmp::Reverse(*k)))
            .map(|(k, o)| (k, o.p))
            .unwrap_or((0, 0));
        if n < o {
            return Err(E2eError::TooFewPositions {
                positions: n,
                output: self.output_names[k].clone(),
                coefficients: o,
            });
        }
        if n > self.n_candidates() {
            return Err(E2eError::TooManyPositions {
                positions: n,
                candidates: self.n_candidates(),
            });
        }
        if !(s.max_condition >= 1.0 && s.max_condition.is_finite()) {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "max_condition".into(),
                value: s.max_condition,
                range: "[1, inf) (a condition number is at least 1)".into(),
            }));
        }
        for (field, v) in [
            ("restarts", s.restarts),
            ("d_optimal_restarts", s.d_optimal_restarts),
        ] {
            tt_core::count(field, v as u64, u64::MAX)?;
        }
        Ok(())
    }

    /// The greedy construction of `n` positions (see the [module](self) docs); the result
    /// may exceed `max_condition` (the search then repairs it).
    ///
    /// # Errors
    /// As [`DesignProblem::evaluate`]; [`E2eError::TooFewPositions`],
    /// [`E2eError::TooManyPositions`] for a bad `n`.
    pub fn greedy(&self, n: usize, max_condition: f64) -> Result<Evaluation, E2eError> {
        self.check_settings(&DesignSettings {
            max_condition,
            ..DesignSettings::new(n, 0)
        })?;
        Search::new(self, max_condition)
            .greedy(n, true)?
            .ok_or(E2eError::NoConvergence {
                what: "greedy construction (the allocation failed at every candidate of a step)",
                iterations: n,
                change: f64::NAN,
            })
    }

    /// The exchange from `start` (see the [module](self) docs).
    ///
    /// # Errors
    /// [`E2eError::ConditionUnreachable`] when `start` is not feasible (unidentifiable, a
    /// condition number above `max_condition`, or no allocation); as
    /// [`DesignProblem::evaluate`].
    pub fn exchange(
        &self,
        start: &[usize],
        max_condition: f64,
    ) -> Result<ExchangeOutcome, E2eError> {
        let e = self.evaluate(start)?;
        if !e.is_feasible(max_condition) {
            return Err(E2eError::ConditionUnreachable {
                max_condition,
                best_condition: e.max_condition(),
            });
        }
        Search::new(self, max_condition).exchange(e)
    }

    /// The single-exchange neighbourhood of a feasible schedule (see [`Neighbourhood`]).
    ///
    /// # Errors
    /// As [`DesignProblem::exchange`].
    pub fn neighbourhood(
        &self,
        schedule: &[usize],
        max_condition: f64,
    ) -> Result<Neighbourhood<'_>, E2eError> {
        let e = self.evaluate(schedule)?;
        if !e.is_feasible(max_condition) {
            return Err(E2eError::ConditionUnreachable {
                max_condition,
                best_condition: e.max_condition(),
            });
        }
        let search = Search::new(self, max_condition);
        let state = search.state(e)?;
        Ok(Neighbourhood { search, state })
    }

    /// $\sum_k\ln\det(\mathbf A_k^T\mathbf A_k)$ of a schedule (`-inf` when an output is rank
    /// deficient): the D-optimal criterion.
    #[must_use]
    pub fn log_det_information(&self, s: &[usize]) -> f64 {
        dopt::log_det(self, s)
    }

    /// The D-optimal schedule of `n` positions: the best of Fedorov's exchange from the
    /// greedy D-optimal construction and `restarts - 1` seeded random starts (ties: the first).
    ///
    /// # Errors
    /// [`E2eError::TooFewPositions`], [`E2eError::TooManyPositions`] for a bad `n`.
    pub fn d_optimal(
        &self,
        n: usize,
        seed: u64,
        restarts: usize,
        progress: &(dyn Fn() + Sync),
    ) -> Result<DOptimalOutcome, E2eError> {
        self.check_settings(&DesignSettings {
            d_optimal_restarts: restarts.max(1),
            ..DesignSettings::new(n, seed)
        })?;
        let never = |_: &[usize]| false;
        let draws = self.search.random_start_draws as u64;
        let outcomes: Vec<Option<DOptimalOutcome>> = (0..restarts.max(1))
            .into_par_iter()
            .map(|r| {
                let start = if r == 0 {
                    Some(dopt::greedy_d(self, n))
                } else {
                    (0..draws)
                        .map(|t| {
                            random_schedule(
                                self.n_candidates(),
                                n,
                                seed,
                                STREAM_D_OPTIMAL + r as u64 * draws + t,
                            )
                        })
                        .find(|s| dopt::log_det(self, s).is_finite())
                        .map(Ok)
                };
                let out = start.map(|s| s.and_then(|s| dopt::exchange_d(self, s, &never)));
                progress();
                out.transpose()
            })
            .collect::<Result<_, _>>()?;
        outcomes
            .into_iter()
            .flatten()
            .reduce(|a, b| if b.log_det > a.log_det { b } else { a })
            .ok_or(E2eError::ConditionUnreachable {
                max_condition: f64::INFINITY,
                best_condition: f64::INFINITY,
            })
    }

    /// A feasible start for restart `kind`, repaired by D-optimal exchange when its condition
    /// numbers exceed the bound; `None` when no feasible schedule was reached.
    fn start(
        &self,
        search: &Search<'_>,
        kind: StartKind,
        given: Option<&[usize]>,
        settings: &DesignSettings,
    ) -> Result<(f64, Option<Evaluation>, f64), E2eError> {
        let n = settings.positions;
        let none = Ok((f64::INFINITY, None, f64::INFINITY));
        let first = match kind {
            StartKind::Study | StartKind::Coarse | StartKind::Given(_) => match given {
                Some(g) => self.evaluate(g)?,
                None => return none,
            },
            StartKind::Greedy | StartKind::GreedyUnconstrained => {
                match search.greedy(n, kind == StartKind::Greedy)? {
                    Some(e) => e,
                    None => return none,
                }
            }
            StartKind::LevelSet => match search.level_set(n)? {
                Some((_, s)) => match self.evaluate_or_skip(&s, f64::INFINITY)? {
                    Some(e) => e,
                    None => return none,
                },
                None => return none,
            },
            StartKind::Random(r) => {
                let mut first_identifiable = None;
                let mut found = None;
                let draws = self.search.random_start_draws as u64;
                for t in 0..draws {
                    let s = random_schedule(
                        self.n_candidates(),
                        n,
                        settings.seed,
                        STREAM_RESTARTS + r * draws + t,
                    );
                    let Some(e) = self.evaluate_or_skip(&s, settings.max_condition)? else {
                        continue;
                    };
                    if search.feasible(&e) {
                        found = Some(e);
                        break;
                    }
                    if first_identifiable.is_none() && e.unidentifiable.is_none() {
                        first_identifiable = Some(e);
                    }
                }
                match (found, first_identifiable) {
                    (Some(e), _) | (None, Some(e)) => e,
                    (None, None) => return none,
                }
            }
        };
        let start_objective = if search.feasible(&first) {
            first.objective
        } else {
            f64::INFINITY
        };
        let reached = |e: &Evaluation| {
            if e.unidentifiable.is_some() {
                f64::INFINITY
            } else {
                e.max_condition()
            }
        };
        let first_condition = reached(&first);
        if search.feasible(&first) {
            return Ok((start_objective, Some(first), first_condition));
        }
        if first.unidentifiable.is_some() {
            return Ok((start_objective, None, first_condition));
        }
        let k = settings.max_condition;
        let ok = |s: &[usize]| {
            self.regressions(s)
                .is_ok_and(|r| r.iter().all(|g| g.condition_number() <= k))
        };
        let repaired = dopt::exchange_d(self, first.schedule.clone(), &ok)?;
        let e = self.evaluate_or_skip(&repaired.schedule, f64::INFINITY)?;
        let best = e
            .as_ref()
            .map_or(first_condition, |e| reached(e).min(first_condition));
        Ok((start_objective, e.filter(|e| search.feasible(e)), best))
    }

    /// The restarts of the design search: the `given` starts (each a kind and a schedule of
    /// `settings.positions` candidates), the greedy construction, the level set and seeded
    /// random feasible schedules up to `settings.restarts`, each exchanged (in parallel); the
    /// outcomes in order and the index of the best (by $J$, then index).
    ///
    /// # Errors
    /// As [`DesignProblem::design`].
    pub fn restarts(
        &self,
        settings: &DesignSettings,
        given: &[(StartKind, Vec<usize>)],
        progress: &(dyn Fn() + Sync),
    ) -> Result<(Vec<RestartOutcome>, usize), E2eError> {
        self.check_settings(settings)?;
        for (_, g) in given {
            self.check_schedule(g)?;
            if g.len() != settings.positions {
                return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: "given start".into(),
                    value: g.len() as f64,
                    range: "schedules of the requested number of positions".into(),
                }));
            }
        }
        let search = Search::new(self, settings.max_condition);
        let mut kinds: Vec<(StartKind, Option<&[usize]>)> = given
            .iter()
            .map(|(k, g)| (*k, Some(g.as_slice())))
            .collect();
        kinds.push((StartKind::Greedy, None));
        kinds.push((StartKind::GreedyUnconstrained, None));
        kinds.push((StartKind::LevelSet, None));
        let mut r = 0;
        while kinds.len() < settings.restarts.max(given.len() + 3) {
            kinds.push((StartKind::Random(r), None));
            r += 1;
        }
        let restarts: Vec<RestartOutcome> = kinds
            .par_iter()
            .map(|&(kind, g)| {
                let (start_objective, start, best_condition) =
                    self.start(&search, kind, g, settings)?;
                let exchange = start.map(|e| search.exchange(e)).transpose()?;
                progress();
                Ok(RestartOutcome {
                    start: kind,
                    start_objective,
                    exchange,
                    best_condition,
                })
            })
            .collect::<Result<_, E2eError>>()?;
        let best_restart = restarts
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.exchange.as_ref().map(|e| (i, e.evaluation.objective)))
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            .map(|t| t.0);
        let Some(best_restart) = best_restart else {
            return Err(E2eError::ConditionUnreachable {
                max_condition: settings.max_condition,
                best_condition: restarts
                    .iter()
                    .map(|r| r.best_condition)
                    .fold(f64::INFINITY, f64::min),
            });
        };
        Ok((restarts, best_restart))
    }

    /// The design search (see the [module](self) docs): [`DesignProblem::restarts`], then the
    /// D-optimal and random baselines. Calls `progress` once per unit of
    /// [`DesignSettings::work_units`].
    ///
    /// # Errors
    /// [`E2eError::TooFewPositions`], [`E2eError::TooManyPositions`],
    /// [`E2eError::Field`] (out of range) for bad settings; [`E2eError::ConditionUnreachable`] when no
    /// restart reaches a feasible schedule; as [`DesignProblem::evaluate`].
    pub fn design(
        &self,
        settings: &DesignSettings,
        given: &[(StartKind, Vec<usize>)],
        progress: &(dyn Fn() + Sync),
    ) -> Result<DesignSearch, E2eError> {
        let search = Search::new(self, settings.max_condition);
        let (restarts, best_restart) = self.restarts(settings, given, progress)?;
        let designed = restarts[best_restart]
            .exchange
            .clone()
            .unwrap_or_else(|| unreachable!("chosen among restarts with an exchange"));
        let d_optimal = self.d_optimal(
            settings.positions,
            settings.seed,
            settings.d_optimal_restarts,
            progress,
        )?;
        let randoms: Vec<Evaluation> = (0..settings.random_schedules as u64)
            .into_par_iter()
            .map(|r| {
                let e = self.evaluate_or_skip(
                    &random_schedule(
                        self.n_candidates(),
                        settings.positions,
                        settings.seed,
                        STREAM_RANDOM + r,
                    ),
                    settings.max_condition,
                );
                progress();
                e
            })
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .flatten()
            .collect();
        let random_feasible = randoms.iter().filter(|e| search.feasible(e)).count();
        let random_best = randoms
            .into_iter()
            .filter(|e| search.feasible(e))
            .reduce(|a, b| if b.objective < a.objective { b } else { a });
        Ok(DesignSearch {
            designed,
            best_restart,
            restarts,
            d_optimal,
            random_best,
            random_drawn: settings.random_schedules,
            random_feasible,
        })
    }

    /// The end-to-end simulator of a schedule (joint angles, deg) through the same path as
    /// every other command: study positions to [`Calibration`], then [`EndToEnd::new`].
    ///
    /// # Errors
    /// As [`Calibration::new`] and [`EndToEnd::new`].
    pub fn end_to_end(&self, positions_deg: &[Vec<f64>]) -> Result<EndToEnd, E2eError> {
        self.end_to_end_with_rate_steps(positions_deg, &[])
    }

    /// [`DesignProblem::end_to_end`] with `rate_steps` (schedule entries with a motion, e.g. a
    /// study's) after the static positions, in order.
    ///
    /// # Errors
    /// As [`DesignProblem::end_to_end`].
    pub fn end_to_end_with_rate_steps(
        &self,
        positions_deg: &[Vec<f64>],
        rate_steps: &[calib_lsq::Position],
    ) -> Result<EndToEnd, E2eError> {
        let mut positions = positions_deg
            .iter()
            .map(|p| {
                let pose = tt_kinematics::Pose::from_deg(p)?;
                Ok(calib_lsq::Position::new(
                    self.turntable.nominal_rotation(&pose)?,
                    p.clone(),
                )?)
            })
            .collect::<Result<Vec<_>, E2eError>>()?;
        positions.extend_from_slice(rate_steps);
        let calibration = Calibration::new(&self.sensor, &self.site, &Schedule::new(positions)?)?;
        let poses = positions_deg
            .iter()
            .map(Vec::as_slice)
            .chain(rate_steps.iter().map(calib_lsq::Position::joint_angles_deg))
            .map(tt_kinematics::Pose::from_deg)
            .collect::<Result<Vec<_>, _>>()?;
        EndToEnd::new(&self.turntable, &calibration, &poses, self.reading)
    }

    /// A schedule's report through the same path as every other command (study positions to
    /// [`Calibration`], [`EndToEnd::new`], [`EndToEnd::linearization`],
    /// [`EndToEnd::allocate_direct`]): its own direct allocation (the design objective), the
    /// same certified on the exact chain ([`EndToEnd::allocate_direct_certified`], the
    /// tolerances to buy), condition numbers, the D-criterion, the worst case of every output
    /// with the tolerances `study_tolerances` (rad; `None`: this schedule's own certified
    /// tolerances, else its direct allocation) and the orientation requirement of eq 15-16
    /// under `delta_r_kind`.
    ///
    /// # Errors
    /// As [`Calibration::new`], [`EndToEnd::new`] and [`EndToEnd::allocate_direct`].
    pub fn report(
        &self,
        positions_deg: &[Vec<f64>],
        delta_r_kind: DeltaRKind,
        study_tolerances: Option<&StudyTolerances>,
    ) -> Result<ScheduleReport, E2eError> {
        let static_e2e = self.end_to_end(positions_deg)?;
        let calibration = static_e2e.calibration().clone();
        let lb = &self.lower_bounds_rad;
        let (e2e, linear, allocation, (certified, certified_note)) =
            match self.spec_answer(positions_deg)? {
                Some(a) => {
                    let allocation = match a.allocation {
                        Some(d) => d,
                        // no table suffices: the allocation's own error names why
                        None => a.e2e.allocate_direct_specified(&a.linear, lb, &a.rows)?,
                    };
                    let certified = e2e_verify::internals::certified_or_note_specified(
                        &a.e2e,
                        &a.linear,
                        lb,
                        &allocation,
                        &a.rows,
                    )?;
                    (a.e2e, a.linear, allocation, certified)
                }
                None => {
                    let linear = static_e2e.linearization();
                    let allocation = static_e2e.allocate_direct(&linear, lb)?;
                    let certified = e2e_verify::internals::certified_or_note(
                        &static_e2e,
                        &linear,
                        lb,
                        &allocation,
                    )?;
                    (static_e2e, linear, allocation, certified)
                }
            };
        let own = StudyTolerances::of(&allocation, certified.as_ref());
        let tolerances = study_tolerances.unwrap_or(&own);
        let with_study_tolerances = tolerances.worst_case(&e2e, &linear)?;
        let s: Vec<usize> = positions_deg
            .iter()
            .filter_map(|p| self.index_of(p))
            .collect();
        let log_det_information = if s.len() == positions_deg.len() {
            self.log_det_information(&s)
        } else {
            calibration
                .outputs()
                .iter()
                .map(|o| {
                    let a = o.regression().matrix();
                    (a.transpose() * a)
                        .cholesky()
                        .map_or(f64::NEG_INFINITY, |c| {
                            2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>()
                        })
                })
                .sum()
        };
        Ok(ScheduleReport {
            positions_deg: positions_deg.to_vec(),
            condition_numbers: calibration.condition_numbers(),
            requirement: RequirementProblem::new(calibration, self.reading, delta_r_kind)
                .requirement(),
            allocation,
            certified,
            certified_note,
            log_det_information,
            with_study_tolerances,
        })
    }

    /// The positions (deg) of a schedule of candidate indices.
    #[must_use]
    pub fn positions_deg(&self, s: &[usize]) -> Vec<Vec<f64>> {
        s.iter().map(|&c| self.candidates_deg[c].clone()).collect()
    }
}

/// One screened swap of [`Neighbourhood::screen`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SwapBound {
    /// The candidate that would replace the slot's position.
    pub(crate) candidate: usize,
    /// A rigorous lower bound on $J$ after the swap (rad$^{-2}$; `+inf` when the swap makes
    /// an output unidentifiable), up to rounding.
    pub(crate) lower: f64,
    /// An estimate of $J$ after the swap (rad$^{-2}$): a rigorous upper bound when every lower
    /// bound of the errors is zero; `+inf` when the lower bound already rules the swap out.
    pub(crate) estimate: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl SwapBound {
    /// The candidate that would replace the slot's position.
    #[must_use]
    pub fn candidate(&self) -> usize {
        self.candidate
    }

    /// A rigorous lower bound on $J$ after the swap (rad$^{-2}$; `+inf` when the swap makes
    /// an output unidentifiable), up to rounding.
    #[must_use]
    pub fn lower(&self) -> f64 {
        self.lower
    }

    /// An estimate of $J$ after the swap (rad$^{-2}$): a rigorous upper bound when every lower
    /// bound of the errors is zero; `+inf` when the lower bound already rules the swap out.
    #[must_use]
    pub fn estimate(&self) -> f64 {
        self.estimate
    }
}

/// The single-exchange neighbourhood of a schedule, ready to screen: the schedule's exact
/// evaluation, its multipliers and the factors of every output's Gram matrix.
#[derive(Debug)]
pub struct Neighbourhood<'a> {
    search: Search<'a>,
    state: search::State,
}

impl Neighbourhood<'_> {
    /// $J$ of the schedule (rad$^{-2}$).
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.state.j
    }

    /// The schedule (candidate indices).
    #[must_use]
    pub fn schedule(&self) -> &[usize] {
        &self.state.s
    }

    /// Bounds on $J$ for every swap of slot `slot` with a candidate not in the schedule
    /// (see the [module](self) docs: Woodbury update of the rows, the dual lower bound from
    /// the schedule's multipliers, then the dual screening solver). A bound below
    /// $J(1 - \epsilon)$ is not certified further: such swaps are only candidates for an
    /// improvement.
    ///
    /// # Errors
    /// [`E2eError::Field`] (out of range) naming `slot` beyond the schedule.
    pub fn screen(&self, slot: usize) -> Result<Vec<SwapBound>, E2eError> {
        if slot >= self.state.s.len() {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "slot".into(),
                value: slot as f64,
                range: "a slot of the schedule".into(),
            }));
        }
        Ok(self.search.screen_swaps(&self.state, slot))
    }
}

/// One schedule as every command sees it.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ScheduleReport {
    /// The positions (joint angles, deg).
    pub(crate) positions_deg: Vec<Vec<f64>>,
    /// Its own direct allocation ($J$, bounds, active rows): the linearised design objective.
    /// Its worst case on the exact chain may exceed an accuracy (by the second-order terms);
    /// see `certified` for tolerances that are proven.
    pub(crate) allocation: DirectAllocation,
    /// Its direct allocation certified on the exact chain
    /// ([`EndToEnd::allocate_direct_certified`], as `end-to-end`'s `direct_certified`): every
    /// turntable within these tolerances meets every accuracy, so they pass
    /// `check-turntable` on this schedule. `None` when not certifiable (`certified_note`).
    pub(crate) certified: Option<DirectAllocation>,
    /// Why `certified` is `None`.
    pub(crate) certified_note: Option<String>,
    /// Every output's condition number.
    pub(crate) condition_numbers: Vec<f64>,
    /// $\sum_k\ln\det(\mathbf A_k^T\mathbf A_k)$.
    pub(crate) log_det_information: f64,
    /// The worst case of every output over the study schedule's tolerances (what the table
    /// one would buy for the study's schedule gives with this schedule).
    pub(crate) with_study_tolerances: StudyTolerancesWorstCase,
    /// The orientation requirement of eq 15-16 for this schedule, or why there is none.
    pub(crate) requirement: Result<OrientationRequirement, CalibError>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ScheduleReport {
    /// The positions (joint angles, deg).
    #[must_use]
    pub fn positions_deg(&self) -> &[Vec<f64>] {
        &self.positions_deg
    }

    /// Its own direct allocation ($J$, bounds, active rows): the linearised design objective.
    /// Its worst case on the exact chain may exceed an accuracy (by the second-order terms);
    /// see `certified` for tolerances that are proven.
    #[must_use]
    pub fn allocation(&self) -> &DirectAllocation {
        &self.allocation
    }

    /// Its direct allocation certified on the exact chain
    /// ([`EndToEnd::allocate_direct_certified`], as `end-to-end`'s `direct_certified`): every
    /// turntable within these tolerances meets every accuracy, so they pass
    /// `check-turntable` on this schedule. `None` when not certifiable (`certified_note`).
    #[must_use]
    pub fn certified(&self) -> Option<&DirectAllocation> {
        self.certified.as_ref()
    }

    /// Why `certified` is `None`.
    #[must_use]
    pub fn certified_note(&self) -> Option<&str> {
        self.certified_note.as_deref()
    }

    /// Every output's condition number.
    #[must_use]
    pub fn condition_numbers(&self) -> &[f64] {
        &self.condition_numbers
    }

    /// $\sum_k\ln\det(\mathbf A_k^T\mathbf A_k)$.
    #[must_use]
    pub fn log_det_information(&self) -> f64 {
        self.log_det_information
    }

    /// The worst case of every output over the study schedule's tolerances (what the table
    /// one would buy for the study's schedule gives with this schedule).
    #[must_use]
    pub fn with_study_tolerances(&self) -> &StudyTolerancesWorstCase {
        &self.with_study_tolerances
    }

    /// The orientation requirement of eq 15-16 for this schedule, or why there is none.
    pub fn requirement(&self) -> &Result<OrientationRequirement, CalibError> {
        &self.requirement
    }
}

/// The tolerances one would buy for the study's schedule: its certified allocation when it has
/// one, else its (linearised) direct allocation.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StudyTolerances {
    /// The upper bounds (rad; `+inf` for an error the study's schedule needs no bound on).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// Whether they are the certified allocation (else the linearised one).
    pub(crate) certified: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl StudyTolerances {
    /// Tolerances `upper_bounds_rad` (rad, the table's rotation errors in order; `+inf` for an
    /// error left free), `certified` when they are a certified allocation.
    #[must_use]
    pub fn new(upper_bounds_rad: Vec<f64>, certified: bool) -> Self {
        Self {
            upper_bounds_rad,
            certified,
        }
    }

    /// The upper bounds (rad; `+inf` for an error the study's schedule needs no bound on).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// Whether they are the certified allocation (else the linearised one).
    #[must_use]
    pub fn certified(&self) -> bool {
        self.certified
    }
}

impl StudyTolerances {
    /// The certified allocation if any, else the direct one.
    #[must_use]
    pub fn of(direct: &DirectAllocation, certified: Option<&DirectAllocation>) -> Self {
        match certified {
            Some(c) => Self {
                upper_bounds_rad: c.upper_bounds_rad().to_vec(),
                certified: true,
            },
            None => Self {
                upper_bounds_rad: direct.upper_bounds_rad().to_vec(),
                certified: false,
            },
        }
    }

    /// The worst case of every output of `e2e` over these tolerances: an error they leave
    /// free (`+inf`) that `e2e`'s schedule depends on is unbounded, so every output that
    /// depends on it (to first order) has no finite worst case; the others are evaluated with
    /// those errors at 0.
    ///
    /// # Errors
    /// As [`EndToEnd::worst_case`].
    pub fn worst_case(
        &self,
        e2e: &EndToEnd,
        linear: &Linearization,
    ) -> Result<StudyTolerancesWorstCase, E2eError> {
        let free = linear.unconstrained();
        let unbounded: Vec<usize> = self
            .upper_bounds_rad
            .iter()
            .enumerate()
            .filter(|(j, u)| !u.is_finite() && !free.contains(j))
            .map(|(j, _)| j)
            .collect();
        let ub: Vec<f64> = self
            .upper_bounds_rad
            .iter()
            .enumerate()
            .map(|(j, u)| if unbounded.contains(&j) { 0.0 } else { *u })
            .collect();
        let wc = e2e.worst_case(linear, &ub)?;
        let n = linear.positions();
        // as Linearization::unconstrained: an entry below 1e-12 of the largest is no dependence
        let small = 1e-12 * linear.matrix().amax();
        let outputs = wc
            .outputs()
            .iter()
            .cloned()
            .map(|o| {
                let k = o.output();
                let reached = (0..n).any(|i| {
                    let row = linear.row(k, i);
                    unbounded.iter().any(|&j| row[j].abs() > small)
                });
                (!reached).then_some(o)
            })
            .collect();
        Ok(StudyTolerancesWorstCase {
            certified: self.certified,
            upper_bounds_rad: self.upper_bounds_rad.clone(),
            outputs,
            unbounded,
        })
    }
}

/// The worst case of a schedule's outputs over [`StudyTolerances`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct StudyTolerancesWorstCase {
    /// Whether the tolerances are the study schedule's certified allocation (else its
    /// linearised direct allocation, when it has no certified one).
    pub(crate) certified: bool,
    /// The tolerances (rad).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// Per output its worst case (linearised, exact at the worst vertex, second-order bound),
    /// or `None` when the output depends to first order on an error in `unbounded`.
    pub(crate) outputs: Vec<Option<OutputWorstCase>>,
    /// The errors the tolerances leave free (the study's schedule needs no bound on them)
    /// that this schedule depends on.
    pub(crate) unbounded: Vec<usize>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl StudyTolerancesWorstCase {
    /// Whether the tolerances are the study schedule's certified allocation (else its
    /// linearised direct allocation, when it has no certified one).
    #[must_use]
    pub fn certified(&self) -> bool {
        self.certified
    }

    /// The tolerances (rad).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// Per output its worst case (linearised, exact at the worst vertex, second-order bound),
    /// or `None` when the output depends to first order on an error in `unbounded`.
    #[must_use]
    pub fn outputs(&self) -> &[Option<OutputWorstCase>] {
        &self.outputs
    }

    /// The errors the tolerances leave free (the study's schedule needs no bound on them)
    /// that this schedule depends on.
    #[must_use]
    pub fn unbounded(&self) -> &[usize] {
        &self.unbounded
    }
}

/// The designed schedule and the baselines, each as a [`ScheduleReport`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ScheduleDesign {
    /// The designed schedule.
    pub(crate) designed: ScheduleReport,
    /// The study's own schedule.
    pub(crate) study: ScheduleReport,
    /// The D-optimal schedule of the same size over the same candidates.
    pub(crate) d_optimal: ScheduleReport,
    /// The best of the random schedules (`None` when none was feasible).
    pub(crate) random_best: Option<ScheduleReport>,
    /// The search behind them.
    pub(crate) search: DesignSearch,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ScheduleDesign {
    /// The designed schedule.
    #[must_use]
    pub fn designed(&self) -> &ScheduleReport {
        &self.designed
    }

    /// The study's own schedule.
    #[must_use]
    pub fn study(&self) -> &ScheduleReport {
        &self.study
    }

    /// The D-optimal schedule of the same size over the same candidates.
    #[must_use]
    pub fn d_optimal(&self) -> &ScheduleReport {
        &self.d_optimal
    }

    /// The best of the random schedules (`None` when none was feasible).
    #[must_use]
    pub fn random_best(&self) -> Option<&ScheduleReport> {
        self.random_best.as_ref()
    }

    /// The search behind them.
    #[must_use]
    pub fn search(&self) -> &DesignSearch {
        &self.search
    }
}

/// Design a schedule for a problem whose candidates contain the study's positions
/// ([`candidates_with`]) and report it beside the baselines: the study's schedule is a start
/// when it has `settings.positions` positions, so then the designed $J$ is at most the
/// study's. `extra` adds starts (e.g. a coarse-grid design, [`design_on_grid`]).
///
/// # Errors
/// As [`DesignProblem::design`] and [`DesignProblem::report`].
pub fn design_schedule(
    problem: &DesignProblem,
    study_positions_deg: &[Vec<f64>],
    delta_r_kind: DeltaRKind,
    settings: &DesignSettings,
    extra: &[(StartKind, Vec<usize>)],
    progress: &(dyn Fn() + Sync),
) -> Result<ScheduleDesign, E2eError> {
    let study_idx: Option<Vec<usize>> = study_positions_deg
        .iter()
        .map(|p| problem.index_of(p))
        .collect();
    let mut given: Vec<(StartKind, Vec<usize>)> = study_idx
        .into_iter()
        .filter(|s| s.len() == settings.positions)
        .map(|s| (StartKind::Study, s))
        .collect();
    given.extend(extra.iter().cloned());
    let search = problem.design(settings, &given, progress)?;
    let study = problem.report(study_positions_deg, delta_r_kind, None)?;
    let tolerances = StudyTolerances::of(&study.allocation, study.certified.as_ref());
    let rep =
        |s: &[usize]| problem.report(&problem.positions_deg(s), delta_r_kind, Some(&tolerances));
    Ok(ScheduleDesign {
        designed: rep(&search.designed.evaluation.schedule)?,
        d_optimal: rep(&search.d_optimal.schedule)?,
        random_best: search
            .random_best
            .as_ref()
            .map(|e| rep(&e.schedule))
            .transpose()?,
        study,
        search,
    })
}

/// Coarse grids are used up to this step (deg): every grid whose step is a whole multiple of
/// the fine step up to a full turn is one the fine grid contains.
pub(crate) const MAX_COARSE_STEP_DEG: f64 = 360.0;

/// Two grid positions are the same candidate when every joint angle agrees to this (deg):
/// a coarse grid's angles $k(Ms)$ and the fine grid's $(kM)s$ may differ by rounding.
pub(crate) const GRID_MATCH_DEG: f64 = 1e-9;

/// The coarse levels of a grid design with step `step_deg`: the multiples $M s$
/// ($M = 2, 3, \dots$) up to [`MAX_COARSE_STEP_DEG`], as `(M, step)`, coarsest first.
fn coarse_steps(step_deg: f64) -> Vec<(u32, f64)> {
    (2..=most_coarse_multiple(step_deg))
        .rev()
        .map(|m| (m, f64::from(m) * step_deg))
        .collect()
}

/// What a grid design needs besides the step and the settings (a study fills it).
#[derive(Debug, Clone, Copy)]
pub struct DesignInputs<'a> {
    /// The turntable.
    pub turntable: &'a tt_kinematics::Turntable,
    /// The sensor.
    pub sensor: &'a gw_model::SensorModel,
    /// The site.
    pub site: &'a gw_model::Site,
    /// The reading of eq 13.
    pub reading: calib_lsq::Reading,
    /// The orientation-error matrix of eq 7 (for the requirement).
    pub delta_r_kind: DeltaRKind,
    /// Lower bounds of the angular errors (rad).
    pub lower_bounds_rad: &'a [f64],
    /// The study's schedule (joint angles, deg).
    pub study_positions_deg: &'a [Vec<f64>],
    /// The study's specifications (`None`: the design objective is eq 14's direct allocation).
    pub specifications: Option<&'a SpecObjective>,
}

/// The grid design: the candidates are the grid of `step_deg` ([`grid_positions_deg`]) and
/// the study's positions; besides the study's schedule, the best design of every coarser grid
/// the fine one contains (the steps $Ms$, $M \ge 2$, up to [`MAX_COARSE_STEP_DEG`]) is a start.
/// Each coarse level is designed exactly as `design_on_grid` would design it on its own (its
/// grid and the study's positions, the study's schedule and the best of its own coarser
/// levels as starts), coarsest first, so a finer grid is never worse than a coarser one it
/// contains: the exchange never loses on its start. A coarse grid that cannot identify the
/// sensor or meet the bound is skipped. Returns the problem (for the candidates) and the
/// design.
///
/// # Errors
/// As [`grid_positions_deg`], [`DesignProblem::new`] and [`design_schedule`].
pub fn design_on_grid(
    inputs: &DesignInputs<'_>,
    step_deg: f64,
    settings: &DesignSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<(DesignProblem, ScheduleDesign), E2eError> {
    let problem_of = |step: f64| {
        DesignProblem::new(
            inputs.turntable,
            inputs.sensor,
            inputs.site,
            inputs.reading,
            inputs.lower_bounds_rad,
            candidates_with(
                grid_positions_deg(inputs.turntable, step)?,
                inputs.study_positions_deg,
            ),
        )
        .map(|p| p.with_specifications(inputs.specifications.cloned()))
    };
    let fine = problem_of(step_deg)?;
    // The starts of a level: the study's schedule, then the best design of its multiples.
    let starts = |problem: &DesignProblem,
                  best: Option<&(f64, Vec<Vec<f64>>)>|
     -> Vec<(StartKind, Vec<usize>)> {
        let study: Option<Vec<usize>> = inputs
            .study_positions_deg
            .iter()
            .map(|p| problem.index_of(p))
            .collect();
        let mut given: Vec<(StartKind, Vec<usize>)> = study
            .into_iter()
            .filter(|s| s.len() == settings.positions)
            .map(|s| (StartKind::Study, s))
            .collect();
        if let Some(g) = best.and_then(|(_, p)| indices_near(problem, p)) {
            given.push((StartKind::Coarse, g));
        }
        given
    };
    // levels[m]: the design (J, positions) of the grid of step m * step_deg
    let levels_steps = coarse_steps(step_deg);
    let mut designs: Vec<(u32, f64, Vec<Vec<f64>>)> = Vec::new();
    let best_of_multiples = |designs: &[(u32, f64, Vec<Vec<f64>>)], m: u32| {
        designs
            .iter()
            .filter(|(mm, _, _)| mm % m == 0)
            .min_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .map(|(_, j, p)| (*j, p.clone()))
    };
    for &(m, step) in &levels_steps {
        let Ok(problem) = problem_of(step) else {
            progress();
            continue;
        };
        let best = best_of_multiples(&designs, m);
        let given = starts(&problem, best.as_ref());
        match problem.restarts(settings, &given, &|| {}) {
            Ok((r, b)) => {
                if let Some(e) = &r[b].exchange {
                    designs.push((
                        m,
                        e.evaluation.objective,
                        problem.positions_deg(&e.evaluation.schedule),
                    ));
                }
            }
            Err(E2eError::ConditionUnreachable { .. } | E2eError::TooManyPositions { .. }) => {}
            Err(e) => return Err(e),
        }
        progress();
    }
    let best = best_of_multiples(&designs, 1);
    let extra: Vec<(StartKind, Vec<usize>)> = best
        .as_ref()
        .and_then(|(_, p)| indices_near(&fine, p))
        .map(|g| vec![(StartKind::Coarse, g)])
        .unwrap_or_default();
    let design = design_schedule(
        &fine,
        inputs.study_positions_deg,
        inputs.delta_r_kind,
        settings,
        &extra,
        progress,
    )?;
    Ok((fine, design))
}

/// The candidates of `problem` at `positions` (deg), each within [`GRID_MATCH_DEG`] on every
/// joint; `None` if one is missing.
fn indices_near(problem: &DesignProblem, positions: &[Vec<f64>]) -> Option<Vec<usize>> {
    positions
        .iter()
        .map(|p| {
            problem.index_of(p).or_else(|| {
                (0..problem.n_candidates()).find(|&c| {
                    problem.candidates_deg[c]
                        .iter()
                        .zip(p)
                        .all(|(a, b)| (a - b).abs() <= GRID_MATCH_DEG)
                })
            })
        })
        .collect()
}

/// The number of coarse levels [`design_on_grid`] tries for `step_deg` (one progress unit
/// each).
#[must_use]
pub fn coarse_levels(step_deg: f64) -> u64 {
    // counted, not enumerated: a tiny step (refused later, by the grid count) must not
    // allocate one entry per multiple first
    u64::from(most_coarse_multiple(step_deg).saturating_sub(1))
}

/// The largest multiple $M$ with $M \cdot$ `step_deg` $\le$ [`MAX_COARSE_STEP_DEG`] (0 for a
/// step that is not positive and finite).
fn most_coarse_multiple(step_deg: f64) -> u32 {
    if !(step_deg > 0.0 && step_deg.is_finite()) {
        return 0;
    }
    (MAX_COARSE_STEP_DEG / step_deg + 1e-9)
        .floor()
        .min(f64::from(u32::MAX)) as u32
}

#[cfg(test)]
mod grid_tests {
    use super::*;

    /// The enumeration the count replaces (issue 19: it grew to 24 GB for a 1e-308 deg step).
    fn enumerated(lo: f64, hi: f64, step: f64) -> f64 {
        let full = hi - lo >= 360.0 - 1e-9;
        let mut k = 0_u32;
        loop {
            let a = lo + f64::from(k) * step;
            if a > hi + 1e-9 || (full && a >= lo + 360.0 - 1e-9) {
                return f64::from(k);
            }
            k += 1;
        }
    }

    /// The computed count of a joint's grid angles is the enumerated one, for full turns,
    /// partial ranges, steps that divide them and steps that do not.
    #[test]
    fn grid_counts_equal_the_enumeration() {
        for (lo, hi) in [
            (0.0, 360.0),
            (-180.0, 180.0),
            (0.0, 90.0),
            (-45.0, 30.0),
            (10.0, 10.5),
        ] {
            for step in [0.1, 0.7, 1.0, 7.0, 13.0, 15.0, 45.0, 100.0, 360.0] {
                assert_eq!(
                    axis_count(lo, hi, step).to_bits(),
                    enumerated(lo, hi, step).to_bits(),
                    "[{lo}, {hi}] step {step}"
                );
            }
        }
    }

    /// A step that would give more than [`MAX_CANDIDATES`] positions is refused before any
    /// is built, with the counts (also when they exceed every float).
    #[test]
    fn tiny_steps_are_refused_with_the_count_before_building() {
        let t = tt_kinematics::paper::table3();
        let e = grid_positions_deg(&t, 1e-308).unwrap_err();
        let E2eError::GridTooLarge {
            per_joint_log10, ..
        } = &e
        else {
            panic!("{e:?}")
        };
        assert!(
            per_joint_log10.iter().all(|c| *c > 310.0 && *c < 311.0),
            "{e}"
        );
        assert!(
            e.to_string().contains("about 1.3e621 candidate positions"),
            "{e}"
        );
        let e = grid_positions_deg(&t, 1e-6).unwrap_err().to_string();
        assert!(
            e.contains("129600000000000000 candidate positions")
                || e.contains("about 1.3e17 candidate positions"),
            "{e}"
        );
        assert!(e.contains("360000000 x 360000000 per joint"), "{e}");
        let e = grid_positions_deg(&t, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("129600 candidate positions (360 x 360 per joint), more than 50000"),
            "{e}"
        );
    }
}
