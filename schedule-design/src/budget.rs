//! Test time as a resource: the positions and the dwell chosen together under a total
//! test-time budget, with the sensor's noise counted (issue 21, item 4).
//!
//! # Objective
//! For a schedule $S$ of $N$ positions and a dwell $T$ at each, $J(S, T)$ is the direct
//! allocation with the noise part kept free at $\kappa$ sigma
//! ([`e2e_verify::NoiseQuestions::allocate_direct_with_noise`], as `end-to-end`'s trade-off computes it): every
//! row of output $k$ is held to $\omega_{m,k} - \kappa\sigma_k(S, T)$, where $\sigma_k$ is
//! the largest standard deviation of output $k$'s calibrated rate error over the positions
//! (calib-lsq's covariance for white, Gauss-Markov and quantization noise, positions in the
//! schedule's order, the same dwell $T$ at each). No table suffices when the noise part (with
//! the lower bounds' table part) fills an accuracy: $J = \infty$. The total test time is
//! $N\,(T + T_{move})$ (a move before every dwell).
//!
//! # The search
//! ## The number of positions
//! With [`TimeBudget::search_counts`] the number of positions is searched too: besides the
//! table design's $N$, the counts [`budget_counts`] gives (the fewest that identify every
//! output, $N_{min}$; the geometric mean of $N_{min}$ and $N$; the study's own count; and the
//! count the budget affords at the study's dwell), each at most what the budget affords at one
//! sample per dwell and at most [`BudgetParams::max_count_factor`] times the larger of $N$ and
//! the study's count. Each count gets a table design (the greedy construction and the exchange on
//! the same candidates; a count whose construction does not meet the condition bound is
//! skipped and reported) and one noise-aware search at the dwell that spends the budget on it.
//! The front and the choice then run over every count. Fewer positions leave each a longer
//! dwell (and less time moving); more positions give the least squares more equations: which
//! wins depends on the noise, the move time and the reading, so the counts are searched, not
//! assumed. The coarse counts are then refined by bisection: the count halfway between the
//! best count at the budget (least $J$ within it) and each tried neighbour (the nearest tried
//! count below and above) gets a design and a search the same way, and the step repeats on the
//! new best, at most [`BudgetParams::count_refinements`] designs in all; when it ends with
//! designs to spare, the best count's tried neighbours are the adjacent counts (a local optimum
//! over the tried neighbours). Each refined count's budget dwell joins the grid (evaluated for
//! every schedule). A budget shorter than $N_{min}\,(T_{move} + 1/f_s)$ is
//! [`E2eError::BudgetTooShort`], naming `time_budget_s`.
//!
//! The noise part depends on the schedule, so the search holds it fixed and updates it (a
//! fixed point): for a dwell $T$, start from the best schedule known at $T$, take its noise
//! parts $m_k = \kappa\sigma_k(S, T)$, and run the exchange ([`DesignProblem::exchange`],
//! the table's search with every bound and screening unchanged) on the problem whose
//! accuracies are $\omega_{m,k} - m_k$: its $J$ is exactly $J(S', T)$ for any $S'$ with the
//! same noise parts. That problem leaves out the study's specifications
//! ([`DesignProblem::with_specifications`]): $J(S, T)$, which the front reads, is eq 14's
//! rows alone, and the screening holds eq 14's rows to the lowered accuracies, so its bounds
//! are lower bounds of the $J$ the exchange evaluates (with the specifications it evaluated
//! the specified allocation at the study's dwell, which reads neither $T$ nor the lowered
//! accuracies, and its bounds could exceed it). The result's own noise parts are then computed and the step repeated
//! (at most [`BudgetParams::fixed_point_steps`] times, or until the schedule stops changing).
//! This runs at [`BudgetParams::search_dwells`] dwells: the budget's own and dwells spread over those at
//! which some known schedule leaves the table room.
//!
//! # The Pareto front
//! Every schedule found (the table's design, the study's schedule, every noise-aware design)
//! is evaluated exactly at every dwell of a grid ([`BudgetParams::dwells_per_decade`] per decade in
//! $\log T$ from one sample to the longest dwell, plus each schedule's dwell that spends the
//! whole budget, and the study's own dwell); the study's, the table designs' and the
//! baselines' schedules also at the dwells of their own time/table trade-off as `end-to-end`
//! lists it ([`e2e_verify::NoiseQuestions::tradeoff`]: just above the shortest dwell at which some table
//! suffices, and on to a thousand times it), so the front never misses a schedule's short end
//! between the grid's dwells. The front is the set of $(N(T + T_{move}), J)$
//! not dominated by another:
//! sorted by the total time, each point needs a strictly cheaper table than every point
//! before it, so more time never needs a better table. Each front point carries its
//! tolerance box ([`BudgetPoint::tolerances_rad`]: the direct allocation whose $J$ it is).
//! The chosen point is the cheapest table within the budget (ties: the shorter test).
//!
//! # What is guaranteed
//! Every point's $J$ is computed exactly (not estimated) on the same path as `end-to-end`
//! (study positions to [`EndToEnd`], its linearisation, calib-lsq's covariance, the shared
//! allocation core), and the schedules searched include the study's and the table's design,
//! so the chosen point is never worse than either at the budget's dwell, nor than the study's
//! schedule at the study's own dwell ([`TimeBudget::study_dwell_s`]) when that test fits the
//! budget. With the counts searched, the fixed-count design's searches run unchanged (at the
//! same dwells, chosen among the fixed-count design's grid) and every schedule is evaluated
//! at a superset of its dwells, so the choice is never worse than the fixed-count one. The
//! search is a local one (single exchanges, noise parts held fixed within each exchange): not
//! a global optimum.

use super::DesignProblem;
use crate::tally::{Phases, Tally};
use calib_lsq::Timing;
use e2e_verify::E2eError;
use e2e_verify::EndToEnd;
use gw_model::noise::NoiseModel;
use rayon::prelude::*;

