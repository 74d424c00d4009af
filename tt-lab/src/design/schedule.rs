//! The calibration schedule that lets the cheapest turntable meet every output's accuracy
//! (`design-schedule`): the position search on the joint-angle grid
//! ([`schedule_design::design_on_grid`]), the study's, D-optimal and best random schedules
//! answered beside the designed one; with noise and a timing both schedules compared with the
//! noise counted ([`CombinedChoice`]); with candidate rates the rate of the rate steps chosen
//! ([`crate::design::rates`]); with a time budget the positions and the dwell chosen together
//! ([`crate::design::budget`]).
//!
//! One call: [`design`] with [`Options`] answers a [`ScheduleAnswer`]; its JSON view
//! ([`ScheduleAnswer::view`], keys of `design-schedule --json`) is behind the `serde` feature.

use crate::design::budget::{self, Budgeted};
use crate::design::rates::{self, RateChoice};
use crate::error::{InputError, LabError, Result, library};
use crate::json::{ArcminBounds, GroupJson, PerAngle, arcmin_bounds};
use e2e_verify::noise::DEFAULT_K_SIGMA;
use schedule_design::{
    DEFAULT_MAX_CONDITION, DEFAULT_STEP_DEG, DesignInputs, DesignProblem, DesignSettings,
    ScheduleDesign, ScheduleReport, SpecObjective, StartKind, coarse_levels, design_on_grid,
};
use std::collections::BTreeMap;
use std::time::Instant;
use study::Study;
use tt_core::units::objective_to_arcmin;

/// The settings of a schedule design; [`Default`] is the command line's defaults.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Options {
    /// Number of test positions (`None`: the study's).
    pub positions: Option<usize>,
    /// Grid step of the candidate joint angles, deg, in (0, 360].
    pub step_deg: f64,
    /// Largest condition number allowed for any output's regression.
    pub max_condition: f64,
    /// Seed of the restarts and of the random baseline (`None`: the study's).
    pub seed: Option<u64>,
    /// Total test-time budget, s: the positions and the dwell chosen together.
    pub time_budget_s: Option<f64>,
    /// Candidate rates of the study's rate steps, deg/s.
    pub rates_deg_per_s: Option<Vec<f64>>,
    /// With a time budget: positions beyond the fewest that identify every output that every
    /// proposed point keeps (default [`schedule_design::DEFAULT_REDUNDANCY`]).
    pub redundancy: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            positions: None,
            step_deg: DEFAULT_STEP_DEG,
            max_condition: DEFAULT_MAX_CONDITION,
            seed: None,
            time_budget_s: None,
            rates_deg_per_s: None,
            redundancy: schedule_design::DEFAULT_REDUNDANCY,
        }
    }
}

impl Options {
    /// The search's settings for `s` (its position count and seed where not given).
    #[must_use]
    pub fn settings(&self, s: &Study) -> DesignSettings {
        let mut settings = DesignSettings::new(
            self.positions.unwrap_or(s.positions_deg.len()),
            self.seed.unwrap_or(s.monte_carlo.seed),
        );
        settings.max_condition = self.max_condition;
        settings
    }

    /// The units of work [`design`] reports through its progress callback.
    #[must_use]
    pub fn work_units(&self, s: &Study) -> u64 {
        self.settings(s).work_units() + coarse_levels(self.step_deg)
    }
}

/// A study's schedule design: the designed, the study's, D-optimal and best random
/// schedules, and what the options added.
#[derive(Debug)]
#[non_exhaustive]
pub struct ScheduleAnswer {
    design: ScheduleDesign,
    combined: Option<CombinedChoice>,
    budget: Option<Budgeted>,
    rates: Option<RateChoice>,
    settings: DesignSettings,
    candidates: usize,
    step_deg: f64,
    seconds: f64,
}

impl ScheduleAnswer {
    /// The library's design (the four schedules and the search).
    #[must_use]
    pub fn design(&self) -> &ScheduleDesign {
        &self.design
    }

    /// With noise and a timing in the study: both schedules answered for both error sources.
    #[must_use]
    pub fn combined(&self) -> Option<&CombinedChoice> {
        self.combined.as_ref()
    }

    /// With a time budget: the positions and dwell chosen together.
    #[must_use]
    pub fn budget(&self) -> Option<&Budgeted> {
        self.budget.as_ref()
    }

