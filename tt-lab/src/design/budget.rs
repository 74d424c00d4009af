//! The positions and the dwell chosen together under a total test-time budget with the noise
//! counted ([`schedule_design::design_with_budget`]): the Pareto front of total test time
//! against J, and the chosen point certified on the exact chain (`design-schedule
//! --time-budget-s`).

use crate::design::schedule::{NoiseCounted, design_problem, noise_counted};
use crate::end_to_end::uniform_dwell;
use crate::error::{InputError, Result, library};
use crate::json::{ArcminBounds, arcmin_bounds};
use e2e_verify::E2eError;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use schedule_design::{
    BudgetDesign, BudgetParams, BudgetPoint, DesignProblem, ScheduleOrigin, TimeBudget,
    check_budget_affords, design_with_budget,
};
use study::Study;
use tt_core::human::{exact, num, sig};

/// What the budget answers for a study.
#[derive(Debug)]
pub enum Budgeted {
    /// The study gives no noise: the budget only changes the dwell.
    Noiseless {
        /// The budget, s.
        budget_s: f64,
    },
    /// The design under the budget.
    Design(Box<Designed>),
}

/// The budget design with the chosen point certified on the exact chain.
#[derive(Debug)]
#[non_exhaustive]
pub struct Designed {
    design: BudgetDesign,
    /// The fewest positions a proposed point keeps: the fewest that identify every output
    /// plus the redundancy ([`schedule_design::fewest_proposed`]).
    fewest_positions: usize,
    /// Positions beyond the fewest that identify every output ([`Options`]'s `redundancy`).
    redundancy: usize,
    /// Whether the study has rate steps (their windows count in every total).
    rate_steps: bool,
    /// The chosen point's direct allocation with the noise part kept free, certified on the
    /// exact chain (as `end-to-end`'s `direct_with_noise` on the study written with the
    /// chosen positions and dwell); `None` without a chosen point. The budget's own J is the
    /// linearised allocation.
    chosen_counted: Option<NoiseCounted>,
}

impl Designed {
    /// The fewest positions a proposed point keeps (the fewest that identify every output
    /// plus the redundancy).
    #[must_use]
    pub fn fewest_positions(&self) -> usize {
        self.fewest_positions
    }

    /// Positions beyond the fewest that identify every output that every proposed point
    /// keeps.
    #[must_use]
    pub fn redundancy(&self) -> usize {
        self.redundancy
    }

    /// J (arcmin^-2) of [`Designed::chosen_counted`]; `None` without a chosen point or when
    /// no table suffices on the exact chain.
    #[must_use]
    pub fn chosen_certified_arcmin(&self) -> Option<f64> {
        self.chosen_counted
            .as_ref()
            .and_then(NoiseCounted::objective_arcmin)
    }

    /// The chosen point's direct allocation with the noise part kept free, certified on the
    /// exact chain where the reading allows; `None` without a chosen point.
    #[must_use]
    pub(crate) fn chosen_counted(&self) -> Option<&NoiseCounted> {
        self.chosen_counted.as_ref()
    }

    /// The library's budget design.
    #[must_use]
    pub fn design(&self) -> &BudgetDesign {
        &self.design
    }
}

impl std::ops::Deref for Designed {
    type Target = BudgetDesign;
    fn deref(&self) -> &BudgetDesign {
        &self.design
    }
}

/// The study with `p`'s positions and its one dwell at each (the study's move time, sample
/// rate and rate steps' windows kept), as `--write-study` writes it.
///
/// # Errors
/// As [`Study::with_positions_deg`] (the positions were candidates, so only internal).
pub(crate) fn study_at(s: &Study, timing: &calib_lsq::Timing, p: &BudgetPoint) -> Result<Study> {
    let mut s2 = s.clone();
    s2.timing = Some(
        timing
            .with_dwell_s(vec![p.dwell_s(); s.positions_deg.len()])
            .map_err(|e| library(e, s))?,
    );
    Ok(s2
        .with_positions_deg(p.positions_deg().to_vec())
        .map_err(InputError::from)?)
}

/// Why a noiseless study's answer does not change with the budget.
pub const NOISELESS_NOTE: &str = "the study gives no noise: the budget only changes the dwell (without noise the table's part does not depend on the dwell), so the positions are those designed for the table and the answer is the one without a budget";