/// The budget search's knobs (see [`design_with_budget`]); [`BudgetParams::default`] gives the
/// documented values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetParams {
    /// Dwells of the evaluation grid per decade of $T$ (dimensionless; default 4): the front's
    /// resolution in test time (a factor $10^{1/4} \approx 1.78$ between neighbours).
    pub dwells_per_decade: usize,
    /// Dwells at which the noise-aware search runs, the budget's own first (default 4).
    pub search_dwells: usize,
    /// Updates of the noise part per searched dwell at most (the fixed point of the search;
    /// default 2).
    pub fixed_point_steps: usize,
    /// The searched counts are at most this many times the larger of the table design's and
    /// the study's count (dimensionless; default 2): an exchange costs about the count times
    /// the candidates in screened swaps, so the count is bounded to keep the search within
    /// its time.
    pub max_count_factor: usize,
    /// Extra counts the refinement may design at most (default 8; 0: no refinement): after
    /// the coarse counts, the count halfway between the best count at the budget and each
    /// tried neighbour, repeated on the new best (a bisection on the count).
    pub count_refinements: usize,
    /// Positions beyond the fewest that identify every output
    /// ([`DesignProblem::min_positions`]) that every searched count and every point of the
    /// front keeps at least (default [`DEFAULT_REDUNDANCY`]); the study's own schedule is
    /// evaluated whatever its count.
    pub redundancy: usize,
}

/// The default [`BudgetParams::redundancy`]: two positions beyond the fewest that identify
/// every output, so no proposed test rests on an exactly determined fit (issue 35).
pub const DEFAULT_REDUNDANCY: usize = 2;

impl Default for BudgetParams {
    fn default() -> Self {
        Self {
            dwells_per_decade: 4,
            search_dwells: 4,
            fixed_point_steps: 2,
            max_count_factor: 2,
            count_refinements: 8,
            redundancy: DEFAULT_REDUNDANCY,
        }
    }
}

/// The fewest positions a searched count or a front point keeps: the fewest that identify
/// every output plus [`BudgetParams::redundancy`].
#[must_use]
pub fn fewest_proposed(problem: &DesignProblem, b: &TimeBudget<'_>) -> usize {
    problem.min_positions().max(1) + b.params.redundancy
}

/// The noise, timing and budget of a budget design.
#[derive(Debug, Clone, Copy)]
pub struct TimeBudget<'a> {
    /// Per output its noise (`None`: noiseless).
    pub noise: &'a [Option<NoiseModel>],
    /// Time to move between two positions (s).
    pub move_s: f64,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// $\kappa$ of the noise part.
    pub k_sigma: f64,
    /// The total test time allowed (s).
    pub budget_s: f64,
    /// The longest dwell per position considered (s).
    pub max_dwell_s: f64,
    /// The study's own dwell per position (s), when it is one value: every schedule is also
    /// evaluated there, so the choice never loses to the study's schedule at its own timing
    /// when that fits the budget.
    pub study_dwell_s: Option<f64>,
    /// Whether the number of positions is searched too (see [`design_with_budget`]); else only
    /// the table design's count (and the other schedules' own counts) are evaluated.
    pub search_counts: bool,
    /// The search's knobs.
    pub params: BudgetParams,
    /// The study's rate steps (schedule entries with a motion), run after every schedule's
    /// static positions in this order; empty for a static study.
    pub rate_steps: &'a [calib_lsq::Position],
    /// Each rate step's averaging window, its whole revolutions' turning time (s; the study's
    /// `Timing::rate_step_s`): kept whatever the static dwell.
    pub rate_step_s: &'a [f64],
}

impl TimeBudget<'_> {
    /// What the rate steps add to every test (s): their windows and one move before each.
    #[must_use]
    pub(crate) fn rate_steps_s(&self) -> f64 {
        self.rate_step_s.iter().sum::<f64>() + self.move_s * self.rate_step_s.len() as f64
    }

    /// The total time of a test of `n` static positions at `dwell_s` each and the rate steps
    /// ([`total_test_s`] plus [`TimeBudget::rate_steps_s`]), s.
    #[must_use]
    pub fn test_s(&self, n: usize, dwell_s: f64) -> f64 {
        total_test_s(n, dwell_s, self.move_s) + self.rate_steps_s()
    }

    /// The budget left for the static positions (s).
    fn static_budget_s(&self) -> f64 {
        self.budget_s - self.rate_steps_s()
    }

    /// The timing of `n` static positions at `dwell_s` each, then the rate steps' windows.
    ///
    /// # Errors
    /// As [`Timing::uniform`] and [`Timing::with_rate_steps`].
    pub fn timing(&self, n: usize, dwell_s: f64) -> Result<Timing, E2eError> {
        Ok(
            Timing::uniform(n, dwell_s, self.move_s, self.sample_rate_hz)?
                .with_rate_steps(self.rate_step_s.to_vec())?,
        )
    }
}

/// Where a schedule of the budget design comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScheduleOrigin {
    /// The design for the table's part alone.
    Table,
    /// The study's own schedule.
    Study,
    /// The D-optimal schedule (the least noise for white noise, whatever the table).
    DOptimal,
    /// The noise-aware search at this dwell (s).
    Noise(f64),
}

/// One schedule at one dwell, evaluated exactly.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BudgetPoint {
    /// Where the schedule comes from.
    pub(crate) origin: ScheduleOrigin,
    /// The positions (joint angles, deg).
    pub(crate) positions_deg: Vec<Vec<f64>>,
    /// The dwell at every position (s).
    pub(crate) dwell_s: f64,
    /// The total test time $N(T + T_{move})$ (s).
    pub(crate) total_s: f64,
    /// $J$ (rad$^{-2}$) of the direct allocation with the noise part kept free.
    pub(crate) objective: f64,
    /// The allocated tolerance box: the direct allocation's upper bound per rotation error
    /// (rad), the box whose $J$ is `objective`; empty for a point not on the front (the
    /// front's points carry theirs).
    pub(crate) tolerances_rad: Vec<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BudgetPoint {
    /// A point of the front: the schedule from `origin` with `positions_deg` (joint angles,
    /// deg), dwell `dwell_s` (s) at every position, total test time `total_s` (s) and the
    /// table's $J$ `objective` (rad$^{-2}$).
    #[must_use]
    pub fn new(
        origin: ScheduleOrigin,
        positions_deg: Vec<Vec<f64>>,
        dwell_s: f64,
        total_s: f64,
        objective: f64,
    ) -> Self {
        Self {
            origin,
            positions_deg,
            dwell_s,
            total_s,
            objective,
            tolerances_rad: Vec::new(),
        }
    }

    /// The allocated tolerance box: the direct allocation with the noise part kept free,
    /// its upper bound per rotation error (rad, the order of the turntable's rotation
    /// errors); empty for a point built by [`BudgetPoint::new`] or not on the front.
    #[must_use]
    pub fn tolerances_rad(&self) -> &[f64] {
        &self.tolerances_rad
    }

    /// Where the schedule comes from.
    #[must_use]
    pub fn origin(&self) -> ScheduleOrigin {
        self.origin
    }

    /// The positions (joint angles, deg).
    #[must_use]
    pub fn positions_deg(&self) -> &[Vec<f64>] {
        &self.positions_deg
    }

    /// The dwell at every position (s).
    #[must_use]
    pub fn dwell_s(&self) -> f64 {
        self.dwell_s
    }

    /// The total test time $N(T + T_{move})$ (s).
    #[must_use]
    pub fn total_s(&self) -> f64 {
        self.total_s
    }

    /// $J$ (rad$^{-2}$) of the direct allocation with the noise part kept free.
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }
}