    /// With candidate rates: the rate chosen.
    #[must_use]
    pub fn rates(&self) -> Option<&RateChoice> {
        self.rates.as_ref()
    }

    /// The search's settings (positions, seed, condition bound).
    #[must_use]
    pub fn settings(&self) -> &DesignSettings {
        &self.settings
    }

    /// Number of candidate positions.
    #[must_use]
    pub fn candidates(&self) -> usize {
        self.candidates
    }

    /// The candidates' grid step, deg.
    #[must_use]
    pub fn step_deg(&self) -> f64 {
        self.step_deg
    }

    /// Time of the search, s (a timing: not reproducible).
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    /// Whether the study's positions are recommended over the designed ones: the designed
    /// lose once the noise is counted.
    #[must_use]
    pub(crate) fn keep_study(&self) -> bool {
        self.combined
            .as_ref()
            .is_some_and(|c| !c.designed_recommended)
    }

    /// The bounds behind each schedule's recommended tolerances (`designed`, `study's`), for
    /// the groups of errors that act only together.
    #[must_use]
    pub fn group_bounds(&self) -> [(&'static str, &[f64]); 2] {
        let c = self.combined.as_ref();
        [
            (
                "designed",
                recommended_bounds(self.design.designed(), c.map(|c| &c.designed)),
            ),
            (
                "study's",
                recommended_bounds(self.design.study(), c.map(|c| &c.study)),
            ),
        ]
    }
}

/// Check the options against the study before the (long) search: the candidate rates
/// ([`rates::check`]) and the time budget ([`budget::check_affords`]).
///
/// # Errors
/// An [`InputError`] naming the flag.
pub fn check(s: &Study, o: &Options) -> Result<()> {
    if let Some(r) = &o.rates_deg_per_s {
        rates::check(s, r)?;
    }
    if let Some(b) = o.time_budget_s {
        budget::check_affords(s, b)?;
    }
    Ok(())
}

/// Design the schedule of `s` with `o`, `progress` called once per unit of work
/// ([`Options::work_units`]).
///
/// # Errors
/// As [`check`]; a library error located in the study.
pub fn design(s: &Study, o: &Options, progress: &(dyn Fn() + Sync)) -> Result<ScheduleAnswer> {
    check(s, o)?;
    let settings = o.settings(s);
    let (problem, design, seconds) = search(s, o.step_deg, &settings, progress)?;
    let combined = combined_choice(s, &design)?;
    let keep_study = combined.as_ref().is_some_and(|c| !c.designed_recommended);
    let rates = match &o.rates_deg_per_s {
        Some(r) => Some(rates::choose(
            s,
            if keep_study {
                design.study().positions_deg()
            } else {
                design.designed().positions_deg()
            },
            r,
        )?),
        None => None,
    };
    let budget = o
        .time_budget_s
        .map(|b| {
            budget::run(
                s,
                &problem,
                design.search().designed().evaluation().schedule(),
                design.search().d_optimal().schedule(),
                o.max_condition,
                b,
                o.redundancy,
            )
        })
        .transpose()?;
    Ok(ScheduleAnswer {
        design,
        combined,
        budget,
        rates,
        settings,
        candidates: problem.n_candidates(),
        step_deg: o.step_deg,
        seconds,
    })
}

/// The position search on the grid, timed, with its J checked against the end-to-end path's.
fn search(
    s: &Study,
    step_deg: f64,
    settings: &DesignSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<(DesignProblem, ScheduleDesign, f64)> {
    let specifications = spec_objective(s)?;
    let inputs = DesignInputs {
        turntable: &s.turntable,
        sensor: &s.sensor,
        site: &s.site,
        reading: s.reading,
        delta_r_kind: s.delta_r_kind,
        lower_bounds_rad: &s.lower_bounds_rad,
        study_positions_deg: &s.positions_deg,
        specifications: specifications.as_ref(),
    };
    let t0 = Instant::now();
    let (problem, design) =
        design_on_grid(&inputs, step_deg, settings, progress).map_err(|e| library(e, s))?;
    let seconds = t0.elapsed().as_secs_f64();
    // the report's J comes from the same path as `end-to-end`; the search's must agree
    let searched = design.search().designed().evaluation().objective();
    let reported = design.designed().allocation().objective();
    if (searched - reported).abs() > 1e-9 * reported {
        return Err(LabError::internal(Disagree { searched, reported }));
    }
    Ok((problem, design, seconds))
}

/// The design objective against the study's specifications (issue 34 item 6): the
/// specifications the study's own schedule leaves the table room for
/// ([`crate::allocation::spec::context`], the ones `end-to-end`'s direct allocation holds),
/// with the study's rate steps after every schedule's static positions; `None` when the study
/// gives none (or none leaves room): the design is then eq 14's, as before.
///
/// # Errors
/// A library error located in the study.
pub fn spec_objective(s: &Study) -> Result<Option<SpecObjective>> {
    if s.specifications.is_empty() {
        return Ok(None);
    }
    let e2e = crate::loaded::simulator(s)?;
    let Some(context) = crate::allocation::spec::context(s, &e2e)?.context else {
        return Ok(None);
    };
    let rate_steps = s.calibration.schedule().positions()[s.positions_deg.len()..].to_vec();
    Ok(Some(SpecObjective::new(context, rate_steps)))
}

/// The design problem of the study's table, sensor, site, reading and lower bounds over the
/// candidate positions `candidates_deg` (deg, one row per position).
///
/// # Errors
/// A library error located in the study (no candidates, too many, a position of the wrong
/// length).
pub fn design_problem(s: &Study, candidates_deg: Vec<Vec<f64>>) -> Result<DesignProblem> {
    DesignProblem::new(
        &s.turntable,
        &s.sensor,
        &s.site,
        s.reading,
        &s.lower_bounds_rad,
        candidates_deg,
    )
    .map_err(|e| library(e, s))
}

/// The search's J and the end-to-end path's differ (a defect, not the input's).
#[derive(Debug, thiserror::Error)]
#[error("internal: the search's J {searched} and the end-to-end path's {reported} differ")]
struct Disagree {
    searched: f64,
    reported: f64,
}

/// A restart's start in words (`search.restarts[].start`).
#[must_use]
pub fn start_name(k: StartKind) -> String {
    match k {
        StartKind::Study => "study schedule".into(),
        StartKind::Coarse => "coarse grid".into(),
        StartKind::Given(g) => format!("given {g}"),
        StartKind::Greedy => "greedy".into(),
        StartKind::GreedyUnconstrained => "greedy (J only)".into(),
        StartKind::LevelSet => "level set".into(),
        StartKind::Random(r) => format!("random {r}"),
    }
}

/// The bounds behind each schedule's recommended tolerances: the certified allocation, or the
/// linearised one where none is certified.
fn recommended_bounds<'a>(r: &'a ScheduleReport, noise: Option<&'a NoiseCounted>) -> &'a [f64] {
    // with noise in the study the recommendation is the allocation with the noise counted
    if let Some(a) = noise.and_then(|n| n.allocation.as_ref()) {
        return a.upper_bounds_rad();
    }
    r.certified()
        .map_or(r.allocation().upper_bounds_rad(), |c| c.upper_bounds_rad())
}

/// With noise in the study: the positions are searched for the table's part alone (with
/// `--time-budget-s` the count, the positions and the dwell are then chosen together, see
/// [`crate::design::budget`]), which the output says; the recommendation then counts the noise
/// ([`CombinedChoice`]).
pub fn noise_note(s: &Study) -> Option<&'static str> {
    s.noise.iter().any(Option::is_some).then_some(
        "the study gives noise: the positions are searched for the table's part alone (dwell times and the noise part are not part of this search; --time-budget-s adds the search of the number of positions, the positions and the dwell together with the noise counted); the designed and the study's schedule are then compared with the noise counted, and the designed one is recommended only if it does not lose",
    )
}

/// With rate steps in the study: they are kept fixed (and written unchanged); the search
/// designs the static positions, and its J values are those of the static positions alone.
pub fn rate_steps_note(s: &Study) -> Option<&'static str> {
    s.has_rate_steps().then_some(
        "the study has rate steps: the search designs the static positions only, and the J values below are those of the static positions alone (end-to-end on the written study answers with its rate steps); the rate steps are kept fixed and written unchanged with --write-study, unless --rates-deg-per-s gives candidate rates: then the pair of a rate and the designed or the study's positions with the least J of the allocation with the rate tolerances is chosen and written",
    )
}

