//! Allocation against every output's calibration accuracy itself: direct (the worst case of
//! $\Delta\omega_k$ over the box within $\omega_{m,k}$ at every position) and yield-based (a
//! chosen fraction of the turntables in the box meet every accuracy).

use crate::budget::SpecificationRow;
use crate::error::{E2eError, fraction};
use crate::linear::Linearization;
use crate::montecarlo::{McSettings, YieldCount, wilson_interval_95};
use crate::simulate::EndToEnd;
use crate::specified_yield::{SpecCheck, SpecifiedCount};
use alloc_opt::solver::{Cut, FiniteCuts, InverseSquareProblem, solve_inverse_square};
use alloc_opt::{TIGHT_REL, Weights};
use mc_verify::ErrorBox;
use tt_core::units::objective_to_arcmin;
use tt_core::units::rad_to_arcmin;
use tt_kinematics::{ScheduleErrorModel, Turntable};

/// Tuning of the certified direct allocation ([`EndToEnd::allocate_direct_certified_with`]):
/// a parameter struct with [`Default`] (faer's convention), so a caller changes one knob
/// without the others: `let mut p = CertifyParams::default(); p.steps = 60;`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CertifyParams {
    /// Golden-section steps over the $\ell_1$ budget (default 40: relative resolution
    /// $0.618^{40} \approx 4\cdot10^{-9}$ of the log range).
    pub steps: usize,
    /// Bisection steps for the largest $\ell_1$ budget whose second-order bound is admissible
    /// (default 50: relative resolution $2^{-50}$).
    pub bisection_steps: usize,
    /// Largest share of an accuracy kept free for the second-order terms (dimensionless,
    /// default 0.9): a bound that needs more is reported as not certifiable.
    pub max_margin: f64,
    /// Share of every accuracy kept free besides the second-order bound (dimensionless,
    /// default $10^{-12}$): room for the round trip of the tolerances through a decimal sheet
    /// (written at full precision and read back, a bound moves by a few ulp, about
    /// $10^{-16}$), so that a sheet of the certified tolerances is still proven by
    /// `check-turntable`.
    pub round_trip_rel: f64,
}

impl Default for CertifyParams {
    fn default() -> Self {
        Self {
            steps: 40,
            bisection_steps: 50,
            max_margin: 0.9,
            round_trip_rel: 1e-12,
        }
    }
}

/// Tuning of the yield-based allocation ([`EndToEnd::allocate_yield_with`]), with
/// [`Default`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct YieldParams {
    /// Bisection steps in $\log s$ on the scale (default 40: from a bracket of ratio 2,
    /// $\ln 2 / 2^{40} \approx 6\cdot10^{-13}$ relative).
    pub bisection_steps: usize,
    /// Maximum fixed-point steps of the scale when $\mathrm{LB} = 0$ (default 8; each one an
    /// exact-quantile Monte Carlo; two or three reach $10^{-12}$).
    pub fixed_point_steps: usize,
    /// Maximum doublings of the upper end of the scale's bracket, and of shrink steps when
    /// the fixed point's rounding leaves the boundary draw on the wrong side (default 60).
    pub bracket_steps: usize,
    /// Relative margin taken off the fixed-point scale so that the draw at the quantile lands
    /// on the safe side of the accuracy despite rounding (dimensionless, default $10^{-9}$).
    pub scale_margin: f64,
    /// The scale search stops when every finite bound of the shape reaches this (rad, default
    /// $\pi$, half a turn: a larger bound describes no other rotation). Meeting the target
    /// there means the accuracies do not constrain the table ([`YieldAllocation::capped`]).
    pub scale_cap_rad: f64,
    /// The log-scale bisection stops when the bracket's ratio is within this of 1
    /// (dimensionless, default $10^{-12}$).
    pub scale_rel: f64,
}

impl Default for YieldParams {
    fn default() -> Self {
        Self {
            bisection_steps: 40,
            fixed_point_steps: 8,
            bracket_steps: 60,
            scale_margin: 1e-9,
            scale_cap_rad: std::f64::consts::PI,
            scale_rel: 1e-12,
        }
    }
}

/// What every output says when no error affects any output to first order
/// ([`DirectAllocation::no_bound_needed`]).
pub const NO_BOUND_NEEDED: &str = "no error affects any output to first order (the calibration absorbs every error): no bound is needed for any error";

/// The default yield target: 99.73% (the $3\sigma$ fraction of a normal law).
pub const DEFAULT_YIELD_FRACTION: f64 = 0.9973;

/// The fewest Monte Carlo draws that can demonstrate a yield `target` at 95% confidence: with
/// $n$ draws none of which fails, the lower end of the 95% Wilson interval
/// ([`wilson_interval_95`]) is $n/(n + z^2)$, which reaches the target $p$ only for
/// $$n \ge \frac{z^2\,p}{1 - p},\qquad z = 1.96.$$
/// Fewer draws cannot tell a yield of $p$ from a smaller one whatever they show (1419 for
/// 99.73%, 35 for 90%). A `target` outside $(0, 1)$ gives 1.
#[must_use]
pub fn min_yield_samples(target: f64) -> u64 {
    if !(target > 0.0 && target < 1.0) {
        return 1;
    }
    let z2 = crate::montecarlo::Z_95 * crate::montecarlo::Z_95;
    let mut n = (z2 * target / (1.0 - target)).ceil().max(1.0) as u64;
    // the closed form up to rounding: the interval itself decides
    while n > 1 && wilson_interval_95(n - 1, n - 1).0 >= target {
        n -= 1;
    }
    while wilson_interval_95(n, n).0 < target {
        n += 1;
    }
    n
}

/// Whether a yield measured with a 95% interval reaches its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum YieldVerdict {
    /// The whole interval is at or above the target.
    Meets,
    /// The whole interval is below the target.
    DoesNotMeet,
    /// The interval contains the target: the draws cannot tell.
    CannotTell,
}

impl YieldVerdict {
    /// The verdict for a 95% interval `(lo, hi)` of the yield against `target`.
    #[must_use]
    pub fn of(interval_95: (f64, f64), target: f64) -> Self {
        if interval_95.0 >= target {
            YieldVerdict::Meets
        } else if interval_95.1 < target {
            YieldVerdict::DoesNotMeet
        } else {
            YieldVerdict::CannotTell
        }
    }

    /// `meets`, `does not meet` or `cannot tell`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            YieldVerdict::Meets => "meets",
            YieldVerdict::DoesNotMeet => "does not meet",
            YieldVerdict::CannotTell => "cannot tell",
        }
    }
}

/// Refuse a draw count that cannot resolve `target` ([`min_yield_samples`]).
pub(crate) fn check_yield_samples(samples: u64, target: f64) -> Result<(), E2eError> {
    let needed = min_yield_samples(target);
    if samples < needed {
        return Err(E2eError::TooFewSamples {
            samples,
            needed,
            target,
        });
    }
    Ok(())
}

/// One row (output, position) of the direct allocation's constraints.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RowLoad {
    /// The output's index.
    pub(crate) output: usize,
    /// Position index in the schedule.
    pub(crate) position: usize,
    /// $\sum_j |M_{rj}|\,\mathrm{UB}_j / \omega_{m,k}$ (1 = the whole accuracy used).
    pub(crate) load: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RowLoad {
    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }

    /// Position index in the schedule.
    #[must_use]
    pub fn position(&self) -> usize {
        self.position
    }

    /// $\sum_j |M_{rj}|\,\mathrm{UB}_j / \omega_{m,k}$ (1 = the whole accuracy used).
    #[must_use]
    pub fn load(&self) -> f64 {
        self.load
    }
}

/// One specification row of the direct allocation ([`crate::budget::SpecificationRow`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SpecLoad {
    /// The specification's index.
    pub(crate) spec: usize,
    /// Its label (`gx bg_x (bias)`) and unit.
    pub(crate) label: String,
    /// The row's table part over what the noise leaves, $\sum_j f_j|c_j|\mathrm{UB}_j /
    /// (L - k\,u_{\text{noise}})$ (1 = all of it used).
    pub(crate) load: f64,
}

