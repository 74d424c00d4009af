//! `design-schedule --time-budget-s SECONDS [--pareto-svg PATH]`: the positions and the dwell
//! chosen together under a total test-time budget with the noise counted
//! ([`schedule_design::design_with_budget`]); the Pareto front of total test time against
//! J as a table, JSON (`time_budget`, `pareto`) and a figure.

use crate::InputError;
use crate::report::figures::{self, LIMIT, LinePanel, Mark, Series, colour};
use anyhow::Result;
use e2e_verify::E2eError;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use schedule_design::{
    BudgetDesign, BudgetParams, BudgetPoint, DesignProblem, ScheduleOrigin, TimeBudget,
    check_budget_affords, design_with_budget,
};
use serde::Serialize;
use study::Study;
use study::fmt::{exact, num, sig};

/// What the budget answers for a study.
pub enum Budgeted {
    /// The study gives no noise: the budget only changes the dwell.
    Noiseless { budget_s: f64 },
    /// The design under the budget.
    Design(Box<Designed>),
}

/// The budget design with the chosen point certified on the exact chain.
pub struct Designed {
    /// The library's answer.
    pub design: BudgetDesign,
    /// The chosen point's direct allocation with the noise part kept free, certified on the
    /// exact chain (as `end-to-end`'s `direct_with_noise` on the study written with the
    /// chosen positions and dwell); `None` without a chosen point. The budget's own J is the
    /// linearised allocation.
    pub(crate) chosen_counted: Option<crate::design_schedule::NoiseCounted>,
}

impl Designed {
    /// J (arcmin^-2) of [`Designed::chosen_counted`]; `None` without a chosen point or when
    /// no table suffices on the exact chain.
    pub fn chosen_certified_arcmin(&self) -> Option<f64> {
        self.chosen_counted
            .as_ref()
            .and_then(crate::design_schedule::NoiseCounted::objective_arcmin)
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
pub fn study_at(s: &Study, timing: &calib_lsq::Timing, p: &BudgetPoint) -> Result<Study> {
    let mut s2 = s.clone();
    s2.timing = Some(timing.with_dwell_s(vec![p.dwell_s(); s.positions_deg.len()])?);
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
    let b = time_budget(s, timing, budget_s, uniform_dwell(timing.dwell_s()));
    let d = design_with_budget(
        problem,
        table,
        study.as_deref(),
        &s.positions_deg,
        &[(ScheduleOrigin::DOptimal, d_optimal.to_vec())],
        max_condition,
        &b,
    )
    .map_err(|e| crate::input::library(e, s))?;
    // the chosen point as `--write-study` writes it, with the noise counted
    let chosen_counted = match &d.chosen() {
        Some(p) => crate::design_schedule::noise_counted(&study_at(s, timing, p)?)?,
        None => None,
    };
    Ok(Budgeted::Design(Box::new(Designed {
        design: d,
        chosen_counted,
    })))
}

/// The budget of a study with noise and timing: its noise, move time and sample rate, the
/// default $k\sigma$, dwells up to the study's limit, the counts searched.
fn time_budget<'a>(
    s: &'a Study,
    timing: &calib_lsq::Timing,
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
    }
}

/// The study's dwell when every position has the same one.
pub(crate) fn uniform_dwell(dwell_s: &[f64]) -> Option<f64> {
    let first = *dwell_s.first()?;
    dwell_s
        .iter()
        .all(|d| d.to_bits() == first.to_bits())
        .then_some(first)
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
/// budget quoted as given, [`study::fmt::exact`]). Nothing to check without noise.
///
/// # Errors
/// That [`InputError`].
pub fn check_affords(s: &Study, budget_s: f64) -> Result<()> {
    if s.noise.iter().all(Option::is_none) {
        return Ok(());
    }
    let timing = timing_of(s)?;
    let problem = DesignProblem::new(
        &s.turntable,
        &s.sensor,
        &s.site,
        s.reading,
        &s.lower_bounds_rad,
        s.positions_deg.clone(),
    )
    .map_err(|e| crate::input::library(e, s))?;
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
        e => crate::input::library(e, s),
    })
}