/// The study's and the designed schedule answered for both error sources (table + noise at
/// [`DEFAULT_K_SIGMA`] sigma, the study's timing): the direct allocation with the noise part
/// kept free, and which schedule is recommended. The designed schedule is chosen for the
/// table's part; with noise it must not lose to the study's on the combined answer, else the
/// study's is recommended.
#[derive(Debug)]
#[non_exhaustive]
pub struct CombinedChoice {
    study: NoiseCounted,
    designed: NoiseCounted,
    designed_recommended: bool,
    /// When no table suffices with either schedule at the study's dwell: how each one
    /// stands on the noise alone (`study`, `designed`).
    both_fail: Option<(NoiseStanding, NoiseStanding)>,
}

/// A schedule's noise alone, for the comparison where neither leaves room for a table.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct NoiseStanding {
    /// The largest k sigma / accuracy over the outputs at the study's dwell (above 1: the
    /// noise alone exceeds an accuracy).
    noise_over_accuracy: f64,
    /// The shortest dwell (s) at which some table suffices (`None`: none up to the study's
    /// longest accepted dwell).
    min_dwell_s: Option<f64>,
}

impl NoiseStanding {
    /// The largest k sigma / accuracy over the outputs at the study's dwell.
    #[must_use]
    pub(crate) fn noise_over_accuracy(&self) -> f64 {
        self.noise_over_accuracy
    }