/// Read access to the fields.
impl SpecLoad {
    /// The specification's index.
    #[must_use]
    pub fn spec(&self) -> usize {
        self.spec
    }
    /// Its label.
    #[must_use]
    pub fn label(&self) -> &str {
        &self.label
    }
    /// The row's table part over what the noise leaves (1 = all of it used).
    #[must_use]
    pub fn load(&self) -> f64 {
        self.load
    }
}

/// The direct allocation's result.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DirectAllocation {
    /// $\mathrm{UB}$ (rad, order of $\chi$); `+inf` for an error no output depends on.
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// The errors no output depends on (no bound).
    pub(crate) unconstrained: Vec<usize>,
    /// The lower bounds used (rad).
    pub(crate) lower_bounds_rad: Vec<f64>,
    /// Every output's accuracy $\omega_{m,k}$ (output unit).
    pub(crate) accuracies: Vec<f64>,
    /// $J$ (rad$^{-2}$), see [`EndToEnd::objective`].
    pub(crate) objective: f64,
    /// The load of every row, output-major.
    pub(crate) loads: Vec<RowLoad>,
    /// Sum of the Lagrange multipliers of the rows (units of $J$).
    pub(crate) multiplier: f64,
    /// Conic solves of the exchange method.
    pub(crate) iterations: usize,
    /// Room kept for the exact chain's second-order terms per output (output unit): the rows
    /// are constrained to $\omega_{m,k} - $ this (0 for [`EndToEnd::allocate_direct`]; the
    /// derived bound $\tau_k$ for [`EndToEnd::allocate_direct_certified`]).
    pub(crate) second_order_margins: Vec<f64>,
    /// The load of every specification row ([`EndToEnd::allocate_direct_specified`]; empty
    /// without specifications).
    pub(crate) spec_loads: Vec<SpecLoad>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl DirectAllocation {
    /// The load of every specification row ([`EndToEnd::allocate_direct_specified`]; empty
    /// without specifications), in the rows' order.
    #[must_use]
    pub fn spec_loads(&self) -> &[SpecLoad] {
        &self.spec_loads
    }

    /// The specifications whose rows bound the allocation (load $\ge 1 -$ [`TIGHT_REL`]),
    /// each label once, in the specifications' order.
    #[must_use]
    pub fn limited_by(&self) -> Vec<&str> {
        let mut out: Vec<(usize, &str)> = self
            .spec_loads
            .iter()
            .filter(|l| l.load >= 1.0 - TIGHT_REL)
            .map(|l| (l.spec, l.label.as_str()))
            .collect();
        out.sort_by_key(|l| l.0);
        out.dedup_by_key(|l| l.0);
        out.into_iter().map(|l| l.1).collect()
    }

    /// $\mathrm{UB}$ (rad, order of $\chi$); `+inf` for an error no output depends on.
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// The errors no output depends on (no bound).
    #[must_use]
    pub fn unconstrained(&self) -> &[usize] {
        &self.unconstrained
    }

    /// The lower bounds used (rad).
    #[must_use]
    pub fn lower_bounds_rad(&self) -> &[f64] {
        &self.lower_bounds_rad
    }

    /// Every output's accuracy $\omega_{m,k}$ (output unit).
    #[must_use]
    pub fn accuracies(&self) -> &[f64] {
        &self.accuracies
    }

    /// $J$ (rad$^{-2}$), see [`EndToEnd::objective`].
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The load of every row, output-major.
    #[must_use]
    pub fn loads(&self) -> &[RowLoad] {
        &self.loads
    }

    /// Sum of the Lagrange multipliers of the rows (units of $J$).
    #[must_use]
    pub fn multiplier(&self) -> f64 {
        self.multiplier
    }

    /// Conic solves of the exchange method.
    #[must_use]
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Room kept for the exact chain's second-order terms per output (output unit): the rows
    /// are constrained to $\omega_{m,k} - $ this (0 for [`EndToEnd::allocate_direct`]; the
    /// derived bound $\tau_k$ for [`EndToEnd::allocate_direct_certified`]).
    #[must_use]
    pub fn second_order_margins(&self) -> &[f64] {
        &self.second_order_margins
    }
}

impl DirectAllocation {
    /// $\mathrm{UB}$ in arcminutes.
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> Vec<f64> {
        self.upper_bounds_rad
            .iter()
            .map(|&u| rad_to_arcmin(u))
            .collect()
    }

    /// $J$ in arcmin$^{-2}$.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        objective_to_arcmin(self.objective)
    }

    /// Whether no error affects any output to first order (every bound infinite): the
    /// calibration absorbs every error, and no bound is needed for any
    /// ([`NO_BOUND_NEEDED`]).
    #[must_use]
    pub fn no_bound_needed(&self) -> bool {
        self.upper_bounds_rad.iter().all(|u| u.is_infinite())
    }

    /// The active rows: load $\ge 1 -$ [`TIGHT_REL`].
    #[must_use]
    pub fn active_rows(&self) -> Vec<RowLoad> {
        self.loads
            .iter()
            .copied()
            .filter(|r| r.load >= 1.0 - TIGHT_REL)
            .collect()
    }
}

/// The yield-based allocation's result.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct YieldAllocation {
    /// $\mathrm{UB} = s^*\,\mathrm{UB}_{shape}$ (rad).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// The shape (rad): the direct allocation's bounds.
    pub(crate) shape_rad: Vec<f64>,
    /// The scale $s^*$.
    pub(crate) scale: f64,
    /// The target fraction $p$.
    pub(crate) target: f64,
    /// $J$ (rad$^{-2}$).
    pub(crate) objective: f64,
    /// The design draws and those meeting every accuracy (and, with specifications
    /// ([`EndToEnd::allocate_yield_specified`]), every specification, each counted too) at
    /// $s^*$ (re-evaluated on the exact chain), with their seed; its 95% Wilson interval is
    /// the stated confidence of the allocation.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) counted: SpecifiedCount,
    /// The target is met even at the largest scale searched, [`YieldParams::scale_cap_rad`] on every
    /// finite bound (or the shape has no finite bound): the accuracies do not constrain these
    /// errors, and the bounds are that cap, not a limit.
    pub(crate) capped: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl YieldAllocation {
    /// $\mathrm{UB} = s^*\,\mathrm{UB}_{shape}$ (rad).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// The shape (rad): the direct allocation's bounds.
    #[must_use]
    pub fn shape_rad(&self) -> &[f64] {
        &self.shape_rad
    }

    /// The scale $s^*$.
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The target fraction $p$.
    #[must_use]
    pub fn target(&self) -> f64 {
        self.target
    }

    /// $J$ (rad$^{-2}$).
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The design draws and those meeting every accuracy (and, with specifications, every
    /// specification, with the draws meeting each: [`SpecifiedCount::per_specification`]) at
    /// $s^*$ (re-evaluated on the exact chain), with their seed; its 95% Wilson interval
    /// ([`YieldCount::interval_95`]) is the stated confidence of the allocation, and
    /// [`SpecifiedCount::counts`] says what it counts.
    #[must_use]
    pub fn counted(&self) -> &SpecifiedCount {
        &self.counted
    }

    /// The target is met even at the largest scale searched, [`YieldParams::scale_cap_rad`] on every
    /// finite bound (or the shape has no finite bound): the accuracies do not constrain these
    /// errors, and the bounds are that cap, not a limit.
    #[must_use]
    pub fn capped(&self) -> bool {
        self.capped
    }
}

impl YieldAllocation {
    /// $\mathrm{UB}$ in arcminutes.
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> Vec<f64> {
        self.upper_bounds_rad
            .iter()
            .map(|&u| rad_to_arcmin(u))
            .collect()
    }

    /// $J$ in arcmin$^{-2}$.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        objective_to_arcmin(self.objective)
    }

    /// The design draws' 95% interval against the target.
    #[must_use]
    pub fn design_verdict(&self) -> YieldVerdict {
        YieldVerdict::of(self.counted.count.interval_95(), self.target)
    }
}