impl BudgetPoint {
    /// Number of positions $N$.
    #[must_use]
    pub fn n_positions(&self) -> usize {
        self.positions_deg.len()
    }

    /// $J$ in arcmin$^{-2}$.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        tt_core::units::objective_to_arcmin(self.objective)
    }
}

/// The budget design's result.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BudgetDesign {
    /// The budget (s).
    pub(crate) budget_s: f64,
    /// $\kappa$ of the noise part.
    pub(crate) k_sigma: f64,
    /// The evaluation grid of dwells (s), ascending.
    pub(crate) dwells_s: Vec<f64>,
    /// Every schedule evaluated, with its origin.
    pub(crate) schedules: Vec<(ScheduleOrigin, Vec<Vec<f64>>)>,
    /// Schedule-dwell pairs evaluated.
    pub(crate) evaluated: usize,
    /// The Pareto front, by ascending total time (and strictly descending $J$).
    pub(crate) pareto: Vec<BudgetPoint>,
    /// The cheapest table within the budget; `None` when no evaluated point within it leaves
    /// the table room.
    pub(crate) chosen: Option<BudgetPoint>,
    /// The numbers of positions designed for, ascending (the table design's among them).
    pub(crate) counts: Vec<usize>,
    /// The searched counts with no table design: the greedy construction did not meet the
    /// condition bound (or the allocation failed at every candidate of a step).
    pub(crate) counts_skipped: Vec<usize>,
    /// The counts the refinement tried, in the order tried (among `counts` or
    /// `counts_skipped`).
    pub(crate) counts_refined: Vec<usize>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BudgetDesign {
    /// The budget (s).
    #[must_use]
    pub fn budget_s(&self) -> f64 {
        self.budget_s
    }

    /// $\kappa$ of the noise part.
    #[must_use]
    pub fn k_sigma(&self) -> f64 {
        self.k_sigma
    }

    /// The evaluation grid of dwells (s), ascending.
    #[must_use]
    pub fn dwells_s(&self) -> &[f64] {
        &self.dwells_s
    }

    /// Every schedule evaluated, with its origin.
    #[must_use]
    pub fn schedules(&self) -> &[(ScheduleOrigin, Vec<Vec<f64>>)] {
        &self.schedules
    }

    /// Schedule-dwell pairs evaluated.
    #[must_use]
    pub fn evaluated(&self) -> usize {
        self.evaluated
    }

    /// The Pareto front, by ascending total time (and strictly descending $J$).
    #[must_use]
    pub fn pareto(&self) -> &[BudgetPoint] {
        &self.pareto
    }

    /// The cheapest table within the budget; `None` when no evaluated point within it leaves
    /// the table room.
    #[must_use]
    pub fn chosen(&self) -> Option<&BudgetPoint> {
        self.chosen.as_ref()
    }

    /// The numbers of positions designed for, ascending (the table design's among them).
    #[must_use]
    pub fn counts(&self) -> &[usize] {
        &self.counts
    }

    /// The searched counts with no table design: the greedy construction did not meet the
    /// condition bound (or the allocation failed at every candidate of a step).
    #[must_use]
    pub fn counts_skipped(&self) -> &[usize] {
        &self.counts_skipped
    }

    /// The counts the refinement tried, in the order tried (among `counts` or
    /// `counts_skipped`).
    #[must_use]
    pub fn counts_refined(&self) -> &[usize] {
        &self.counts_refined
    }
}

/// The total test time of `n` positions with `dwell_s` each: $N(T + T_{move})$ (s).
#[must_use]
pub fn total_test_s(n: usize, dwell_s: f64, move_s: f64) -> f64 {
    n as f64 * (dwell_s + move_s)
}

/// The non-dominated points of `points` (by total time, then $J$): ascending total time,
/// each with a $J$ strictly below every point before it.
#[must_use]
pub fn pareto_front(points: &[BudgetPoint]) -> Vec<BudgetPoint> {
    let mut sorted: Vec<&BudgetPoint> = points.iter().filter(|p| p.objective.is_finite()).collect();
    sorted.sort_by(|a, b| {
        a.total_s
            .total_cmp(&b.total_s)
            .then(a.objective.total_cmp(&b.objective))
    });
    let mut out: Vec<BudgetPoint> = Vec::new();
    for p in sorted {
        if out.last().is_none_or(|q| p.objective < q.objective) {
            out.push(p.clone());
        }
    }
    out
}

impl DesignProblem {
    /// The noise-aware search's problem: every output's accuracy lowered by `margins[k]`
    /// (output unit) and no specifications, so that its $J$ is the direct allocation with
    /// those margins kept free ($J(S, T)$ of the front) and the screening's eq 14 rows, held
    /// to the lowered accuracies, bound the $J$ its exchange evaluates. `None` when a margin
    /// leaves no room.
    fn with_margins(&self, margins: &[f64]) -> Option<Self> {
        if self
            .accuracies
            .iter()
            .zip(margins)
            .any(|(a, m)| (a - m).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
        {
            return None;
        }
        let mut p = self.clone().with_specifications(None);
        for ((o, acc), m) in p.outputs.iter_mut().zip(&mut p.accuracies).zip(margins) {
            *acc -= m;
            let w = 1.0 / *acc;
            let (c_g, c_e, d) = (self.affine.c_g, self.affine.c_e, self.affine.d);
            o.c0 =
                o.dg.iter()
                    .zip(&o.de)
                    .map(|(g, e)| (c_g * g + c_e * e) * w)
                    .collect();
            o.c1 =
                o.dg.iter()
                    .zip(&o.de)
                    .map(|(g, e)| d * (g + e) * w)
                    .collect();
        }
        Some(p)
    }
}

/// One schedule's end-to-end simulator and linearisation, evaluated at dwells.
struct Evaluator<'a> {
    e2e: EndToEnd,
    linear: e2e_verify::Linearization,
    lower_bounds_rad: &'a [f64],
    budget: &'a TimeBudget<'a>,
    tally: &'a Tally,
}