    /// The shortest dwell (s) at which some table suffices.
    #[must_use]
    pub(crate) fn min_dwell_s(&self) -> Option<f64> {
        self.min_dwell_s
    }

    /// Whether `self` is at least as good as `other` on both: the noise part against the
    /// accuracies and the shortest dwell (none counts as infinitely long).
    fn no_worse_than(&self, other: &NoiseStanding) -> bool {
        let dwell = |d: Option<f64>| d.unwrap_or(f64::INFINITY);
        self.noise_over_accuracy <= other.noise_over_accuracy
            && dwell(self.min_dwell_s) <= dwell(other.min_dwell_s)
    }
}

impl CombinedChoice {
    /// The study's schedule with the noise counted.
    #[must_use]
    pub fn study(&self) -> &NoiseCounted {
        &self.study
    }

    /// The designed schedule with the noise counted.
    #[must_use]
    pub fn designed(&self) -> &NoiseCounted {
        &self.designed
    }

    /// Whether the designed schedule is recommended (it does not lose with the noise counted).
    #[must_use]
    pub(crate) fn designed_recommended(&self) -> bool {
        self.designed_recommended
    }

    /// When no table suffices with either schedule: each one's noise alone (`study`,
    /// `designed`).
    #[must_use]
    pub(crate) fn both_fail(&self) -> Option<(NoiseStanding, NoiseStanding)> {
        self.both_fail
    }
}

/// [`NoiseStanding`] of `s` with the positions `positions_deg` (its noise and timing).
fn noise_standing(s: &Study, positions_deg: &[Vec<f64>]) -> Result<Option<NoiseStanding>> {
    let s2 = s
        .with_positions_deg(positions_deg.to_vec())
        .map_err(InputError::from)?;
    let Some(timing) = &s2.timing else {
        return Ok(None);
    };
    let e2e = crate::loaded::simulator(&s2)?;
    let sigma = e2e
        .noise()
        .worst_noise_sigma(&s2.noise, timing)
        .map_err(|e| library(e, &s2))?;
    let noise_over_accuracy = sigma
        .iter()
        .zip(e2e.accuracies())
        .filter_map(|(sg, a)| sg.map(|sg| DEFAULT_K_SIGMA * sg / a))
        .fold(0.0, f64::max);
    let linear = e2e.linearization();
    let min_dwell_s = e2e
        .noise()
        .tradeoff(&crate::end_to_end::tradeoff_inputs(
            &s2,
            &linear,
            &s2.lower_bounds_rad,
            timing,
            DEFAULT_K_SIGMA,
        ))
        .map_err(|e| library(e, &s2))?
        .min_dwell_s();
    Ok(Some(NoiseStanding {
        noise_over_accuracy,
        min_dwell_s,
    }))
}