/// The rows no other row dominates. Row $a$ (coefficients $\mathbf c_a \ge 0$, bound $b_a$)
/// is implied by row $b$ when $\mathbf c_a/b_a \le \mathbf c_b/b_b$ component-wise: every
/// box meeting $b$ meets $a$. Symmetric schedules repeat rows (the same row at opposite
/// positions), and the conic solver is better conditioned without the copies; the optimum is
/// unchanged. Of equal rows the first is kept.
fn undominated(rows: Vec<Cut>) -> Vec<Cut> {
    let scaled: Vec<Vec<f64>> = rows
        .iter()
        .map(|c| c.coefficients.iter().map(|a| a / c.bound).collect())
        .collect();
    let dominates = |b: usize, a: usize| scaled[a].iter().zip(&scaled[b]).all(|(x, y)| x <= y);
    rows.iter()
        .enumerate()
        .filter(|&(a, _)| {
            !(0..rows.len()).any(|b| b != a && dominates(b, a) && (!dominates(a, b) || b < a))
        })
        .map(|(_, c)| c.clone())
        .collect()
}

impl<S: ScheduleErrorModel + Sync> EndToEnd<S> {
    /// The paper's combined weights $w_j = \sqrt{\sum_k W_{kj}^2}$ with
    /// $W_{kj} = 1/\overline{|\partial f_k/\partial\chi_j|}$ (eq 28, Figure 8) of this turntable:
    /// then $\sum_j w_j^2/\mathrm{UB}_j^2$ equals alloc-opt's $J = J_\psi + J_\theta + J_\gamma$,
    /// so an error that appears in two angles counts twice, exactly as in the two-step
    /// allocation, and the objectives are comparable.
    ///
    /// A model that is not a turntable has no pose-domain linear model: its weights are those
    /// of its own end-to-end linearisation ($W_{kj}$ over its outputs $k$ instead of the three
    /// angles, averaged over the schedule's positions).
    #[must_use]
    pub fn combined_weights(&self) -> Vec<f64> {
        match self.model().as_turntable_schedule() {
            Some(t) => {
                // the schedule's own model: its average sensitivities are computed once
                Weights::inverse_average_sensitivity(t.linear_model()).combined()
            }
            None => Weights::inverse_average_sensitivity(&self.linearization()).combined(),
        }
    }

    /// $J(\mathrm{UB}) = \sum_j w_j^2/\mathrm{UB}_j^2$ with [`EndToEnd::combined_weights`]
    /// (rad$^{-2}$ for bounds in radians; infinite bounds count 0).
    #[must_use]
    pub fn objective(&self, ub_rad: &[f64]) -> f64 {
        objective_with(&self.combined_weights(), ub_rad)
    }

    fn check_lower_bounds(&self, lower_bounds_rad: &[f64]) -> Result<(), E2eError> {
        check_lower_bounds_named(self.error_names(), lower_bounds_rad)
    }

    /// [`EndToEnd::allocate_direct_keeping`] with the objective's weights `weights` (one per
    /// column of `linear`) in place of the combined weights (the paired allocation,
    /// [`crate::disc`], merges a pair's weights into one column), with `l1_budget_rad` (see
    /// [`DirectSetup::allocate`]) and the specification rows `spec_rows`.
    pub(crate) fn allocate_direct_weighted(
        &self,
        weights: &[f64],
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
        l1_budget_rad: Option<f64>,
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        let accuracies = self.accuracies();
        let names: Vec<&str> = self
            .calibration()
            .outputs()
            .iter()
            .map(|o| o.output().name.as_str())
            .collect();
        DirectSetup {
            error_names: &self.error_names(),
            weights,
            accuracies: &accuracies,
            output_names: &names,
        }
        .allocate_with_rows(linear, lower_bounds_rad, margins, l1_budget_rad, spec_rows)
    }

    /// Direct allocation against every output's accuracy, keeping `margins[k]` (output unit)
    /// of each accuracy free (the noise part of
    /// [`crate::NoiseQuestions::allocate_direct_with_noise`]).
    pub(crate) fn allocate_direct_keeping(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
    ) -> Result<DirectAllocation, E2eError> {
        let weights = self.combined_weights();
        self.allocate_direct_weighted(&weights, linear, lower_bounds_rad, margins, None, &[])
    }

    /// Direct allocation against every output's accuracy.
    ///
    /// # Formula
    /// $$\min_{\mathrm{UB}} \sum_j \frac{w_j^2}{\mathrm{UB}_j^2}\quad\text{s.t.}\quad
    /// \sum_j |M_{rj}|\,\mathrm{UB}_j \le \omega_{m,k}\ \ \forall r = (k, i),
    /// \qquad \mathrm{UB} \ge \mathrm{LB},$$
    /// with the paper's weights ([`EndToEnd::combined_weights`]) and the linearised errors
    /// $\mathbf M$: one linear constraint per output and position with non-negative
    /// coefficients, solved by alloc-opt's power-cone core ([`solve_inverse_square`] with
    /// [`FiniteCuts`]). Errors no output depends on get no bound.
    ///
    /// # Reference
    /// The objective of problems (31)-(33) (eq 28 weights) with the requirement of eq 14 in
    /// place of eq 15; an extension of the paper.
    ///
    /// # Errors
    /// [`E2eError::Bounds`] for bad lower bounds; [`E2eError::InfeasibleLowerBounds`] naming
    /// the output and the row; [`E2eError::Alloc`] if the solver fails.
    pub fn allocate_direct(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
    ) -> Result<DirectAllocation, E2eError> {
        self.allocate_direct_keeping(linear, lower_bounds_rad, &vec![0.0; self.n_outputs()])
    }

    /// [`EndToEnd::allocate_direct`] constrained by every specification as well: the rows
    /// `spec_rows` ([`crate::BudgetQuestions::specification_rows`]) beside the eq-14 rows, each
    /// $\sum_j f_j|c_j|\,\mathrm{UB}_j \le L - k\,u_{\text{noise}}$, so that the table's
    /// worst case plus the noise part, and the verdict's expanded uncertainty
    /// ([`crate::BudgetQuestions::plan_verdict`]), are within every limit to first order. Without rows it is
    /// [`EndToEnd::allocate_direct`], bit for bit.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct`]; [`E2eError::NoTableSuffices`] naming a specification
    /// whose noise part alone fills its limit.
    pub fn allocate_direct_specified(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        self.allocate_direct_specified_weighted(
            &self.combined_weights(),
            linear,
            lower_bounds_rad,
            spec_rows,
        )
    }

    /// [`EndToEnd::allocate_direct_specified`] with the objective's weights `weights` given
    /// (one per error): a caller that answers many schedules of one turntable passes
    /// [`EndToEnd::combined_weights`] computed once (they depend on the turntable alone, and
    /// their average over the joint ranges is the costly part of a schedule's answer); with
    /// those weights it is [`EndToEnd::allocate_direct_specified`], bit for bit.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct_specified`]; [`E2eError::Field`] when `weights` does
    /// not have one value per error.
    pub fn allocate_direct_specified_weighted(
        &self,
        weights: &[f64],
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        let n_errors = self.error_names().len();
        if weights.len() != n_errors {
            return Err(E2eError::Field(tt_core::FieldError::Length {
                field: "weights".into(),
                expected: n_errors,
                found: weights.len(),
            }));
        }
        self.allocate_direct_weighted(
            weights,
            linear,
            lower_bounds_rad,
            &vec![0.0; self.n_outputs()],
            None,
            spec_rows,
        )
    }