impl Evaluator<'_> {
    fn noise(&self, dwell_s: f64) -> Result<e2e_verify::NoiseBudget, E2eError> {
        let n = self.e2e.len() - self.budget.rate_steps.len();
        let timing = self.budget.timing(n, dwell_s)?;
        self.e2e.noise().noise_budget(self.budget.noise, &timing)
    }

    /// The direct allocation with the noise part kept free at `dwell_s` (`None` when no
    /// table suffices).
    fn allocation(&self, dwell_s: f64) -> Result<Option<e2e_verify::DirectAllocation>, E2eError> {
        self.tally.dwell_evaluation();
        let noise = self.noise(dwell_s)?;
        Ok(self
            .e2e
            .noise()
            .allocate_direct_with_noise(
                &self.linear,
                self.lower_bounds_rad,
                &noise,
                self.budget.k_sigma,
                None,
            )?
            .ok())
    }

    /// $J(S, T)$ (rad$^{-2}$; `+inf` when no table suffices).
    fn objective(&self, dwell_s: f64) -> Result<f64, E2eError> {
        Ok(self
            .allocation(dwell_s)?
            .map_or(f64::INFINITY, |d| d.objective()))
    }

    /// The schedule's points at the dwells of its time/table trade-off, as `end-to-end`
    /// lists them ([`e2e_verify::NoiseQuestions::tradeoff`] over the budget's dwells, from one sample to the
    /// longest dwell): the first just above the shortest dwell at which some table suffices,
    /// so the front never misses a schedule's own short end between the grid's dwells. A
    /// listed dwell within [`SAME_DWELL_REL`] of a `grid` dwell is left to the grid (the
    /// trade-off's longest dwell is the grid's last one up to round-off: kept twice it gave
    /// the front two copies of one point, one of them at 86,399.99999999993 s).
    fn tradeoff_points(
        &self,
        origin: ScheduleOrigin,
        positions_deg: &[Vec<f64>],
        lo: f64,
        grid: &[f64],
    ) -> Result<Vec<BudgetPoint>, E2eError> {
        let b = self.budget;
        let n = positions_deg.len();
        self.tally.tradeoff();
        let tradeoff = self.e2e.noise().tradeoff(&e2e_verify::TradeoffInputs {
            linear: &self.linear,
            lower_bounds_rad: self.lower_bounds_rad,
            noise: b.noise,
            timing: &b.timing(n, lo)?,
            k_sigma: b.k_sigma,
            dwell_range_s: (lo, b.max_dwell_s),
        })?;
        Ok(tradeoff
            .points()
            .iter()
            .filter(|p| {
                !grid
                    .iter()
                    .any(|g| (g - p.dwell_s()).abs() <= SAME_DWELL_REL * g)
            })
            .filter_map(|p| {
                p.objective().map(|j| BudgetPoint {
                    origin,
                    positions_deg: positions_deg.to_vec(),
                    dwell_s: p.dwell_s(),
                    total_s: b.test_s(n, p.dwell_s()),
                    objective: j,
                    tolerances_rad: Vec::new(),
                })
            })
            .collect())
    }
}

/// Two dwells closer than this fraction of the grid's are one dwell (round-off of the same
/// time, e.g. a day computed as a sum of steps).
const SAME_DWELL_REL: f64 = 1e-9;