/// A schedule's direct allocation with the noise part kept free (the tolerances recommended
/// when the study gives noise): `allocation` `None` when no table suffices at the dwell.
#[derive(Debug)]
#[non_exhaustive]
pub struct NoiseCounted {
    allocation: Option<e2e_verify::DirectAllocation>,
    /// Whether it is certified on the exact chain (the table's part proven within each
    /// accuracy less the noise part); else first order only (the reading has no derived
    /// second-order bound, or none leaves room beside the noise).
    certified: bool,
}

impl NoiseCounted {
    /// The allocation with the noise part kept free; `None` when no table suffices.
    #[must_use]
    pub(crate) fn allocation(&self) -> Option<&e2e_verify::DirectAllocation> {
        self.allocation.as_ref()
    }

    /// Whether it is certified on the exact chain, else first order only.
    #[must_use]
    pub fn certified(&self) -> bool {
        self.certified
    }

    /// J, arcmin^-2 (`None`: no table suffices).
    pub(crate) fn objective_arcmin(&self) -> Option<f64> {
        self.allocation
            .as_ref()
            .map(e2e_verify::DirectAllocation::objective_arcmin)
    }
}

/// The direct allocation with the noise part kept free for `s` (its positions and timing),
/// certified on the exact chain where the reading allows (as `end-to-end`'s
/// `direct_with_noise`); `Ok(None)` when the study has no noise or no timing.
pub(crate) fn noise_counted(s: &Study) -> Result<Option<NoiseCounted>> {
    let e2e = crate::loaded::simulator(s)?;
    let Some(budget) = crate::end_to_end::noise_budget(s, &e2e)? else {
        return Ok(None);
    };
    let linear = e2e.linearization();
    let answer = e2e
        .noise()
        .allocate_direct_with_noise(
            &linear,
            &s.lower_bounds_rad,
            &budget,
            DEFAULT_K_SIGMA,
            Some(&e2e_verify::CertifyParams::default()),
        )
        .map_err(|e| library(e, s))?;
    let Ok(allocation) = answer else {
        return Ok(Some(NoiseCounted {
            allocation: None,
            certified: false,
        }));
    };
    // the certified allocation falls back to the first-order one where it cannot certify:
    // the same bounds as the first-order allocation mean it did
    let first_order = e2e
        .noise()
        .allocate_direct_with_noise(&linear, &s.lower_bounds_rad, &budget, DEFAULT_K_SIGMA, None)
        .map_err(|e| library(e, s))?;
    let certified = first_order.is_ok_and(|f| {
        f.upper_bounds_rad()
            .iter()
            .zip(allocation.upper_bounds_rad())
            .any(|(a, b)| a.to_bits() != b.to_bits())
    });
    Ok(Some(NoiseCounted {
        allocation: Some(allocation),
        certified,
    }))
}

/// [`noise_counted`] for `s` with the positions `positions_deg`.
fn combined_objective(s: &Study, positions_deg: &[Vec<f64>]) -> Result<Option<NoiseCounted>> {
    let s2 = s
        .with_positions_deg(positions_deg.to_vec())
        .map_err(InputError::from)?;
    noise_counted(&s2)
}

/// [`CombinedChoice`] of a design, `None` without noise or timing.
fn combined_choice(s: &Study, d: &ScheduleDesign) -> Result<Option<CombinedChoice>> {
    let Some(study) = combined_objective(s, d.study().positions_deg())? else {
        return Ok(None);
    };
    let Some(designed) = combined_objective(s, d.designed().positions_deg())? else {
        return Ok(None);
    };
    let mut both_fail = None;
    let designed_recommended = match (designed.objective_arcmin(), study.objective_arcmin()) {
        (Some(a), Some(b)) => a <= b,
        (Some(_), None) => true,
        (None, Some(_)) => false,
        // neither leaves room for a table at the study's dwell: the designed schedule must
        // not lose on the noise part nor on the shortest dwell at which some table suffices
        (None, None) => {
            match (
                noise_standing(s, d.study().positions_deg())?,
                noise_standing(s, d.designed().positions_deg())?,
            ) {
                (Some(st), Some(de)) => {
                    both_fail = Some((st, de));
                    de.no_worse_than(&st)
                }
                _ => false,
            }
        }
    };
    Ok(Some(CombinedChoice {
        study,
        designed,
        designed_recommended,
        both_fail,
    }))
}