    /// [`EndToEnd::allocate_direct_certified`] constrained by every specification as well:
    /// the certified search with `spec_rows` beside the eq-14 rows, then each specified
    /// quantity evaluated on the exact chain ([`EndToEnd::coefficient_errors`], and
    /// [`EndToEnd::error_vectors`] for eq 14's error at a position) at the box's vertex of each
    /// row's sign pattern and its opposite; where one exceeds $L - k\,u_{\text{noise}}$ the
    /// finite bounds are scaled down together by bisection ([`CertifyParams::bisection_steps`])
    /// to the largest scale at which every one is within. Without rows it is
    /// [`EndToEnd::allocate_direct_certified`].
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct_certified`] and
    /// [`EndToEnd::allocate_direct_specified`].
    pub fn allocate_direct_certified_specified(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        let params = CertifyParams::default();
        let weights = self.combined_weights();
        let zeros = vec![0.0; self.n_outputs()];
        let d = self.certified_weighted(
            &weights,
            linear,
            lower_bounds_rad,
            &zeros,
            &params,
            spec_rows,
        )?;
        if spec_rows.is_empty() {
            return Ok(d);
        }
        self.shrink_to_exact(d, &weights, linear, lower_bounds_rad, spec_rows, &params)
    }

    /// `d` with its finite bounds scaled down together (never below the lower bounds) to the
    /// largest scale at which every specification row's quantity on the exact chain, at the
    /// row's worst vertex and its opposite, is within $L - k\,u_{\text{noise}}$ (less
    /// [`CertifyParams::round_trip_rel`] of $L$); loads and objective recomputed.
    fn shrink_to_exact(
        &self,
        mut d: DirectAllocation,
        weights: &[f64],
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        spec_rows: &[SpecificationRow],
        params: &CertifyParams,
    ) -> Result<DirectAllocation, E2eError> {
        let offsets = self.coefficient_offsets();
        let scaled = |s: f64| -> Vec<f64> {
            d.upper_bounds_rad
                .iter()
                .zip(lower_bounds_rad)
                .map(|(u, l)| if u.is_finite() { (s * u).max(*l) } else { *u })
                .collect()
        };
        let within = |ub: &[f64]| -> Result<bool, E2eError> {
            for r in spec_rows {
                let room = r.room() - params.round_trip_rel * r.limit();
                let chi = r.vertex(ub);
                for sign in [1.0, -1.0] {
                    let chi: Vec<f64> = chi.iter().map(|c| sign * c).collect();
                    let coefficients = self.coefficient_errors(&chi)?;
                    let errors = self.error_vectors(&chi)?;
                    if r.exact(&coefficients, &offsets, &errors).abs() > room {
                        return Ok(false);
                    }
                }
            }
            Ok(true)
        };
        if within(&d.upper_bounds_rad)? {
            return Ok(d);
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..params.bisection_steps {
            let mid = 0.5 * (lo + hi);
            if within(&scaled(mid))? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if !within(&scaled(lo))? {
            return Err(E2eError::NoConvergence {
                what: "certified direct allocation (the lower bounds alone exceed a specification on the exact chain)",
                iterations: params.bisection_steps,
                change: lo,
            });
        }
        let ub = scaled(lo);
        let n = linear.positions();
        let acc = self.accuracies();
        for (load, v) in d.loads.iter_mut().zip(linear.row_worst_cases(&ub).iter()) {
            load.load = v / acc[load.output];
        }
        debug_assert!(d.loads.iter().all(|l| l.position < n));
        for (load, r) in d.spec_loads.iter_mut().zip(spec_rows) {
            load.load = r.value(&ub) / r.room();
        }
        d.objective = objective_with(weights, &ub);
        d.upper_bounds_rad = ub;
        Ok(d)
    }

    /// Direct allocation certified on the exact chain: the cheapest allocation found whose
    /// linearised worst case plus the derived second-order bound is within every accuracy
    /// (less [`CertifyParams::round_trip_rel`] of it), so that every turntable of the box meets every
    /// accuracy on the exact chain, not only to first order.
    ///
    /// # Method
    /// The bound $\tau_k(s)$ ([`EndToEnd::second_order_bound`]) depends on the box through
    /// $s = \sum_j \mathrm{UB}_j$ only and grows with it. For an $\ell_1$ budget $S$ the
    /// allocation with rows held to $\omega_{m,k} - \tau_k(S)$ and the extra row
    /// $\sum_j \mathrm{UB}_j \le S$ is certified by construction; its cost $J(S)$ is searched
    /// over $S$ by golden section in $\log S$ ([`CertifyParams::steps`] solves) on
    /// $[S_{hi}\,10^{-4}, S_{hi}]$, $S_{hi}$ the smaller of the plain allocation's $\ell_1$ size
    /// and the largest $S$ with $\tau_k(S) \le$ [`CertifyParams::max_margin`]$\,\omega_{m,k}$. The
    /// budget matters where the first-order error is small and the second-order one is not
    /// (accelerometers, which absorb most of a rotation, see the IMU example); for the paper's
    /// study it is inactive and the result is the plain allocation with $\tau$ kept free.
    /// $J(S)$ is a guarantee of the returned box, not a proof that no cheaper certified box
    /// exists (the search is one-dimensional).
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct`]; [`E2eError::NoSecondOrderBound`] when the reading has
    /// no derived bound; [`E2eError::NoConvergence`] when no budget in the range certifies.
    pub fn allocate_direct_certified(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
    ) -> Result<DirectAllocation, E2eError> {
        self.allocate_direct_certified_with(linear, lower_bounds_rad, &CertifyParams::default())
    }

    /// [`EndToEnd::allocate_direct_certified`] with its search tuned by `params`.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_direct_certified`].
    pub fn allocate_direct_certified_with(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        params: &CertifyParams,
    ) -> Result<DirectAllocation, E2eError> {
        self.certified_keeping(
            linear,
            lower_bounds_rad,
            &vec![0.0; self.n_outputs()],
            params,
        )
    }

    /// [`EndToEnd::allocate_direct_certified_with`] keeping `extra[k]` (output unit) of each
    /// accuracy free besides the second-order bound (the noise part of
    /// [`crate::NoiseQuestions::allocate_direct_with_noise`] with `certify`): every turntable
    /// of the returned box has an exact-chain error within $\omega_{m,k} - \mathrm{extra}_k$.
    pub(crate) fn certified_keeping(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        extra: &[f64],
        params: &CertifyParams,
    ) -> Result<DirectAllocation, E2eError> {
        let weights = self.combined_weights();
        self.certified_weighted(&weights, linear, lower_bounds_rad, extra, params, &[])
    }

    /// [`EndToEnd::certified_keeping`] with the objective's weights `weights` (see
    /// [`EndToEnd::allocate_direct_weighted`]). The second-order bound is taken at the
    /// $\ell_1$ size of the returned bounds, so a column standing for several errors must be
    /// scaled by the caller to make its bound the largest sum of their magnitudes.
    pub(crate) fn certified_weighted(
        &self,
        weights: &[f64],
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        extra: &[f64],
        params: &CertifyParams,
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        let acc = self.accuracies();
        let n = self.len();
        // the rotation angles of a box with l1 size S sum to at most gain * S (the model's
        // angle-sum bound is a gauge, so its largest value on the l1 ball is at a vertex; a
        // turntable's is the l1 norm itself, gain 1)
        let gain = self.angle_sum_gain()?;
        let taus = |s: f64| -> Result<Vec<f64>, E2eError> {
            (0..self.n_outputs())
                .map(|k| {
                    self.second_order_bound(k, gain * s)?.ok_or_else(|| {
                        E2eError::NoSecondOrderBound {
                            reading: self.reading().to_string(),
                        }
                    })
                })
                .collect()
        };
        let plain = self.allocate_direct_weighted(
            weights,
            linear,
            lower_bounds_rad,
            extra,
            None,
            spec_rows,
        )?;
        let l1 = |ub: &[f64]| -> f64 { ub.iter().filter(|u| u.is_finite()).sum() };
        let admissible = |t: &[f64]| t.iter().zip(&acc).all(|(t, a)| *t <= params.max_margin * a);
        let mut s_hi = l1(&plain.upper_bounds_rad);
        if !admissible(&taus(s_hi)?) {
            // largest admissible budget by bisection (tau grows with s)
            let (mut lo, mut hi) = (0.0, s_hi);
            for _ in 0..params.bisection_steps {
                let mid = 0.5 * (lo + hi);
                if admissible(&taus(mid)?) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            s_hi = lo;
        }
        let s_lb: f64 = lower_bounds_rad
            .iter()
            .zip(&plain.upper_bounds_rad)
            .filter(|(_, u)| u.is_finite())
            .map(|(l, _)| l)
            .sum();
        let s_lo = (s_hi * 1e-4).max(s_lb * (1.0 + 1e-9));
        if s_hi.partial_cmp(&s_lo) != Some(std::cmp::Ordering::Greater) {
            return Err(E2eError::NoConvergence {
                what: "certified direct allocation (no l1 budget leaves room for the second-order bound)",
                iterations: 0,
                change: s_hi,
            });
        }
        let room = |k: usize| acc[k] * (1.0 - params.round_trip_rel) - extra[k];
        let certified = |d: &DirectAllocation| -> Result<bool, E2eError> {
            let tau = taus(l1(&d.upper_bounds_rad))?;
            let rows = linear.row_worst_cases(&d.upper_bounds_rad);
            Ok((0..acc.len()).all(|k| rows.rows(k * n, n).max() + tau[k] <= room(k)))
        };
        let solve = |s: f64| -> Result<Option<DirectAllocation>, E2eError> {
            let margins: Vec<f64> = taus(s)?
                .iter()
                .zip(&acc)
                .zip(extra)
                .map(|((t, a), e)| t + a * params.round_trip_rel + e)
                .collect();
            if margins.iter().zip(&acc).any(|(t, a)| t >= a) {
                return Ok(None);
            }
            match self.allocate_direct_weighted(
                weights,
                linear,
                lower_bounds_rad,
                &margins,
                Some(s),
                spec_rows,
            ) {
                Ok(d) if certified(&d)? => Ok(Some(d)),
                Ok(_) | Err(E2eError::InfeasibleLowerBounds { .. } | E2eError::Alloc(_)) => {
                    Ok(None)
                }
                Err(e) => Err(e),
            }
        };
        let cost = |d: &Option<DirectAllocation>| d.as_ref().map_or(f64::INFINITY, |d| d.objective);
        // golden section on log S
        let phi = 0.5 * (5.0_f64.sqrt() - 1.0);
        let (mut a, mut b) = (s_lo.ln(), s_hi.ln());
        let mut best: Option<DirectAllocation> = solve(s_hi)?;
        let mut c = b - phi * (b - a);
        let mut d = a + phi * (b - a);
        let mut fc = solve(c.exp())?;
        let mut fd = solve(d.exp())?;
        for _ in 0..params.steps {
            if cost(&fc) <= cost(&fd) {
                b = d;
                d = c;
                fd = fc.take();
                c = b - phi * (b - a);
                fc = solve(c.exp())?;
            } else {
                a = c;
                c = d;
                fc = fd.take();
                d = a + phi * (b - a);
                fd = solve(d.exp())?;
            }
            for cand in [&fc, &fd] {
                if cost(cand) < cost(&best) {
                    best.clone_from(cand);
                }
            }
        }
        best.ok_or(E2eError::NoConvergence {
            what: "certified direct allocation (no l1 budget certifies)",
            iterations: params.steps,
            change: s_hi,
        })
    }

    /// $\max_j$ of the model's angle-sum bound at the unit box $\mathbf e_j$
    /// ([`ScheduleErrorModel::angle_sum_bound`]): the rotation angles of any box with
    /// $\sum_j \mathrm{UB}_j \le S$ sum to at most this times $S$ (1 for a turntable).
    ///
    /// # Errors
    /// [`E2eError::NoSecondOrderBound`] when the model gives no angle-sum bound (or a
    /// non-finite or negative one).
    fn angle_sum_gain(&self) -> Result<f64, E2eError> {
        let none = || E2eError::NoSecondOrderBound {
            reading: format!(
                "{} (the table model gives no angle-sum bound)",
                self.reading()
            ),
        };
        let mut unit = vec![0.0; self.n_errors()];
        let mut gain = 0.0_f64;
        for j in 0..unit.len() {
            unit[j] = 1.0;
            let g = self.model().angle_sum_bound(&unit).ok_or_else(none)?;
            unit[j] = 0.0;
            if !(g.is_finite() && g >= 0.0) {
                return Err(none());
            }
            gain = gain.max(g);
        }
        Ok(gain)
    }

    /// The Monte Carlo box of upper bounds `ub_rad` (rad) and lower bounds: errors without a
    /// bound (`+inf`, no output depends on them to first order) are held at their lower bound.
    ///
    /// # Errors
    /// [`E2eError::Bounds`] naming the error of an invalid pair.
    pub fn box_of(&self, ub_rad: &[f64], lower_bounds_rad: &[f64]) -> Result<ErrorBox, E2eError> {
        let ub: Vec<f64> = ub_rad
            .iter()
            .zip(lower_bounds_rad)
            .map(|(u, l)| if u.is_finite() { *u } else { *l })
            .collect();
        Ok(ErrorBox::with_names(
            self.error_names(),
            lower_bounds_rad.to_vec(),
            ub,
        )?)
    }

    /// Yield-based allocation: keep the shape $\mathrm{UB}_{shape}$ (e.g. the direct
    /// allocation) and take the largest scale $s^*$ at which at least a fraction `target` of
    /// the design draws meet every accuracy.
    ///
    /// # Formula
    /// With $\mathrm{LB} = 0$ the box scales with $s$ and the draws of a stream scale with it
    /// ($\chi(s) = s\,\chi(1)$ for the same random words), and the errors are homogeneous of
    /// degree 1 in $\chi$ to first order, so $s^* = 1 / q_p$ where $q_p$ is the exact empirical
    /// $p$-quantile ([`crate::MonteCarloQuestions::ratio_quantile`]) of $r = \max_k \Delta\omega_k/\omega_{m,k}$ at
    /// $s = 1$ on the exact chain; the chain's curvature is absorbed by iterating
    /// $s \leftarrow s / q_p(s)$ (at most [`YieldParams::fixed_point_steps`]) and taking
    /// [`YieldParams::scale_margin`] off. When that does not settle (rounding dominates the quantile
    /// at tiny accuracies, the chain's curvature at huge ones), and with positive lower bounds,
    /// the scale is bracketed in factors of 2 and bisected in $\log s$
    /// ([`YieldParams::bisection_steps`], to [`YieldParams::scale_rel`]) on the count of draws meeting every
    /// accuracy, with common random numbers (same seed at every $s$), on
    /// $s \in [\max_j \mathrm{LB}_j/\mathrm{UB}_{shape,j}, s_{cap}]$: nothing depends on the
    /// absolute scale of the accuracies. $s_{cap}$ brings every finite bound to
    /// [`YieldParams::scale_cap_rad`]; a target met there (or a shape without a finite bound, when no
    /// error affects an output to first order) is reported as [`YieldAllocation::capped`]. The
    /// yield at $s^*$ is
    /// re-evaluated on the design draws and stated with its 95% Wilson interval.
    ///
    /// # Errors
    /// [`E2eError::Field`] (out of range) naming `yield_fraction`; [`E2eError::TooFewSamples`]
    /// when the draws cannot resolve the target ([`min_yield_samples`]); [`E2eError::Field`] (not positive)
    /// naming `shape.<error>`; [`E2eError::Bounds`]; [`E2eError::YieldUnreachable`] when no
    /// scale meets the target; as [`McSettings::validate`].
    pub fn allocate_yield(
        &self,
        shape_rad: &[f64],
        lower_bounds_rad: &[f64],
        target: f64,
        settings: &McSettings,
    ) -> Result<YieldAllocation, E2eError> {
        self.allocate_yield_with(
            shape_rad,
            lower_bounds_rad,
            target,
            settings,
            &YieldParams::default(),
        )
    }

    /// [`EndToEnd::allocate_yield`] with its scale search tuned by `params`.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_yield`].
    pub fn allocate_yield_with(
        &self,
        shape_rad: &[f64],
        lower_bounds_rad: &[f64],
        target: f64,
        settings: &McSettings,
        params: &YieldParams,
    ) -> Result<YieldAllocation, E2eError> {
        self.allocate_yield_specified(shape_rad, lower_bounds_rad, target, settings, params, &[])
    }

    /// [`EndToEnd::allocate_yield_with`] counting the specifications too: a draw meets when
    /// every accuracy holds and every row of `spec_rows` holds in the direct allocation's
    /// convention ([`SpecificationRow`]: the quantity's table part on the exact chain within
    /// $L - k\,u_{\text{noise}}$), so the yield is the fraction of draws meeting every accuracy
    /// and every specification ([`crate::SPECIFIED_YIELD_COUNTS`]); the scale search is the same, on
    /// the ratio $\max(\max_k \Delta\omega_k/\omega_{m,k}, \max_{\text{rows}}
    /// |q|/(L - k\,u_{\text{noise}}))$. [`YieldAllocation::counted`] gives the
    /// design draws meeting each specification. Without rows it is
    /// [`EndToEnd::allocate_yield_with`], bit for bit.
    ///
    /// # Errors
    /// As [`EndToEnd::allocate_yield`]; [`E2eError::NoTableSuffices`] naming a specification
    /// whose noise part fills its limit; [`E2eError::Draw`] naming a draw whose specified
    /// quantity cannot be computed.
    pub fn allocate_yield_specified(
        &self,
        shape_rad: &[f64],
        lower_bounds_rad: &[f64],
        target: f64,
        settings: &McSettings,
        params: &YieldParams,
        spec_rows: &[SpecificationRow],
    ) -> Result<YieldAllocation, E2eError> {
        let p = fraction("yield_fraction", target)?;
        settings.validate()?;
        check_yield_samples(settings.samples, p)?;
        self.check_lower_bounds(lower_bounds_rad)?;
        check_spec_rows(spec_rows, lower_bounds_rad)?;
        for (name, v) in self.error_names().iter().zip(shape_rad) {
            if v.is_nan() || *v <= 0.0 {
                return Err(tt_core::FieldError::NotPositive {
                    field: format!("shape.{name}"),
                    value: *v,
                }
                .into());
            }
        }
        // s >= max LB/UB_shape whenever it is called, so s u >= LB up to rounding: made exact
        let scaled = |s: f64| -> Vec<f64> {
            shape_rad
                .iter()
                .zip(lower_bounds_rad)
                .map(|(u, l)| (s * u).max(*l))
                .collect()
        };
        let check = (!spec_rows.is_empty()).then(|| SpecCheck::new(self, spec_rows));
        let count = |s: f64| -> Result<u64, E2eError> {
            let b = self.box_of(&scaled(s), lower_bounds_rad)?;
            match &check {
                None => self.monte_carlo().meeting_count(&b, settings),
                Some(c) => Ok(c.count(&b, settings)?.count.meeting()),
            }
        };
        let quantile = |s: f64| -> Result<f64, E2eError> {
            let b = self.box_of(&scaled(s), lower_bounds_rad)?;
            match &check {
                None => self.monte_carlo().ratio_quantile(&b, settings, p),
                Some(c) => c.ratio_quantile(&b, settings, p),
            }
        };
        let need = (p * settings.samples as f64).ceil() as u64;
        let goal = YieldGoal {
            target: p,
            need,
            samples: settings.samples,
        };
        let finite: Vec<f64> = shape_rad
            .iter()
            .copied()
            .filter(|u| u.is_finite())
            .collect();
        // the scale at which every finite bound reaches the cap (no finite bound: the box does
        // not depend on the scale, and 1 is as good as any)
        let s_cap = finite
            .iter()
            .map(|u| params.scale_cap_rad / u)
            .fold(1.0_f64, f64::max);
        let (scale, capped) = if finite.is_empty() {
            let best = count(1.0)?;
            if best < need {
                return Err(E2eError::YieldUnreachable {
                    target: p,
                    best: best as f64 / settings.samples as f64,
                });
            }
            (1.0, true)
        } else if lower_bounds_rad.iter().all(|&l| l == 0.0) {
            match yield_fixed_point(&count, &quantile, &goal, s_cap, params)? {
                Some(s) => (s, false),
                // the fixed point did not settle (rounding at tiny accuracies, the exact
                // chain's curvature at huge ones): bracket and bisect on the count instead
                None => bisect_scale(&count, &goal, 0.0, 1.0, s_cap, params)?,
            }
        } else {
            let s_lo = lower_bounds_rad
                .iter()
                .zip(shape_rad)
                .map(|(l, u)| if u.is_finite() { l / u } else { 0.0 })
                .fold(0.0, f64::max);
            bisect_scale(&count, &goal, s_lo, s_lo.max(1.0), s_cap.max(s_lo), params)?
        };
        let ub = scaled(scale);
        let (meeting, per_specification) = match &check {
            None => (count(scale)?, Vec::new()),
            Some(c) => {
                let found = c.count(&self.box_of(&ub, lower_bounds_rad)?, settings)?;
                (found.count.meeting(), found.per_specification)
            }
        };
        Ok(YieldAllocation {
            objective: self.objective(&ub),
            upper_bounds_rad: ub,
            shape_rad: shape_rad.to_vec(),
            scale: Self::check_positive("yield scale", scale)?,
            target: p,
            counted: SpecifiedCount {
                count: YieldCount::new(settings.samples, settings.seed, meeting, Vec::new()),
                per_specification,
            },
            capped,
        })
    }
}