/// The dwell grid: `per_decade` dwells per decade from one sample to `max_dwell_s`, with
/// `extra` dwells in that range merged in, ascending, without repeats.
fn dwell_grid(lo: f64, hi: f64, extra: &[f64], per_decade: usize) -> Vec<f64> {
    let decades = (hi / lo).log10().max(0.0);
    let steps = (decades * per_decade as f64).ceil() as usize;
    let mut out: Vec<f64> = (0..=steps)
        .map(|i| {
            if steps == 0 {
                lo
            } else {
                (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / steps as f64)
                    .exp()
                    .clamp(lo, hi)
            }
        })
        .collect();
    out.extend(extra.iter().copied().filter(|t| *t >= lo && *t <= hi));
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

/// The shortest test that can identify every output: the fewest positions that do
/// ([`DesignProblem::min_positions`]) with one move and one sample each (s).
#[must_use]
pub fn shortest_test_s(problem: &DesignProblem, b: &TimeBudget<'_>) -> f64 {
    b.test_s(problem.min_positions(), 1.0 / b.sample_rate_hz)
}

/// [`E2eError::BudgetTooShort`] when the budget is shorter than [`shortest_test_s`].
///
/// # Errors
/// That error, naming `time_budget_s`.
pub fn check_budget_affords(problem: &DesignProblem, b: &TimeBudget<'_>) -> Result<(), E2eError> {
    let needed_s = shortest_test_s(problem, b);
    if b.budget_s < needed_s {
        let n = problem.min_positions();
        let output = problem
            .outputs
            .iter()
            .zip(&problem.output_names)
            .find(|(o, _)| o.p == n)
            .map(|(_, name)| name.clone())
            .unwrap_or_default();
        return Err(E2eError::BudgetTooShort {
            budget_s: b.budget_s,
            positions: n,
            output,
            needed_s,
        });
    }
    Ok(())
}

/// The counts searched besides the table design's `n` (see [`design_with_budget`]): $N_{min}$,
/// $\mathrm{round}\sqrt{N_{min} N}$, the study's count `n_study` and the count the budget
/// affords at the study's dwell, each within $[N_{min}$, the count the budget affords at one
/// sample per dwell$]$, at most [`BudgetParams::max_count_factor`] $\max(N, N_{study})$ and the
/// candidates; ascending, without `n` and repeats.
#[must_use]
pub fn budget_counts(
    problem: &DesignProblem,
    b: &TimeBudget<'_>,
    n: usize,
    n_study: usize,
) -> Vec<usize> {
    let n_min = fewest_proposed(problem, b);
    let top = count_limit(problem, b, n, n_study);
    let mut v = vec![
        n_min,
        ((n_min as f64) * (n as f64)).sqrt().round() as usize,
        n_study,
    ];
    if let Some(t) = b.study_dwell_s {
        v.push(
            (b.static_budget_s() / (t + b.move_s))
                .floor()
                .max(0.0)
                .min(usize::MAX as f64) as usize,
        );
    }
    v.retain(|&c| c >= n_min && c <= top && c != n);
    v.sort_unstable();
    v.dedup();
    v
}

/// The largest count searched: what the budget affords at one sample per dwell, at most
/// [`BudgetParams::max_count_factor`] $\max(N, N_{study})$ and the candidates.
fn count_limit(problem: &DesignProblem, b: &TimeBudget<'_>, n: usize, n_study: usize) -> usize {
    let per_position = b.move_s + 1.0 / b.sample_rate_hz;
    let afford = (b.static_budget_s() / per_position)
        .floor()
        .max(0.0)
        .min(usize::MAX as f64) as usize;
    afford
        .min(b.params.max_count_factor.saturating_mul(n.max(n_study)))
        .min(problem.n_candidates())
}

/// The dwell that spends the whole budget on `n` positions, if it holds one sample and is
/// within the longest dwell.
fn budget_dwell(b: &TimeBudget<'_>, n: usize, lo: f64) -> Option<f64> {
    let t = b.static_budget_s() / n as f64 - b.move_s;
    (t >= lo && t <= b.max_dwell_s).then_some(t)
}

/// Positions and dwell chosen together under a total test-time budget (the objective, the
/// count search with its refinement by bisection, the front and the guarantees are described
/// in `src/budget.rs`'s module docs and the crate README): `table` is the design for the table's part alone, `study` the study's
/// schedule (candidate indices of `problem`, if all its positions are candidates) and
/// `others` more schedules (e.g. the D-optimal one), each a start of the noise-aware search
/// when it has the designed size; the study's schedule (`study_positions_deg`) is evaluated in
/// any case.
///
/// The steps: the inputs checked (`checked_shortest_dwell`), the known schedules and the
/// other counts' table designs (`Found::start`, `Found::design_counts`), every schedule at
/// every dwell of the grid (`Found::evaluate_grid`), the noise-aware searches
/// (`Found::searched_dwells`, `Found::noise_jobs`, `Found::add_noise_searches`), the
/// count's refinement (`Found::refine_counts`) and the front (`Found::finish`). Each
/// schedule's end-to-end simulator and linearisation are built once and kept for every dwell.
///
/// # Errors
/// [`E2eError::Field`] naming `budget_s`, `max_dwell_s`, `sample_rate_hz` or `move_s` when
/// not finite and positive (non-negative for the move); as [`e2e_verify::NoiseQuestions::noise_budget`] and
/// [`e2e_verify::NoiseQuestions::allocate_direct_with_noise`].
pub fn design_with_budget(
    problem: &DesignProblem,
    table: &[usize],
    study: Option<&[usize]>,
    study_positions_deg: &[Vec<f64>],
    others: &[(ScheduleOrigin, Vec<usize>)],
    max_condition: f64,
    b: &TimeBudget<'_>,
) -> Result<BudgetDesign, E2eError> {
    let lo = checked_shortest_dwell(problem, b)?;
    let tally = Tally::default();
    let mut phases = Phases::start();
    let run = Run {
        problem,
        b,
        max_condition,
        lo,
        n: table.len(),
        n_study: study_positions_deg.len(),
        tally: &tally,
    };
    let mut found = Found::start(&run, table, study, study_positions_deg, others)?;
    phases.step("known schedules' simulators", &tally);
    // the dwells of the fixed-count design: the searched dwells are chosen among them, so that
    // the count search only adds to what the fixed-count design searches
    let mut fixed_extra: Vec<f64> = found
        .schedules
        .iter()
        .filter_map(|(_, s)| budget_dwell(b, s.len(), lo))
        .collect();
    fixed_extra.extend(b.study_dwell_s);
    let fixed_dwells = dwell_grid(lo, b.max_dwell_s, &fixed_extra, b.params.dwells_per_decade);
    let count_tables = found.design_counts(&run)?;
    phases.step("other counts' table designs", &tally);
    let mut extra = fixed_extra;
    extra.extend(
        count_tables
            .iter()
            .filter_map(|s| budget_dwell(b, s.len(), lo)),
    );
    found.evaluate_grid(dwell_grid(
        lo,
        b.max_dwell_s,
        &extra,
        b.params.dwells_per_decade,
    ))?;
    phases.step("dwell grid", &tally);
    let searched = found.searched_dwells(&run, &fixed_dwells);
    let jobs = found.noise_jobs(&run, &searched, &count_tables);
    found.add_noise_searches(&run, jobs)?;
    phases.step("noise-aware searches", &tally);
    if b.search_counts {
        found.refine_counts(&run)?;
    }
    phases.step("count refinement", &tally);
    let design = found.finish(&run);
    phases.step("front", &tally);
    design
}

/// The checked inputs of a budget design: the shortest dwell, one sample (a relative 1e-9
/// above, against rounding; at most the longest dwell).
///
/// # Errors
/// As [`design_with_budget`]'s checks of `budget_s`, `max_dwell_s`, `sample_rate_hz`,
/// `move_s`, `k_sigma` and [`check_budget_affords`].
fn checked_shortest_dwell(problem: &DesignProblem, b: &TimeBudget<'_>) -> Result<f64, E2eError> {
    tt_core::positive("budget_s", b.budget_s)?;
    tt_core::positive("max_dwell_s", b.max_dwell_s)?;
    let rate = tt_core::positive("sample_rate_hz", b.sample_rate_hz)?;
    if !(b.move_s >= 0.0 && b.move_s.is_finite()) {
        return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
            field: "move_s".into(),
            value: b.move_s,
            range: "[0, inf) s".into(),
        }));
    }
    e2e_verify::check_k_sigma(b.k_sigma)?;
    check_budget_affords(problem, b)?;
    Ok((1.0 / rate * (1.0 + 1e-9)).min(b.max_dwell_s))
}

/// What every step of a budget design reads: the problem, the budget, the condition bound,
/// the shortest dwell, the table design's and the study's counts.
struct Run<'a> {
    problem: &'a DesignProblem,
    b: &'a TimeBudget<'a>,
    max_condition: f64,
    lo: f64,
    n: usize,
    n_study: usize,
    /// The work counted.
    tally: &'a Tally,
}