/// One output's worst case under the study's tolerances, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct WithStudyOutputJson {
    /// The linearised worst case, output's unit.
    linear: f64,
    /// The exact chain at the worst vertex, output's unit.
    exact_at_vertex: f64,
    /// The certified bound (`null` when not computed), output's unit.
    certified_bound: Option<f64>,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// The computation's precision, output's unit.
    precision: f64,
    /// The worst position (index into the schedule).
    position: usize,
}

/// The schedule's worst case under the study's tolerances.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct WithStudyJson<'a> {
    /// `certified` or `linearised`: which tolerances.
    tolerances: &'static str,
    /// The errors with no bound.
    unbounded_errors: Vec<&'a str>,
    /// Per output (by name): its worst case, `null` when it is not bounded.
    outputs: BTreeMap<String, Option<WithStudyOutputJson>>,
}

/// A schedule's certified direct allocation.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct CertifiedJson {
    /// J, arcmin^-2.
    objective: f64,
    /// Its bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// Per output (by name): the margin kept for the second-order terms, output's unit.
    second_order_margins: BTreeMap<String, f64>,
}

/// One schedule's answer (`designed`, `study`, `d_optimal`, `random_best`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct ScheduleJson<'a> {
    /// J of the direct allocation, arcmin^-2.
    objective: f64,
    /// The positions, degrees (joint angles per position).
    positions_deg: &'a [Vec<f64>],
    /// Per output (by name): the condition number of its regression.
    condition_numbers: BTreeMap<String, f64>,
    /// The orientation requirement, degrees (`null` per angle when it failed,
    /// `requirement_note`).
    requirement_deg: PerAngle<Option<f64>>,
    /// Why there is no requirement, else `null`.
    requirement_note: Option<String>,
    /// The direct allocation's bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// Whether no error needs a bound.
    no_bound_needed: bool,
    /// log det of the information matrix.
    log_det_information: f64,
    /// The certified direct allocation, `null` when none (`certified_note`).
    certified: Option<CertifiedJson>,
    /// Why there is no certified allocation, else `null`.
    certified_note: Option<&'a str>,
    /// The worst case under the study's tolerances.
    worst_case_with_study_tolerances: WithStudyJson<'a>,
}

fn schedule_json<'a>(s: &'a Study, r: &'a ScheduleReport) -> ScheduleJson<'a> {
    let outputs = s.sensor.outputs();
    let errors = s.turntable.rotation_error_names();
    let by_output = |v: &[f64]| -> BTreeMap<String, f64> {
        outputs
            .iter()
            .zip(v)
            .map(|(o, x)| (o.name.clone(), *x))
            .collect()
    };
    let w = &r.with_study_tolerances();
    ScheduleJson {
        objective: r.allocation().objective_arcmin(),
        positions_deg: r.positions_deg(),
        condition_numbers: by_output(r.condition_numbers()),
        requirement_deg: match &r.requirement() {
            Ok(q) => crate::json::deg3(&q.requirement().to_array()),
            Err(_) => PerAngle::new(|_| None),
        },
        requirement_note: r.requirement().as_ref().err().map(ToString::to_string),
        bounds_arcmin: arcmin_bounds(&errors, r.allocation().upper_bounds_rad()),
        no_bound_needed: r.allocation().no_bound_needed(),
        log_det_information: r.log_det_information(),
        certified: r.certified().map(|c| CertifiedJson {
            objective: c.objective_arcmin(),
            bounds_arcmin: arcmin_bounds(&errors, c.upper_bounds_rad()),
            second_order_margins: by_output(c.second_order_margins()),
        }),
        certified_note: r.certified_note(),
        worst_case_with_study_tolerances: WithStudyJson {
            tolerances: if w.certified() {
                "certified"
            } else {
                "linearised"
            },
            unbounded_errors: w.unbounded().iter().map(|&j| errors[j]).collect(),
            outputs: outputs
                .iter()
                .zip(w.outputs())
                .map(|(out, o)| {
                    (
                        out.name.clone(),
                        o.as_ref().map(|o| WithStudyOutputJson {
                            linear: o.linear_bound(),
                            exact_at_vertex: o.exact_at_vertex(),
                            certified_bound: o.certified_bound(),
                            accuracy: out.accuracy,
                            precision: o.precision(),
                            position: o.position(),
                        }),
                    )
                })
                .collect(),
        },
    }
}