/// The scale of the yield-based allocation with $\mathrm{LB} = 0$ by the fixed point
/// $s \leftarrow s/q_p(s)$ (see [`EndToEnd::allocate_yield`]; `quantile(s)` is $q_p(s)$, `count(s)`
/// the draws meeting at $s$), [`YieldParams::scale_margin`] taken off and checked on the count;
/// `None` when it does not settle to $10^{-6}$ in [`YieldParams::fixed_point_steps`], leaves
/// $(0, s_{cap}]$, or the margin does not restore the count (the caller then bisects).
fn yield_fixed_point(
    count: &dyn Fn(f64) -> Result<u64, E2eError>,
    quantile: &dyn Fn(f64) -> Result<f64, E2eError>,
    goal: &YieldGoal,
    s_cap: f64,
    params: &YieldParams,
) -> Result<Option<f64>, E2eError> {
    let need = goal.need;
    let mut s = 1.0;
    let mut change = f64::INFINITY;
    for _ in 0..params.fixed_point_steps {
        let q = quantile(s)?;
        let next = s / q;
        if !(next.is_finite() && next > 0.0 && next <= s_cap) {
            return Ok(None);
        }
        change = (next / s - 1.0).abs();
        s = next;
        if change < 1e-12 {
            break;
        }
    }
    if change > 1e-6 {
        return Ok(None);
    }
    let mut s = s * (1.0 - params.scale_margin);
    let mut steps = 0;
    while count(s)? < need {
        s *= 1.0 - 1e3 * params.scale_margin;
        steps += 1;
        if steps >= params.bracket_steps {
            return Ok(None);
        }
    }
    Ok(Some(s))
}