/// Run the budget design on the designed (`table`) and the study's schedule.
///
/// # Errors
/// An [`InputError`] naming `--time-budget-s` when the study gives noise but no
/// `[calibration.timing]` (the sample rate and move time); library errors otherwise.
pub fn run(
    s: &Study,
    problem: &DesignProblem,
    table: &[usize],
    d_optimal: &[usize],
    max_condition: f64,
    budget_s: f64,
    redundancy: usize,
) -> Result<Budgeted> {
    if s.noise.iter().all(Option::is_none) {
        return Ok(Budgeted::Noiseless { budget_s });
    }
    let timing = timing_of(s)?;
    let study: Option<Vec<usize>> = s
        .positions_deg
        .iter()
        .map(|p| problem.index_of(p))
        .collect();
    let mut b = time_budget(s, timing, budget_s, uniform_dwell(timing.dwell_s()));
    b.params.redundancy = redundancy;
    let d = design_with_budget(
        problem,
        table,
        study.as_deref(),
        &s.positions_deg,
        &[(ScheduleOrigin::DOptimal, d_optimal.to_vec())],
        max_condition,
        &b,
    )
    .map_err(|e| library(e, s))?;
    // the chosen point as `--write-study` writes it, with the noise counted
    let chosen_counted = match &d.chosen() {
        Some(p) => noise_counted(&study_at(s, timing, p)?)?,
        None => None,
    };
    Ok(Budgeted::Design(Box::new(Designed {
        design: d,
        fewest_positions: schedule_design::fewest_proposed(problem, &b),
        redundancy,
        rate_steps: s.has_rate_steps(),
        chosen_counted,
    })))
}

/// The budget of a study with noise and timing: its noise, move time and sample rate, the
/// default $k\sigma$, dwells up to the study's limit, the counts searched, and its rate steps
/// with their windows after every schedule's static positions.
fn time_budget<'a>(
    s: &'a Study,
    timing: &'a calib_lsq::Timing,
    budget_s: f64,
    study_dwell_s: Option<f64>,
) -> TimeBudget<'a> {
    TimeBudget {
        noise: &s.noise,
        move_s: timing.move_s(),
        sample_rate_hz: timing.sample_rate_hz(),
        k_sigma: DEFAULT_K_SIGMA,
        budget_s,
        max_dwell_s: study::limits::DWELL_S.1,
        study_dwell_s,
        search_counts: true,
        params: BudgetParams::default(),
        // the study's rate steps follow its static positions, with their whole-revolution
        // windows whatever the static dwell
        rate_steps: &s.calibration.schedule().positions()[s.positions_deg.len()..],
        rate_step_s: timing.rate_step_s(),
    }
}

/// The timing of a study with noise: the budget needs its sample rate and move time.
///
/// # Errors
/// An [`InputError`] naming `--time-budget-s` when the study has no `[calibration.timing]`.
fn timing_of(s: &Study) -> Result<&calib_lsq::Timing, InputError> {
    s.timing.as_ref().ok_or_else(|| {
        InputError::new(
            "--time-budget-s",
            "the study gives noise but no [calibration.timing]: the budget needs its sample_rate_hz and move_s",
        )
    })
}

/// Before the (long) table search: a study with noise but no timing, and a budget shorter
/// than the fewest positions that identify every output (at one move and one sample each),
/// are input errors naming `--time-budget-s` (the second checked again by the library; the
/// budget quoted as given, [`tt_core::human::exact`]). Nothing to check without noise.
///
/// # Errors
/// That [`InputError`].
pub(crate) fn check_affords(s: &Study, budget_s: f64) -> Result<()> {
    if s.noise.iter().all(Option::is_none) {
        return Ok(());
    }
    let timing = timing_of(s)?;
    let problem = design_problem(s, s.positions_deg.clone())?;
    let b = time_budget(s, timing, budget_s, None);
    check_budget_affords(&problem, &b).map_err(|e| match e {
        E2eError::BudgetTooShort {
            positions,
            output,
            needed_s,
            ..
        } => InputError::new(
            "--time-budget-s",
            format!(
                "time_budget_s = {} s is too short: the fewest positions that identify every output ({positions}, for output `{output}`) take {} s at one sample each (positions x (move_s + 1/sample_rate_hz))",
                exact(budget_s),
                num(needed_s)
            ),
        )
        .into(),
        e => library(e, s),
    })
}

/// A budget point's schedule origin in words (`pareto[].origin`).
#[must_use]
pub fn origin(o: ScheduleOrigin) -> String {
    match o {
        ScheduleOrigin::Table => "designed for the table".into(),
        ScheduleOrigin::Study => "study's positions".into(),
        ScheduleOrigin::DOptimal => "D-optimal".into(),
        ScheduleOrigin::Noise(t) => format!("designed with the noise at {} s", sig(t, 4)),
    }
}

/// A point of the Pareto front (the cheapest table for a total test time).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct PointJson {
    /// Total test time, s (positions x (dwell + move)).
    total_s: f64,
    /// Number of positions.
    n_positions: usize,
    /// Dwell per position, s.
    dwell_s: f64,
    /// J of the direct allocation with the noise part kept free, arcmin^-2.
    objective_arcmin: f64,
    /// The schedule's origin, in words.
    origin: String,
    /// The point's tolerance box: the direct allocation with the noise part kept free for
    /// its schedule at its dwell, arcmin per rotation error (`null`: no bound needed), as
    /// `end-to-end`'s linearised `direct_with_noise` box for that schedule and dwell.
    bounds_arcmin: ArcminBounds,
}