fn origin(o: ScheduleOrigin) -> String {
    match o {
        ScheduleOrigin::Table => "designed for the table".into(),
        ScheduleOrigin::Study => "study's positions".into(),
        ScheduleOrigin::DOptimal => "D-optimal".into(),
        ScheduleOrigin::Noise(t) => format!("designed with the noise at {} s", sig(t, 4)),
    }
}

/// A point of the Pareto front (the cheapest table for a total test time).
#[derive(Debug, Serialize)]
pub struct PointJson {
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
}

impl From<&BudgetPoint> for PointJson {
    fn from(p: &BudgetPoint) -> Self {
        Self {
            total_s: p.total_s(),
            n_positions: p.n_positions(),
            dwell_s: p.dwell_s(),
            objective_arcmin: p.objective_arcmin(),
            origin: origin(p.origin()),
        }
    }
}

/// The front's cheapest table within the budget, with its positions.
#[derive(Debug, Serialize)]
pub struct ChosenJson<'a> {
    /// The point.
    #[serde(flatten)]
    point: PointJson,
    /// Its positions, degrees (joint angles per position).
    positions_deg: &'a [Vec<f64>],
    /// Its J certified on the exact chain (arcmin^-2; `end-to-end`'s `direct_with_noise`
    /// objective on the study `--write-study` writes), `null` when no certified table
    /// suffices.
    certified_objective_arcmin: Option<f64>,
}

/// `time_budget`.
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum TimeBudgetJson<'a> {
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
#[derive(Debug, Serialize)]
pub struct BudgetJson<'a> {
    /// The budget and the choice.
    time_budget: TimeBudgetJson<'a>,
    /// With noise: the Pareto front; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pareto: Option<Vec<PointJson>>,
}

/// The budget's view.
pub fn json(b: &Budgeted) -> BudgetJson<'_> {
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
                total_time: "n_positions x (dwell_s + move_s)",
                schedules: d.schedules().len(),
                dwells: d.dwells_s().len(),
                evaluated: d.evaluated(),
                counts: d.counts(),
                counts_skipped: d.counts_skipped(),
                counts_refined: d.counts_refined(),
                chosen: d.chosen().map(|p| ChosenJson {
                    point: p.into(),
                    positions_deg: p.positions_deg(),
                    certified_objective_arcmin: d.chosen_certified_arcmin(),
                }),
            },
            pareto: Some(d.pareto().iter().map(PointJson::from).collect()),
        },
    }
}

/// The lines `--write-study` puts above the positions the budget chose (`p`, chosen in `d`).
pub fn chosen_comment(d: &Designed, p: &BudgetPoint) -> String {
    format!(
        "With --time-budget-s {}: these {} positions ({}) and dwell_s = {} s at each\n({} s of test in all) were chosen together; J = {} arcmin^-2 with the noise part\nkept free at {} sigma (linearised), {} certified on the exact chain (end-to-end's\ndirect_with_noise objective on this file). The dwell_s of [calibration.timing] below is\nthis one; the comments there describe the study's original timing.",
        num(d.budget_s()),
        p.n_positions(),
        origin(p.origin()),
        num(p.dwell_s()),
        sig(p.total_s(), 6),
        num(p.objective_arcmin()),
        num(d.k_sigma()),
        d.chosen_certified_arcmin()
            .map_or("no table suffices".to_string(), |j| format!(
                "J = {}",
                num(j)
            )),
    )
}