/// What the yield scale must reach: a fraction `target` of `samples` draws, i.e. `need` of
/// them.
#[derive(Debug, Clone, Copy)]
struct YieldGoal {
    target: f64,
    need: u64,
    samples: u64,
}

/// The largest scale found at which `count` reaches `goal.need`, by bracketing from `start` (in
/// factors of 2, no lower than `s_min`, no higher than `s_cap`) and bisection in $\log s$ to
/// [`YieldParams::scale_rel`]: independent of the absolute scale. Returns `(s_cap, true)` when the
/// cap itself meets the target.
///
/// # Errors
/// [`E2eError::YieldUnreachable`] when no scale down to `s_min` (or $2^{-60}$ of the start)
/// meets it; as `count`.
fn bisect_scale(
    count: &dyn Fn(f64) -> Result<u64, E2eError>,
    goal: &YieldGoal,
    s_min: f64,
    start: f64,
    s_cap: f64,
    params: &YieldParams,
) -> Result<(f64, bool), E2eError> {
    let YieldGoal {
        target,
        need,
        samples,
    } = *goal;
    let unreachable = |best: u64| E2eError::YieldUnreachable {
        target,
        best: best as f64 / samples as f64,
    };
    let start = start.clamp(s_min, s_cap);
    let (mut lo, mut hi);
    if count(start)? >= need {
        lo = start;
        hi = start;
        loop {
            if hi >= s_cap {
                return Ok((s_cap, true));
            }
            hi = (2.0 * hi).min(s_cap);
            if count(hi)? < need {
                break;
            }
            lo = hi;
        }
    } else {
        hi = start;
        lo = start;
        let mut steps = 0;
        loop {
            lo = (0.5 * lo).max(s_min);
            let c = count(lo)?;
            if c >= need {
                break;
            }
            steps += 1;
            if lo <= s_min || steps >= params.bracket_steps {
                return Err(unreachable(c));
            }
            hi = lo;
        }
    }
    for _ in 0..params.bisection_steps {
        if hi / lo - 1.0 <= params.scale_rel {
            break;
        }
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
        if count(mid)? >= need {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok((lo, false))
}

/// The certified direct allocation of `sim` ([`EndToEnd::allocate_direct_certified`]), or why
/// there is none (the reading has no derived bound, the second-order margin exceeds an
/// output's accuracy, or the search did not certify): the answer of `end-to-end` and of the
/// schedule designer, in the same words.
///
/// # Errors
/// The allocation's other errors (bad lower bounds, solver failure).
pub fn certified_or_note(
    sim: &EndToEnd,
    linear: &Linearization,
    lower_bounds_rad: &[f64],
    plain: &DirectAllocation,
) -> Result<(Option<DirectAllocation>, Option<String>), E2eError> {
    certified_or_note_specified(sim, linear, lower_bounds_rad, plain, &[])
}

/// [`certified_or_note`] with the specification rows `spec_rows`
/// ([`EndToEnd::allocate_direct_certified_specified`]).
///
/// # Errors
/// As [`certified_or_note`].
pub fn certified_or_note_specified(
    sim: &EndToEnd,
    linear: &Linearization,
    lower_bounds_rad: &[f64],
    plain: &DirectAllocation,
    spec_rows: &[SpecificationRow],
) -> Result<(Option<DirectAllocation>, Option<String>), E2eError> {
    if plain.no_bound_needed() {
        return Ok((None, Some(E2eError::NoBoxToCertify.to_string())));
    }
    if sim.has_rate_steps() {
        return Ok((
            None,
            Some(crate::rate::NOT_CERTIFIED_AT_RATE_STEPS.to_string()),
        ));
    }
    match sim.allocate_direct_certified_specified(linear, lower_bounds_rad, spec_rows) {
        Ok(d) => Ok((Some(d), None)),
        // not certifiable for this reading, table and sensor: say why, keep the rest
        Err(E2eError::MarginExceedsAccuracy { output, value }) => Ok((
            None,
            Some(format!(
                "the derived second-order bound exceeds an output's accuracy (accuracy of output {output} minus its second-order margin is {value:.3}): the bound is too coarse for this turntable and sensor"
            )),
        )),
        Err(e @ (E2eError::NoSecondOrderBound { .. } | E2eError::NoConvergence { .. })) => {
            Ok((None, Some(e.to_string())))
        }
        Err(e) => Err(e),
    }
}

/// Check lower bounds: one per angular error of `turntable`, finite and non-negative.
pub fn check_lower_bounds(turntable: &Turntable, lower_bounds_rad: &[f64]) -> Result<(), E2eError> {
    check_lower_bounds_named(
        turntable
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect(),
        lower_bounds_rad,
    )
}

/// Check lower bounds: one per error named in `names`, finite and non-negative.
pub(crate) fn check_lower_bounds_named(
    names: Vec<String>,
    lower_bounds_rad: &[f64],
) -> Result<(), E2eError> {
    ErrorBox::with_names(
        names,
        lower_bounds_rad.to_vec(),
        lower_bounds_rad.iter().map(|v| v.max(0.0)).collect(),
    )?;
    Ok(())
}

/// $J(\mathrm{UB}) = \sum_j w_j^2/\mathrm{UB}_j^2$ (infinite bounds count 0).
pub(crate) fn objective_with(weights: &[f64], ub_rad: &[f64]) -> f64 {
    // a fold from +0 (an empty float sum is -0, which prints as "-0.00")
    weights
        .iter()
        .zip(ub_rad)
        .filter(|(_, u)| u.is_finite())
        .map(|(w, u)| (w / u).powi(2))
        .fold(0.0, |a, b| a + b)
}

/// What the direct allocation needs besides $\mathbf M$: the errors' names (lower-bound
/// checks, messages), the combined weights and every output's accuracy and name. Shared by
/// [`EndToEnd::allocate_direct`] and the schedule designer (the `schedule-design` crate), so both give
/// the same $J$ for the same $\mathbf M$.
pub struct DirectSetup<'a> {
    /// The errors' names, one per column of $\mathbf M$.
    pub error_names: &'a [String],
    /// The objective's weights $w_j$, one per column.
    pub weights: &'a [f64],
    /// Every output's accuracy $\omega_{m,k}$ (output unit).
    pub accuracies: &'a [f64],
    /// Every output's name.
    pub output_names: &'a [&'a str],
}