impl<'a> Run<'a> {
    /// The end-to-end simulator and linearisation of `positions` (the study's rate steps
    /// after them).
    fn evaluator(&self, positions: &[Vec<f64>]) -> Result<Evaluator<'a>, E2eError> {
        let e2e = self
            .problem
            .end_to_end_with_rate_steps(positions, self.b.rate_steps)?;
        let linear = e2e.linearization();
        self.tally.evaluator();
        Ok(Evaluator {
            e2e,
            linear,
            lower_bounds_rad: &self.problem.lower_bounds_rad,
            budget: self.b,
            tally: self.tally,
        })
    }

    /// A table design of `c` positions: the greedy construction and the exchange (`None`: the
    /// condition bound is not met).
    fn design_count(&self, c: usize) -> Result<Option<Vec<usize>>, E2eError> {
        let start = match self.problem.greedy(c, self.max_condition) {
            Ok(e) => e,
            Err(E2eError::NoConvergence { .. }) => return Ok(None),
            Err(e) => return Err(e),
        };
        match self.problem.exchange(&start.schedule, self.max_condition) {
            Ok(e) => {
                self.tally.exchange(&e);
                Ok(Some(e.evaluation.schedule))
            }
            Err(E2eError::ConditionUnreachable { .. }) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// The noise-aware search from `s` at dwell `t`: the schedules of the fixed point's steps.
    fn noise_search(&self, t: f64, mut s: Vec<usize>) -> Result<Vec<Vec<usize>>, E2eError> {
        let mut out = Vec::new();
        for _ in 0..self.b.params.fixed_point_steps {
            let ev = self.evaluator(&self.problem.positions_deg(&s))?;
            let margins = ev.noise(t)?.margins(self.b.k_sigma);
            let Some(reduced) = self.problem.with_margins(&margins) else {
                break;
            };
            let next = match reduced.exchange(&s, self.max_condition) {
                Ok(e) => {
                    self.tally.exchange(&e);
                    e.evaluation.schedule
                }
                Err(E2eError::ConditionUnreachable { .. }) => break,
                Err(e) => return Err(e),
            };
            if next == s {
                break;
            }
            out.push(next.clone());
            s = next;
        }
        Ok(out)
    }

    /// The dwell that spends the whole budget on `c` positions ([`budget_dwell`]).
    fn budget_dwell(&self, c: usize) -> Option<f64> {
        budget_dwell(self.b, c, self.lo)
    }
}

/// Whether two schedules (joint angles, deg) hold the same positions, in any order.
fn same_positions(a: &[Vec<f64>], b: &[Vec<f64>]) -> bool {
    let (mut a, mut b) = (a.to_vec(), b.to_vec());
    let key = |x: &Vec<f64>, y: &Vec<f64>| {
        x.iter()
            .zip(y)
            .map(|(p, q)| p.total_cmp(q))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    };
    a.sort_by(key);
    b.sort_by(key);
    a == b
}

/// The budget design's state: every schedule found with its evaluator (built once) and its
/// $J$ at every dwell of the grid, the schedules known as candidate indices, and the counts.
struct Found<'a> {
    schedules: Vec<(ScheduleOrigin, Vec<Vec<f64>>)>,
    evaluators: Vec<Evaluator<'a>>,
    /// $J$ per schedule per dwell (rad$^{-2}$; `+inf` when no table suffices).
    objectives: Vec<Vec<f64>>,
    dwells: Vec<f64>,
    known: Vec<Vec<usize>>,
    counts_done: Vec<usize>,
    counts_skipped: Vec<usize>,
    counts_refined: Vec<usize>,
}