/// The budget's answer in words, with the Pareto front as a table.
pub fn text(s: &Study, b: &Budgeted) -> String {
    let d = match b {
        Budgeted::Noiseless { budget_s } => {
            return format!("time budget {} s: {NOISELESS_NOTE}\n\n", num(*budget_s));
        }
        Budgeted::Design(d) => d,
    };
    let mut t = format!(
        "time budget {} s ({} h; total = positions x (dwell + move)), noise counted at {} sigma: {} schedules at {} dwells each (J of the direct allocation with the noise part kept free, as end-to-end's trade-off)\n",
        num(d.budget_s()),
        sig(d.budget_s() / 3600.0, 4),
        num(d.k_sigma()),
        d.schedules().len(),
        d.dwells_s().len()
    );
    t.push_str(&format!(
        "  numbers of positions designed for: {}{}\n",
        d.counts()
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(", "),
        if d.counts_skipped().is_empty() {
            String::new()
        } else {
            format!(
                " (no schedule within the condition bound found for {})",
                d.counts_skipped()
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    ));
    match &d.chosen() {
        Some(p) => t.push_str(&format!(
            "  within the budget: {} positions x {} s ({} s in all), J = {} arcmin^-2 ({}); certified on the exact chain: {}\n",
            p.n_positions(),
            sig(p.dwell_s(), 4),
            sig(p.total_s(), 4),
            sig(p.objective_arcmin(), 6),
            origin(p.origin()),
            d.chosen_certified_arcmin()
                .map_or("no table suffices".to_string(), |j| format!("J = {}", sig(j, 6)))
        )),
        None => t.push_str(&match d.pareto().first() {
            Some(p) => format!(
                "  within the budget no table suffices (the noise fills an accuracy); the shortest test at which one does: {} s ({} positions x {} s)\n",
                sig(p.total_s(), 4),
                p.n_positions(),
                sig(p.dwell_s(), 4)
            ),
            None => format!(
                "  no table suffices at any dwell up to {} s per position: the noise fills an accuracy\n",
                num(study::limits::DWELL_S.1)
            ),
        }),
    }
    if !d.pareto().is_empty() {
        t.push_str(&format!(
            "  Pareto front (the cheapest table for each total test time; outputs {}):\n",
            s.sensor
                .outputs()
                .iter()
                .map(|o| o.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
        t.push_str(&format!(
            "  {:>12} {:>10} {:>12} {:>14}  {}\n",
            "total (s)", "positions", "dwell (s)", "J (arcmin^-2)", "schedule"
        ));
        for p in d.pareto() {
            t.push_str(&format!(
                "  {:>12} {:>10} {:>12} {:>14}  {}{}\n",
                sig(p.total_s(), 4),
                p.n_positions(),
                sig(p.dwell_s(), 4),
                sig(p.objective_arcmin(), 5),
                origin(p.origin()),
                if p.total_s() <= d.budget_s() {
                    ""
                } else {
                    " (over the budget)"
                }
            ));
        }
    }
    t.push('\n');
    t
}

/// Why `--pareto-svg` writes no figure when the front is empty (an answer, not an error).
pub const EMPTY_FRONT_NOTE: &str =
    "not written: the Pareto front is empty (no table suffices at any dwell), nothing to draw";

/// The Pareto front as a figure in the report's style (the report's line-figure code):
/// J against the total test time, both log10, with the chosen point; `None` when the front is
/// empty (no table suffices at any dwell: nothing to draw, [`EMPTY_FRONT_NOTE`]).
///
/// # Errors
/// When a value is not plottable.
pub fn svg(d: &BudgetDesign) -> Result<Option<String>> {
    if d.pareto().is_empty() {
        return Ok(None);
    }
    let xy = |p: &BudgetPoint| ((p.total_s() / 3600.0).log10(), p.objective_arcmin().log10());
    let mut series = vec![Series {
        label: "Pareto front: the cheapest table for each total test time".into(),
        points: d.pareto().iter().map(xy).collect(),
        mark: Mark::Line(colour(0), false),
    }];
    if let Some(p) = &d.chosen() {
        series.push(Series {
            label: format!(
                "chosen within the budget ({} h)",
                sig(d.budget_s() / 3600.0, 3)
            ),
            points: vec![xy(p)],
            mark: Mark::Dots(LIMIT),
        });
    }
    let panel = LinePanel {
        title: "Test time against the table's J".into(),
        x_label: "total test time, log10 (h)".into(),
        y_label: "log10 J (arcmin⁻²)".into(),
        series,
        hlines: Vec::new(),
        x_integer: false,
        y_from_zero: false,
    };
    Ok(Some(figures::line_figure(
        "Test time and the table",
        &[panel],
        1,
    )?))
}