impl DirectSetup<'_> {
    /// `d` with the bound of each error `j` of `ceilings` (`(j, c)`) above `c` lowered to
    /// `c`, its loads and objective recomputed over `linear`: a tighter bound keeps every row
    /// within its accuracy, so the box still meets what it met (the others keep their
    /// bounds: the capped error's unused share of the accuracies is left free).
    pub(crate) fn capped(
        &self,
        mut d: DirectAllocation,
        ceilings: &[(usize, f64)],
        linear: &Linearization,
    ) -> DirectAllocation {
        let mut changed = false;
        for &(j, c) in ceilings {
            if d.upper_bounds_rad[j] > c {
                d.upper_bounds_rad[j] = c.max(d.lower_bounds_rad[j]);
                changed = true;
            }
        }
        if changed {
            let n = linear.positions();
            let acc = self.accuracies;
            for (load, v) in d
                .loads
                .iter_mut()
                .zip(linear.row_worst_cases(&d.upper_bounds_rad).iter())
            {
                load.load = v / acc[load.output];
            }
            debug_assert!(d.loads.iter().all(|l| l.position < n));
            d.objective = objective_with(self.weights, &d.upper_bounds_rad);
        }
        d
    }

    /// Every output's accuracy less its margin is positive, and the lower bounds alone keep
    /// every row within it.
    ///
    /// # Errors
    /// [`E2eError::MarginExceedsAccuracy`] or [`E2eError::InfeasibleLowerBounds`] naming the
    /// output (and position).
    fn check_room(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
    ) -> Result<(), E2eError> {
        let n = linear.positions();
        let acc = self.accuracies;
        let bound = |k: usize| acc[k] - margins[k];
        for (k, _) in acc.iter().enumerate() {
            if bound(k) <= 0.0 {
                return Err(E2eError::MarginExceedsAccuracy {
                    output: self.output_names[k].to_string(),
                    value: bound(k),
                });
            }
        }
        let lb_rows = linear.row_worst_cases(lower_bounds_rad);
        for (r, v) in lb_rows.iter().enumerate() {
            let k = r / n;
            if *v > bound(k) {
                return Err(E2eError::InfeasibleLowerBounds {
                    output: self.output_names[k].to_string(),
                    position: r % n,
                    worst: *v,
                    accuracy: acc[k],
                });
            }
        }
        Ok(())
    }

    /// The direct allocation's cuts over the errors `free`: every accuracy row within its
    /// accuracy less its margin (tag: the row), every specification row within its room
    /// (tag: -2 - its index), dominated cuts dropped; then, with `l1_budget_rad`, the sum of
    /// the bounds within it (tag -1).
    fn cuts(
        &self,
        linear: &Linearization,
        free: &[usize],
        margins: &[f64],
        spec_rows: &[SpecificationRow],
        spec_coefficients: &[Vec<f64>],
        l1_budget_rad: Option<f64>,
    ) -> Vec<Cut> {
        let n = linear.positions();
        let bound = |k: usize| self.accuracies[k] - margins[k];
        let rows: Vec<Cut> = linear
            .matrix()
            .row_iter()
            .enumerate()
            .map(|(r, row)| Cut {
                coefficients: free.iter().map(|&j| row[j].abs()).collect(),
                bound: bound(r / n),
                tag: r as f64,
            })
            .chain(
                spec_rows
                    .iter()
                    .zip(spec_coefficients)
                    .enumerate()
                    .map(|(i, (r, c))| Cut {
                        coefficients: free.iter().map(|&j| c[j]).collect(),
                        bound: r.room(),
                        tag: -2.0 - i as f64,
                    }),
            )
            .collect();
        let mut rows = undominated(rows);
        if let Some(budget) = l1_budget_rad {
            // sum_j UB_j <= budget (rad): the l1 size the second-order bound was taken at
            rows.push(Cut {
                coefficients: vec![1.0; free.len()],
                bound: budget,
                tag: -1.0,
            });
        }
        rows
    }

    /// Direct allocation against every output's accuracy, keeping `margins[k]` (output unit)
    /// of each accuracy free and, with `l1_budget_rad`, $\sum_j \mathrm{UB}_j$ within it (see
    /// [`EndToEnd::allocate_direct`] and [`EndToEnd::allocate_direct_certified`]).
    pub fn allocate(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
        l1_budget_rad: Option<f64>,
    ) -> Result<DirectAllocation, E2eError> {
        self.allocate_with_rows(linear, lower_bounds_rad, margins, l1_budget_rad, &[])
    }

    /// [`DirectSetup::allocate`] with the specification rows `spec_rows` beside the accuracy
    /// rows: $\sum_j f_j|c_j|\,\mathrm{UB}_j \le L - k\,u_{\text{noise}}$ each
    /// ([`SpecificationRow`]).
    ///
    /// # Errors
    /// As [`DirectSetup::allocate`]; [`E2eError::NoTableSuffices`] naming the first
    /// specification whose noise part fills its limit; [`E2eError::InfeasibleLowerBounds`]
    /// naming a specification the lower bounds alone exceed.
    pub(crate) fn allocate_with_rows(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
        l1_budget_rad: Option<f64>,
        spec_rows: &[SpecificationRow],
    ) -> Result<DirectAllocation, E2eError> {
        check_spec_rows(spec_rows, lower_bounds_rad)?;
        let spec_coefficients: Vec<Vec<f64>> = spec_rows
            .iter()
            .map(SpecificationRow::coefficients)
            .collect();
        let spec_loads = |ub: &[f64]| -> Vec<SpecLoad> {
            spec_rows
                .iter()
                .map(|r| SpecLoad {
                    spec: r.spec(),
                    label: format!("{} in {}", r.label(), r.unit()),
                    load: r.value(ub) / r.room(),
                })
                .collect()
        };
        check_lower_bounds_named(self.error_names.to_vec(), lower_bounds_rad)?;
        self.check_room(linear, lower_bounds_rad, margins)?;
        let n = linear.positions();
        let n_errors = self.error_names.len();
        let acc = self.accuracies.to_vec();
        let unconstrained: Vec<usize> = linear
            .unconstrained()
            .into_iter()
            .filter(|&j| spec_coefficients.iter().all(|c| c[j] == 0.0))
            .collect();
        let free: Vec<usize> = (0..n_errors)
            .filter(|j| !unconstrained.contains(j))
            .collect();
        let names = self.error_names;
        let weights = self.weights;
        if free.is_empty() {
            // no error affects any output to first order: no bound is needed for any
            return Ok(DirectAllocation {
                upper_bounds_rad: vec![f64::INFINITY; n_errors],
                unconstrained,
                lower_bounds_rad: lower_bounds_rad.to_vec(),
                loads: (0..linear.matrix().nrows())
                    .map(|r| RowLoad {
                        output: r / n,
                        position: r % n,
                        load: 0.0,
                    })
                    .collect(),
                accuracies: acc,
                objective: 0.0,
                multiplier: 0.0,
                iterations: 0,
                second_order_margins: margins.to_vec(),
                spec_loads: spec_loads(&vec![0.0; n_errors]),
            });
        }
        let rows = self.cuts(
            linear,
            &free,
            margins,
            spec_rows,
            &spec_coefficients,
            l1_budget_rad,
        );
        let oracle = FiniteCuts::new(rows.clone());
        let problem = InverseSquareProblem {
            label: "direct".into(),
            names: free.iter().map(|&j| names[j].to_string()).collect(),
            weights: free.iter().map(|&j| weights[j]).collect(),
            lower: free.iter().map(|&j| lower_bounds_rad[j]).collect(),
            initial_cuts: rows,
            oracle: &oracle,
        };
        let sol = solve_inverse_square(&problem)?;
        let mut ub = vec![f64::INFINITY; n_errors];
        for (k, &j) in free.iter().enumerate() {
            // the solver meets UB >= LB to rounding; make it exact so the box is valid
            ub[j] = crate::error::finite(format!("upper_bounds.{}", names[j]), sol.x()[k])?
                .max(lower_bounds_rad[j]);
        }
        let loads = linear
            .row_worst_cases(&ub)
            .iter()
            .enumerate()
            .map(|(r, v)| RowLoad {
                output: r / n,
                position: r % n,
                load: v / acc[r / n],
            })
            .collect();
        let spec_loaded = spec_loads(&ub);
        Ok(DirectAllocation {
            objective: objective_with(weights, &ub),
            upper_bounds_rad: ub,
            unconstrained,
            lower_bounds_rad: lower_bounds_rad.to_vec(),
            accuracies: acc,
            loads,
            multiplier: sol.multiplier(),
            iterations: sol.iterations(),
            second_order_margins: margins.to_vec(),
            spec_loads: spec_loaded,
        })
    }
}

/// Every specification row leaves room beside its noise part, and the lower bounds alone fit
/// in it.
///
/// # Errors
/// [`E2eError::NoTableSuffices`] or [`E2eError::InfeasibleLowerBounds`] naming the row.
fn check_spec_rows(
    spec_rows: &[SpecificationRow],
    lower_bounds_rad: &[f64],
) -> Result<(), E2eError> {
    for row in spec_rows {
        row.check_room()?;
        let lb = row.value(lower_bounds_rad);
        if lb > row.room() {
            return Err(E2eError::InfeasibleLowerBounds {
                output: format!("{} (specification)", row.label()),
                position: 0,
                worst: lb,
                accuracy: row.limit(),
            });
        }
    }
    Ok(())
}