impl PointJson {
    /// The view of `p`, its tolerances keyed by the rotation errors' `names`.
    fn new(p: &BudgetPoint, names: &[&str]) -> Self {
        Self {
            total_s: p.total_s(),
            n_positions: p.n_positions(),
            dwell_s: p.dwell_s(),
            objective_arcmin: p.objective_arcmin(),
            origin: origin(p.origin()),
            bounds_arcmin: arcmin_bounds(names, p.tolerances_rad()),
        }
    }
}

/// A point's tolerance box in words: `name value` in arcmin per rotation error, in the
/// turntable's order (`-`: no bound needed), three significant digits.
#[must_use]
pub fn tolerances_text(p: &BudgetPoint, names: &[&str]) -> String {
    names
        .iter()
        .zip(p.tolerances_rad())
        .map(|(n, u)| {
            if u.is_finite() {
                format!("{n} {}", sig(tt_core::units::rad_to_arcmin(*u), 3))
            } else {
                format!("{n} -")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The front's cheapest table within the budget, with its positions.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct ChosenJson<'a> {
    /// The point.
    #[cfg_attr(feature = "serde", serde(flatten))]
    point: PointJson,
    /// Its positions, degrees (joint angles per position).
    positions_deg: &'a [Vec<f64>],
    /// Its J certified on the exact chain (arcmin^-2; `end-to-end`'s `direct_with_noise`
    /// objective on the study `--write-study` writes), `null` when no certified table
    /// suffices.
    certified_objective_arcmin: Option<f64>,
}

/// `time_budget`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
#[allow(
    clippy::large_enum_variant,
    reason = "a view built once per command and serialised at once; boxing buys nothing"
)]
pub(crate) enum TimeBudgetJson<'a> {
    /// The study gives no noise.
    Noiseless {
        /// The budget, s.
        budget_s: f64,
        /// Why the answer does not change.
        note: &'static str,
    },
    /// The design under the budget.
    Design {
        /// The budget, s.
        budget_s: f64,
        /// The confidence multiplier of the noise part.
        k_sigma: f64,
        /// The total test time's definition.
        total_time: &'static str,
        /// Positions beyond the fewest that identify every output that every proposed point
        /// keeps (`--redundancy`).
        redundancy: usize,
        /// The fewest positions of a proposed point (the study's own schedule is evaluated
        /// whatever its count).
        fewest_positions: usize,
        /// Schedules evaluated.
        schedules: usize,
        /// Dwells evaluated.
        dwells: usize,
        /// (schedule, dwell) pairs evaluated.
        evaluated: usize,
        /// The numbers of positions designed for.
        counts: &'a [usize],
        /// The counts with no table design.
        counts_skipped: &'a [usize],
        /// The counts the refinement added (bisection around the best count).
        counts_refined: &'a [usize],
        /// The front's cheapest table within the budget, `null` when none fits.
        chosen: Option<ChosenJson<'a>>,
    },
}

/// The budget's keys of `design-schedule --json`: `time_budget` and, with noise, `pareto`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct BudgetJson<'a> {
    /// The budget and the choice.
    time_budget: TimeBudgetJson<'a>,
    /// With noise: the Pareto front; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pareto: Option<Vec<PointJson>>,
}

/// The budget's view.
pub(crate) fn json<'a>(s: &Study, b: &'a Budgeted) -> BudgetJson<'a> {
    let names = s.turntable.rotation_error_names();
    match b {
        Budgeted::Noiseless { budget_s } => BudgetJson {
            time_budget: TimeBudgetJson::Noiseless {
                budget_s: *budget_s,
                note: NOISELESS_NOTE,
            },
            pareto: None,
        },
        Budgeted::Design(d) => BudgetJson {
            time_budget: TimeBudgetJson::Design {
                budget_s: d.budget_s(),
                k_sigma: d.k_sigma(),
                total_time: if d.rate_steps {
                    "n_positions x (dwell_s + move_s) + the rate steps' whole-revolution windows and a move before each"
                } else {
                    "n_positions x (dwell_s + move_s)"
                },
                redundancy: d.redundancy,
                fewest_positions: d.fewest_positions,
                schedules: d.schedules().len(),
                dwells: d.dwells_s().len(),
                evaluated: d.evaluated(),
                counts: d.counts(),
                counts_skipped: d.counts_skipped(),
                counts_refined: d.counts_refined(),
                chosen: d.chosen().map(|p| ChosenJson {
                    point: PointJson::new(p, &names),
                    positions_deg: p.positions_deg(),
                    certified_objective_arcmin: d.chosen_certified_arcmin(),
                }),
            },
            pareto: Some(
                d.pareto()
                    .iter()
                    .map(|p| PointJson::new(p, &names))
                    .collect(),
            ),
        },
    }
}