/// With noise and a timing: both schedules answered with the noise counted (`combined`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct CombinedJson {
    /// The confidence multiplier of the noise part.
    k_sigma: f64,
    /// J of the study's schedule with the noise counted, arcmin^-2 (`null`: no table
    /// suffices).
    study_objective_arcmin: Option<f64>,
    /// J of the designed schedule with the noise counted, arcmin^-2 (`null`: no table
    /// suffices).
    designed_objective_arcmin: Option<f64>,
    /// `designed` or `study`: the schedule recommended (and written).
    recommended: &'static str,
    /// The tolerances recommended for the study's schedule with the noise counted, arcmin
    /// (`null`: no table suffices).
    study_bounds_arcmin: Option<ArcminBounds>,
    /// The same for the designed schedule.
    designed_bounds_arcmin: Option<ArcminBounds>,
    /// Whether those are certified on the exact chain (the table's part proven within each
    /// accuracy less the noise part), per schedule: `study`, `designed`.
    certified_on_exact_chain: BTreeMap<&'static str, bool>,
    /// When neither schedule leaves room for a table: each one's noise alone (`study`,
    /// `designed`: `noise_over_accuracy`, `min_dwell_s`); `null` otherwise.
    both_fail: Option<BTreeMap<&'static str, NoiseStanding>>,
}

/// One output of the study.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct OutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
}

/// One restart of the search.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct RestartJson {
    /// Its start, in words.
    start: String,
    /// J of the start, arcmin^-2 (`null` when infeasible and repaired).
    start_objective: Option<f64>,
    /// J after the exchange, arcmin^-2 (`null`: no feasible start).
    objective: Option<f64>,
    /// Exchanges made.
    exchanges: Option<usize>,
    /// Exact evaluations.
    exact_evaluations: Option<usize>,
    /// Swaps screened.
    screened_swaps: Option<usize>,
    /// Swaps not evaluated.
    unevaluated_swaps: Option<usize>,
    /// Whether the exchange ended at a local optimum.
    local_optimum: Option<bool>,
}

/// The design search.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct SearchJson {
    /// The restart that gave the design, in words.
    best_restart: String,
    /// Whether the design is a local optimum of the exchange.
    local_optimum: bool,
    /// Every restart.
    restarts: Vec<RestartJson>,
    /// log det of the D-optimal schedule's information matrix.
    d_optimal_log_det: f64,
    /// Random schedules drawn.
    random_drawn: usize,
    /// Of those, feasible.
    random_feasible: usize,
}

/// `design-schedule --json`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct DesignJson<'a> {
    /// The study's path.
    study_path: &'a str,
    /// The study's reading of eq 13.
    reading: String,
    /// Positions designed for.
    positions: usize,
    /// The candidates' grid step, degrees.
    step_deg: f64,
    /// The condition bound.
    max_condition: f64,
    /// Seed of the random starts.
    seed: u64,
    /// Candidate positions.
    candidates: usize,
    /// Time of the search, s.
    seconds: f64,
    /// The command that reproduces the run.
    command: &'a str,
    /// With rate steps in the study: what is designed; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    rate_steps_note: Option<&'static str>,
    /// With `--rates-deg-per-s`: the rate chosen; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    rates: Option<rates::RatesJson<'a>>,
    /// With noise in the study: how it is counted; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    noise_note: Option<&'static str>,
    /// With noise and a timing: both schedules with the noise counted; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    combined: Option<CombinedJson>,
    /// The study's outputs.
    outputs: Vec<OutputJson<'a>>,
    /// The designed schedule.
    designed: ScheduleJson<'a>,
    /// The study's schedule.
    study: ScheduleJson<'a>,
    /// The D-optimal schedule.
    d_optimal: ScheduleJson<'a>,
    /// The best random schedule, `null` when none was feasible.
    random_best: Option<ScheduleJson<'a>>,
    /// The search.
    search: SearchJson,
    /// Errors that act only together, with their combination's bound under each schedule's
    /// recommended tolerances.
    groups: Vec<GroupJson>,
    /// The study written by `--write-study`, else `null`.
    written_study: Option<&'a str>,
    /// With `--pareto-svg` and an empty front: why no figure was written; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pareto_svg_note: Option<&'a str>,
    /// With `--time-budget-s`: `time_budget` and `pareto` (at the top level); absent
    /// otherwise.
    #[cfg_attr(feature = "serde", serde(flatten))]
    budget: Option<budget::BudgetJson<'a>>,
}