impl<'a> Found<'a> {
    /// The table design, then the study's schedule and `others` unless the same positions
    /// are already there; their evaluators (in parallel; order kept). No dwell yet.
    fn start(
        run: &Run<'a>,
        table: &[usize],
        study: Option<&[usize]>,
        study_positions_deg: &[Vec<f64>],
        others: &[(ScheduleOrigin, Vec<usize>)],
    ) -> Result<Self, E2eError> {
        let problem = run.problem;
        let mut schedules: Vec<(ScheduleOrigin, Vec<Vec<f64>>)> =
            vec![(ScheduleOrigin::Table, problem.positions_deg(table))];
        for (origin, positions) in
            std::iter::once((ScheduleOrigin::Study, study_positions_deg.to_vec()))
                .chain(others.iter().map(|(o, s)| (*o, problem.positions_deg(s))))
        {
            if !schedules.iter().any(|(_, q)| same_positions(q, &positions)) {
                schedules.push((origin, positions));
            }
        }
        let mut known: Vec<Vec<usize>> = vec![table.to_vec()];
        if let Some(s) = study.filter(|s| s.len() == run.n) {
            known.push(s.to_vec());
        }
        known.extend(others.iter().map(|(_, s)| s.clone()));
        let evaluators = schedules
            .par_iter()
            .map(|(_, s)| run.evaluator(s))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            schedules,
            evaluators,
            objectives: Vec::new(),
            dwells: Vec::new(),
            known,
            counts_done: vec![run.n],
            counts_skipped: Vec::new(),
            counts_refined: Vec::new(),
        })
    }

    /// Add `positions` from `origin` with its evaluator and its $J$ at every dwell of the
    /// grid, unless the same positions are there already.
    fn push(
        &mut self,
        run: &Run<'a>,
        origin: ScheduleOrigin,
        positions: Vec<Vec<f64>>,
    ) -> Result<(), E2eError> {
        if self
            .schedules
            .iter()
            .any(|(_, q)| same_positions(q, &positions))
        {
            return Ok(());
        }
        self.push_evaluated(run, origin, positions)
    }

    /// Add `positions` from `origin` with its evaluator and its $J$ at every dwell of the
    /// grid (the caller has checked that it is new).
    fn push_evaluated(
        &mut self,
        run: &Run<'a>,
        origin: ScheduleOrigin,
        positions: Vec<Vec<f64>>,
    ) -> Result<(), E2eError> {
        let ev = run.evaluator(&positions)?;
        let js = self
            .dwells
            .iter()
            .map(|&t| ev.objective(t))
            .collect::<Result<_, _>>()?;
        self.schedules.push((origin, positions));
        self.evaluators.push(ev);
        self.objectives.push(js);
        Ok(())
    }

    /// The other counts' table designs (in parallel; order kept), each added as a schedule
    /// from the table and known; the designs returned (before any dwell is evaluated).
    fn design_counts(&mut self, run: &Run<'a>) -> Result<Vec<Vec<usize>>, E2eError> {
        let counts = if run.b.search_counts {
            budget_counts(run.problem, run.b, run.n, run.n_study)
        } else {
            Vec::new()
        };
        let designs: Vec<Option<Vec<usize>>> = counts
            .par_iter()
            .map(|&c| run.design_count(c))
            .collect::<Result<_, E2eError>>()?;
        let mut tables = Vec::new();
        for (&c, design) in counts.iter().zip(designs) {
            match design {
                Some(s) => {
                    self.counts_done.push(c);
                    self.push(run, ScheduleOrigin::Table, run.problem.positions_deg(&s))?;
                    tables.push(s);
                }
                None => self.counts_skipped.push(c),
            }
        }
        self.counts_done.sort_unstable();
        self.known.extend(tables.iter().cloned());
        Ok(tables)
    }

    /// $J$ of every schedule at every dwell of `dwells` (in parallel over the schedules).
    fn evaluate_grid(&mut self, dwells: Vec<f64>) -> Result<(), E2eError> {
        self.objectives = self
            .evaluators
            .par_iter()
            .map(|ev| dwells.iter().map(|&t| ev.objective(t)).collect())
            .collect::<Result<_, _>>()?;
        self.dwells = dwells;
        Ok(())
    }

    /// A new dwell `t` of the grid, evaluated for every schedule (nothing if it is there).
    fn insert_dwell(&mut self, t: f64) -> Result<(), E2eError> {
        if let Err(at) = self.dwells.binary_search_by(|x| x.total_cmp(&t)) {
            self.dwells.insert(at, t);
            let column: Vec<f64> = self
                .evaluators
                .par_iter()
                .map(|ev| ev.objective(t))
                .collect::<Result<_, _>>()?;
            for (row, j) in self.objectives.iter_mut().zip(column) {
                row.insert(at, j);
            }
        }
        Ok(())
    }

    /// The index of dwell `t` in the grid (bit for bit).
    fn dwell_index(&self, t: f64) -> Option<usize> {
        self.dwells.iter().position(|&x| x.to_bits() == t.to_bits())
    }

    /// The searched dwells (indices into the grid): the budget's own for the designed count,
    /// then spread over the fixed-count design's dwells where a schedule of the designed size
    /// leaves the table room.
    fn searched_dwells(&self, run: &Run<'_>, fixed_dwells: &[f64]) -> Vec<usize> {
        let same_size = self.same_size(run);
        let open: Vec<usize> = (0..self.dwells.len())
            .filter(|&d| {
                fixed_dwells
                    .iter()
                    .any(|t| t.to_bits() == self.dwells[d].to_bits())
                    && same_size.iter().any(|&i| self.objectives[i][d].is_finite())
            })
            .collect();
        let mut searched: Vec<usize> = Vec::new();
        if let Some(d) = run.budget_dwell(run.n).and_then(|t| self.dwell_index(t)) {
            searched.push(d);
        }
        let spread = run.b.params.search_dwells.saturating_sub(searched.len());
        for i in 0..spread {
            if open.is_empty() {
                break;
            }
            let f = if spread > 1 {
                i as f64 / (spread - 1) as f64
            } else {
                0.0
            };
            let d = open[(f * (open.len() - 1) as f64).round() as usize];
            if !searched.contains(&d) {
                searched.push(d);
            }
        }
        searched
    }

    /// The schedules of the designed size (indices).
    fn same_size(&self, run: &Run<'_>) -> Vec<usize> {
        (0..self.schedules.len())
            .filter(|&i| self.schedules[i].1.len() == run.n)
            .collect()
    }

    /// The noise-aware searches to run, (dwell index, start): every schedule of the designed
    /// size that leaves the table room at a searched dwell starts one there, and every other
    /// count's table design one at the dwell that spends the budget on it.
    fn noise_jobs(
        &self,
        run: &Run<'_>,
        searched: &[usize],
        count_tables: &[Vec<usize>],
    ) -> Vec<(usize, Vec<usize>)> {
        let index_of = |positions: &[Vec<f64>]| -> Option<Vec<usize>> {
            positions.iter().map(|p| run.problem.index_of(p)).collect()
        };
        let same_size = self.same_size(run);
        let mut jobs: Vec<(usize, Vec<usize>)> = Vec::new();
        for &d in searched {
            for &i in &same_size {
                if self.objectives[i][d].is_finite() {
                    if let Some(s) = index_of(&self.schedules[i].1) {
                        jobs.push((d, s));
                    }
                }
            }
        }
        for s in count_tables {
            let positions = run.problem.positions_deg(s);
            let Some(i) = self
                .schedules
                .iter()
                .position(|(_, q)| same_positions(q, &positions))
            else {
                continue;
            };
            if let Some(d) = run.budget_dwell(s.len()).and_then(|t| self.dwell_index(t)) {
                if self.objectives[i][d].is_finite() {
                    jobs.push((d, s.clone()));
                }
            }
        }
        jobs
    }

    /// Run `jobs` (in parallel; order kept) and add the schedules they find that are not
    /// known, with their origin's dwell, evaluated at every dwell (in parallel).
    fn add_noise_searches(
        &mut self,
        run: &Run<'a>,
        jobs: Vec<(usize, Vec<usize>)>,
    ) -> Result<(), E2eError> {
        let found: Vec<(usize, Vec<Vec<usize>>)> = jobs
            .into_par_iter()
            .map(|(d, s)| Ok((d, run.noise_search(self.dwells[d], s)?)))
            .collect::<Result<_, E2eError>>()?;
        let mut new: Vec<(ScheduleOrigin, Vec<Vec<f64>>)> = Vec::new();
        for (d, list) in found {
            for s in list {
                if !is_known(&self.known, &s) {
                    self.known.push(s.clone());
                    new.push((
                        ScheduleOrigin::Noise(self.dwells[d]),
                        run.problem.positions_deg(&s),
                    ));
                }
            }
        }
        let dwells = &self.dwells;
        let more: Vec<(Evaluator<'a>, Vec<f64>)> = new
            .par_iter()
            .map(|(_, s)| {
                let ev = run.evaluator(s)?;
                let js = dwells
                    .iter()
                    .map(|&t| ev.objective(t))
                    .collect::<Result<_, E2eError>>()?;
                Ok((ev, js))
            })
            .collect::<Result<_, E2eError>>()?;
        for (s, (ev, js)) in new.into_iter().zip(more) {
            self.schedules.push(s);
            self.evaluators.push(ev);
            self.objectives.push(js);
        }
        Ok(())
    }

    /// The refinement of the count: bisection between the best count at the budget and its
    /// tried neighbours, at most [`BudgetParams::count_refinements`] designs; each refined
    /// count's table design and noise-aware search run in parallel, then join in order.
    fn refine_counts(&mut self, run: &Run<'a>) -> Result<(), E2eError> {
        let b = run.b;
        let n_min = fewest_proposed(run.problem, b);
        let top = count_limit(run.problem, b, run.n, run.n_study);
        while self.counts_refined.len() < b.params.count_refinements {
            let mut tried: Vec<usize> = self
                .counts_done
                .iter()
                .chain(&self.counts_skipped)
                .copied()
                .collect();
            tried.sort_unstable();
            tried.dedup();
            let Some(best) = best_count(&self.schedules, &self.objectives, &self.dwells, b) else {
                break;
            };
            let below = tried.iter().rev().find(|&&c| c < best).copied();
            let above = tried.iter().find(|&&c| c > best).copied();
            let mut mids: Vec<usize> = below
                .map(|l| l + (best - l) / 2)
                .into_iter()
                .chain(above.map(|u| best + (u - best).div_ceil(2)))
                .filter(|c| !tried.contains(c) && *c >= n_min && *c <= top)
                .collect();
            mids.dedup();
            mids.truncate(b.params.count_refinements - self.counts_refined.len());
            if mids.is_empty() {
                break;
            }
            // each count's design and its noise-aware search at its budget dwell
            type Refined = Option<(Vec<usize>, Vec<Vec<usize>>)>;
            let designs: Vec<Refined> = mids
                .par_iter()
                .map(|&c| -> Result<Refined, E2eError> {
                    let Some(sched) = run.design_count(c)? else {
                        return Ok(None);
                    };
                    let searched = match run.budget_dwell(c) {
                        Some(t) => run.noise_search(t, sched.clone())?,
                        None => Vec::new(),
                    };
                    Ok(Some((sched, searched)))
                })
                .collect::<Result<_, _>>()?;
            for (&c, design) in mids.iter().zip(designs) {
                self.counts_refined.push(c);
                let Some((sched, searched)) = design else {
                    self.counts_skipped.push(c);
                    continue;
                };
                self.counts_done.push(c);
                // its budget dwell joins the grid, evaluated for every schedule
                let t = run.budget_dwell(c);
                if let Some(t) = t {
                    self.insert_dwell(t)?;
                }
                let added = std::iter::once((ScheduleOrigin::Table, sched)).chain(
                    t.into_iter().flat_map(|t| {
                        searched
                            .iter()
                            .map(move |s| (ScheduleOrigin::Noise(t), s.clone()))
                    }),
                );
                for (origin, s) in added.collect::<Vec<_>>() {
                    if is_known(&self.known, &s) {
                        continue;
                    }
                    self.known.push(s.clone());
                    self.push_evaluated(run, origin, run.problem.positions_deg(&s))?;
                }
            }
        }
        self.counts_done.sort_unstable();
        self.counts_skipped.sort_unstable();
        Ok(())
    }

    /// The front over every schedule at every dwell of the grid and the study's, the table's
    /// and the baselines' schedules at their own trade-off dwells, each front point with its
    /// tolerance box; the choice (the front's last point within the budget).
    fn finish(self, run: &Run<'a>) -> Result<BudgetDesign, E2eError> {
        let b = run.b;
        let fewest = fewest_proposed(run.problem, b);
        // fewer positions than the redundancy asks: not proposed (the study's own is kept)
        let proposed =
            |o: ScheduleOrigin, s: &[Vec<f64>]| s.len() >= fewest || o == ScheduleOrigin::Study;
        let mut points = Vec::new();
        for ((origin, s), js) in self.schedules.iter().zip(&self.objectives) {
            if !proposed(*origin, s) {
                continue;
            }
            for (&t, &j) in self.dwells.iter().zip(js) {
                if j.is_finite() {
                    points.push(BudgetPoint::new(
                        *origin,
                        s.clone(),
                        t,
                        b.test_s(s.len(), t),
                        j,
                    ));
                }
            }
        }
        // the study's, the table's and the baselines' schedules also at their own trade-off
        // dwells (the points end-to-end lists for them)
        let listed: Vec<Vec<BudgetPoint>> = self
            .schedules
            .par_iter()
            .zip(self.evaluators.par_iter())
            .filter(|((o, s), _)| !matches!(o, ScheduleOrigin::Noise(_)) && proposed(*o, s))
            .map(|((o, s), ev)| ev.tradeoff_points(*o, s, run.lo, &self.dwells))
            .collect::<Result<_, _>>()?;
        points.extend(listed.into_iter().flatten());
        let mut pareto = pareto_front(&points);
        // every front point's tolerance box (the allocation whose J it is)
        pareto.par_iter_mut().try_for_each(|p| {
            let i = self
                .schedules
                .iter()
                .position(|(_, q)| q == &p.positions_deg)
                .expect("a front point's schedule is among those evaluated");
            if let Some(d) = self.evaluators[i].allocation(p.dwell_s)? {
                p.tolerances_rad = d.upper_bounds_rad().to_vec();
            }
            Ok::<(), E2eError>(())
        })?;
        // the front holds the cheapest table for every total time: the last point within the
        // budget is the choice
        let chosen = pareto
            .iter()
            .take_while(|p| p.total_s <= b.budget_s)
            .last()
            .cloned();
        Ok(BudgetDesign {
            budget_s: b.budget_s,
            k_sigma: b.k_sigma,
            evaluated: self.schedules.len() * self.dwells.len(),
            dwells_s: self.dwells,
            schedules: self.schedules,
            pareto,
            chosen,
            counts: self.counts_done,
            counts_skipped: self.counts_skipped,
            counts_refined: self.counts_refined,
        })
    }
}

/// The count of the best point within the budget (least $J$, then the fewer positions) over
/// the evaluated schedules and dwells; `None` when no table suffices within the budget.
fn best_count(
    schedules: &[(ScheduleOrigin, Vec<Vec<f64>>)],
    objectives: &[Vec<f64>],
    dwells: &[f64],
    b: &TimeBudget<'_>,
) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for ((_, s), js) in schedules.iter().zip(objectives) {
        for (&t, &j) in dwells.iter().zip(js) {
            if j.is_finite()
                && b.test_s(s.len(), t) <= b.budget_s
                && best.is_none_or(|(bj, bc)| {
                    j.total_cmp(&bj).then(s.len().cmp(&bc)) == std::cmp::Ordering::Less
                })
            {
                best = Some((j, s.len()));
            }
        }
    }
    best.map(|(_, c)| c)
}

/// Whether schedule `s` (candidate indices) is among `known`, compared as sets of positions
/// (the search keeps one visiting order of each set).
fn is_known(known: &[Vec<usize>], s: &[usize]) -> bool {
    let mut sorted = s.to_vec();
    sorted.sort_unstable();
    known.iter().any(|k| {
        let mut k = k.clone();
        k.sort_unstable();
        k == sorted
    })
}

#[cfg(test)]
pub(crate) mod noise_search_tests;