/// The parts of `design-schedule --json` that the command line adds: the command that
/// reproduces the run, the study written, why no figure was written.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunView<'a> {
    /// The command that reproduces the run.
    pub command: &'a str,
    /// The study written by `--write-study`.
    pub written_study: Option<&'a str>,
    /// With `--pareto-svg` and an empty front: why no figure was written.
    pub pareto_svg_note: Option<&'a str>,
}

impl ScheduleAnswer {
    /// The answer's view (`design-schedule --json`) for the study `s` it answers, with the
    /// command line's parts `run`.
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn view<'a>(&'a self, s: &'a Study, run: RunView<'a>) -> impl serde::Serialize + 'a {
        to_json(s, self, run)
    }
}

fn to_json<'a>(s: &'a Study, o: &'a ScheduleAnswer, run: RunView<'a>) -> DesignJson<'a> {
    let d = &o.design;
    let search = &d.search();
    DesignJson {
        study_path: &s.path,
        reading: s.reading.to_string(),
        positions: o.settings.positions,
        step_deg: o.step_deg,
        max_condition: o.settings.max_condition,
        seed: o.settings.seed,
        candidates: o.candidates,
        seconds: o.seconds,
        command: run.command,
        rate_steps_note: rate_steps_note(s),
        rates: o.rates.as_ref().map(rates::RateChoice::view),
        noise_note: noise_note(s),
        combined: o.combined.as_ref().map(|c| CombinedJson {
            k_sigma: DEFAULT_K_SIGMA,
            study_objective_arcmin: c.study.objective_arcmin(),
            designed_objective_arcmin: c.designed.objective_arcmin(),
            study_bounds_arcmin: c
                .study
                .allocation
                .as_ref()
                .map(|a| arcmin_bounds(&s.turntable.rotation_error_names(), a.upper_bounds_rad())),
            designed_bounds_arcmin: c
                .designed
                .allocation
                .as_ref()
                .map(|a| arcmin_bounds(&s.turntable.rotation_error_names(), a.upper_bounds_rad())),
            certified_on_exact_chain: [
                ("study", c.study.certified),
                ("designed", c.designed.certified),
            ]
            .into_iter()
            .collect(),
            recommended: if c.designed_recommended {
                "designed"
            } else {
                "study"
            },
            both_fail: c
                .both_fail
                .map(|(st, de)| [("study", st), ("designed", de)].into_iter().collect()),
        }),
        outputs: s
            .sensor
            .outputs()
            .iter()
            .map(|x| OutputJson {
                name: &x.name,
                unit: &x.unit,
                accuracy: x.accuracy,
            })
            .collect(),
        designed: schedule_json(s, d.designed()),
        study: schedule_json(s, d.study()),
        d_optimal: schedule_json(s, d.d_optimal()),
        random_best: d.random_best().map(|r| schedule_json(s, r)),
        search: SearchJson {
            best_restart: start_name(search.restarts()[search.best_restart()].start()),
            local_optimum: search.designed().stop().local_optimum(),
            restarts: search
                .restarts()
                .iter()
                .map(|r| RestartJson {
                    start: start_name(r.start()),
                    start_objective: r
                        .start_objective()
                        .is_finite()
                        .then(|| objective_to_arcmin(r.start_objective())),
                    objective: r.exchange().map(|e| e.evaluation().objective_arcmin()),
                    exchanges: r.exchange().map(|e| e.stop().exchanges()),
                    exact_evaluations: r.exchange().map(|e| e.exact_evaluations()),
                    screened_swaps: r.exchange().map(|e| e.screened_swaps()),
                    unevaluated_swaps: r.exchange().map(|e| e.unevaluated_swaps()),
                    local_optimum: r.exchange().map(|e| e.stop().local_optimum()),
                })
                .collect(),
            d_optimal_log_det: search.d_optimal().log_det(),
            random_drawn: search.random_drawn(),
            random_feasible: search.random_feasible(),
        },
        groups: GroupJson::all(&s.turntable, &o.group_bounds()),
        written_study: run.written_study,
        pareto_svg_note: run.pareto_svg_note,
        budget: o.budget.as_ref().map(|b| budget::json(s, b)),
    }
}
