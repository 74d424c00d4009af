//! `cargo xtask design-schedule [--study FILE] [--positions N] [--step-deg S]
//! [--max-condition K] [--seed S] [--write-study OUT.toml] [--json]`: the calibration schedule
//! that lets the cheapest turntable meet every output's accuracy.
//!
//! Candidates: the joint-angle grid with step S over the joint ranges (default 15 deg) plus
//! the study's positions. The designed schedule (N positions, default the study's count,
//! minimum direct-allocation objective J under the study's reading, every condition number at
//! most K) is printed beside the study's schedule, the D-optimal schedule and the best of the
//! random schedules, each with J (arcmin^-2, as `end-to-end --json` reports
//! `direct_objective`), the condition numbers, the orientation requirement (eq 15-16) and the
//! worst case of every output with the study's tolerances (the allocation certified on the
//! exact chain for the study's schedule: what one would buy for it), then the tolerances each
//! schedule allows: certified on the exact chain (as `end-to-end`'s `direct_certified`; these
//! pass `check-turntable` on the schedule) and linearised (the design objective J). With noise
//! and a timing in the study the recommended tolerances are the direct allocation with the
//! noise part kept free, certified on the exact chain (as `end-to-end`'s `direct_with_noise`;
//! JSON `combined.designed_bounds_arcmin`, `study_bounds_arcmin`): the table's part proven
//! within each accuracy less the noise part at 3 sigma, which `check-turntable` accepts on
//! the written study with the noise counted; the table-alone certified ones follow, marked as
//! such. The written study's comment describes the positions written (designed, the study's
//! kept, or the budget's choice) and the tolerances recommended for exactly them.
//! `--write-study OUT.toml` writes the input study with the designed positions and a comment
//! saying how they were made (refused if OUT exists or its directory is not writable, both checked before the search;
//! written atomically, mode 0666 less the umask). `--json` prints an
//! object with keys `designed`, `study`, `d_optimal`, `random_best`, each with `objective`,
//! `positions_deg`, `condition_numbers`, `requirement_deg`, `bounds_arcmin` (linearised),
//! `certified` (`objective`, `bounds_arcmin`) and `worst_case_with_study_tolerances`, and
//! `groups` (errors that act only together, with the bound of their combination under the
//! certified allocation of each schedule, the linearised one where none is certified).
//!
//! `--time-budget-s S` (finite, > 0) with noise in the study: the number of positions, the
//! positions and the dwell chosen together with the noise counted
//! ([`schedule_design::design_with_budget`]; total test time = positions x (dwell +
//! move)), JSON `time_budget` (`budget_s`, `k_sigma`, `counts`, `counts_skipped`, `chosen`
//! with its `n_positions`) and `pareto` (list of `{total_s, n_positions, dwell_s, objective_arcmin,
//! origin}`), and `--pareto-svg OUT` the front as a figure (a new file, staged with
//! `--write-study`; an empty front, no table at any dwell, is an answer: no figure, and the
//! text and JSON `pareto_svg_note` say so). With `--write-study` the written study has the chosen point's positions
//! and its one dwell (`calibration.timing.dwell_s`), so `end-to-end` on it answers the
//! chosen J (`direct_with_noise`) and its combined answer. Without noise the budget only
//! changes the dwell: `time_budget.note` says so and the answer is unchanged.

use crate::InputError;
use crate::json::{ArcminBounds, GroupJson, PerAngle, arcmin_bounds};
use anyhow::Result;
use clap::Parser;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use schedule_design::{
    DEFAULT_MAX_CONDITION, DEFAULT_STEP_DEG, DesignInputs, DesignSettings, ScheduleDesign,
    ScheduleReport, StartKind, coarse_levels, design_on_grid,
};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;
use study::Study;
use study::fmt::{num, sig};
use tt_core::units::objective_to_arcmin;
use tt_core::units::rad_to_arcmin;

/// Arguments of `design-schedule`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// Number of test positions N (default: the study's).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::positions)]
    pub positions: Option<u64>,
    /// Grid step of the candidate joint angles, deg, in (0, 360].
    #[arg(long, allow_negative_numbers = true, default_value_t = DEFAULT_STEP_DEG, value_parser = step)]
    pub step_deg: f64,
    /// Largest condition number allowed for any output's regression, in [1, 1e12].
    #[arg(long, allow_negative_numbers = true, default_value_t = DEFAULT_MAX_CONDITION, value_parser = condition)]
    pub max_condition: f64,
    /// Seed of the restarts and of the random baseline (default: the study's).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// Write the study with the designed positions to this new file (never overwritten).
    #[arg(long)]
    pub write_study: Option<PathBuf>,
    /// Total test-time budget (s, finite, > 0): choose the positions and the dwell together
    /// with the noise counted, and report the Pareto front of test time against J.
    #[arg(long, allow_negative_numbers = true, value_parser = budget)]
    pub time_budget_s: Option<f64>,
    /// Write the Pareto front of `--time-budget-s` as an SVG figure to this new file.
    #[arg(long)]
    pub pareto_svg: Option<PathBuf>,
    /// Candidate rates (deg/s, > 0, comma-separated) for the study's rate steps: the rate with
    /// the least J of the allocation with the rate tolerances, at the designed positions, is
    /// chosen (and written by `--write-study`; each step keeps its sign).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = crate::design_rates::rate)]
    pub rates_deg_per_s: Option<Vec<f64>>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The largest `--time-budget-s` (s): about 32 years.
const MAX_BUDGET_S: f64 = 1e9;

fn budget(s: &str) -> Result<f64, String> {
    crate::args::positive(s, MAX_BUDGET_S)
}

fn step(s: &str) -> Result<f64, String> {
    crate::args::positive(s, 360.0)
}

fn condition(s: &str) -> Result<f64, String> {
    crate::args::number_in(s, 1.0, 1e12, "a condition number")
}

fn progress_bar(units: u64) -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = ProgressBar::with_draw_target(Some(units), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:40} {pos}/{len} restarts and baseline schedules, {elapsed}",
    ) {
        pb.set_style(style);
    }
    Some(pb)
}

/// Everything the command prints, computed.
struct Outcome {
    design: ScheduleDesign,
    /// With noise and a timing in the study: both schedules answered for both error sources.
    combined: Option<CombinedChoice>,
    /// With `--time-budget-s`: positions and dwell chosen together.
    budget: Option<crate::design_budget::Budgeted>,
    settings: DesignSettings,
    candidates: usize,
    step_deg: f64,
    seconds: f64,
    command: String,
    written: Option<String>,
    /// With `--pareto-svg` and an empty front: why no figure was written.
    pareto_svg_note: Option<String>,
    /// With `--rates-deg-per-s`: the rate chosen among the candidates.
    rates: Option<crate::design_rates::RateChoice>,
}

/// One output's worst case under the study's tolerances, output's unit.
#[derive(Debug, Serialize)]
struct WithStudyOutputJson {
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
#[derive(Debug, Serialize)]
struct WithStudyJson<'a> {
    /// `certified` or `linearised`: which tolerances.
    tolerances: &'static str,
    /// The errors with no bound.
    unbounded_errors: Vec<&'a str>,
    /// Per output (by name): its worst case, `null` when it is not bounded.
    outputs: BTreeMap<String, Option<WithStudyOutputJson>>,
}

/// A schedule's certified direct allocation.
#[derive(Debug, Serialize)]
struct CertifiedJson {
    /// J, arcmin^-2.
    objective: f64,
    /// Its bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// Per output (by name): the margin kept for the second-order terms, output's unit.
    second_order_margins: BTreeMap<String, f64>,
}

/// One schedule's answer (`designed`, `study`, `d_optimal`, `random_best`).
#[derive(Debug, Serialize)]
struct ScheduleJson<'a> {
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

fn start_name(k: StartKind) -> String {
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

/// The designed and the study's allocations by label, for the groups of errors that act only
/// together.
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

fn group_bounds(o: &Outcome) -> [(&'static str, &[f64]); 2] {
    let c = o.combined.as_ref();
    [
        (
            "designed",
            recommended_bounds(o.design.designed(), c.map(|c| &c.designed)),
        ),
        (
            "study's",
            recommended_bounds(o.design.study(), c.map(|c| &c.study)),
        ),
    ]
}

/// With noise in the study: the positions are searched for the table's part alone (with
/// `--time-budget-s` the count, the positions and the dwell are then chosen together, see
/// [`crate::design_budget`]), which the output says; the recommendation then counts the noise
/// ([`CombinedChoice`]).
fn noise_note(s: &Study) -> Option<&'static str> {
    s.noise.iter().any(Option::is_some).then_some(
        "the study gives noise: the positions are searched for the table's part alone (dwell times and the noise part are not part of this search; --time-budget-s adds the search of the number of positions, the positions and the dwell together with the noise counted); the designed and the study's schedule are then compared with the noise counted, and the designed one is recommended only if it does not lose",
    )
}

/// With rate steps in the study: they are kept fixed (and written unchanged); the search
/// designs the static positions, and its J values are those of the static positions alone.
fn rate_steps_note(s: &Study) -> Option<&'static str> {
    s.has_rate_steps().then_some(
        "the study has rate steps: the search designs the static positions only, and the J values below are those of the static positions alone (end-to-end on the written study answers with its rate steps); the rate steps are kept fixed and written unchanged with --write-study, unless --rates-deg-per-s gives candidate rates: then the pair of a rate and the designed or the study's positions with the least J of the allocation with the rate tolerances is chosen and written",
    )
}

/// The study's and the designed schedule answered for both error sources (table + noise at
/// [`DEFAULT_K_SIGMA`] sigma, the study's timing): the direct allocation with the noise part
/// kept free, and which schedule is recommended. The designed schedule is chosen for the
/// table's part; with noise it must not lose to the study's on the combined answer, else the
/// study's is recommended.
struct CombinedChoice {
    study: NoiseCounted,
    designed: NoiseCounted,
    designed_recommended: bool,
    /// When no table suffices with either schedule at the study's dwell: how each one
    /// stands on the noise alone (`study`, `designed`).
    both_fail: Option<(NoiseStanding, NoiseStanding)>,
}

/// A schedule's noise alone, for the comparison where neither leaves room for a table.
#[derive(Debug, Clone, Copy, Serialize)]
pub(crate) struct NoiseStanding {
    /// The largest k sigma / accuracy over the outputs at the study's dwell (above 1: the
    /// noise alone exceeds an accuracy).
    noise_over_accuracy: f64,
    /// The shortest dwell (s) at which some table suffices (`None`: none up to the study's
    /// longest accepted dwell).
    min_dwell_s: Option<f64>,
}

impl NoiseStanding {
    /// Whether `self` is at least as good as `other` on both: the noise part against the
    /// accuracies and the shortest dwell (none counts as infinitely long).
    fn no_worse_than(&self, other: &NoiseStanding) -> bool {
        let dwell = |d: Option<f64>| d.unwrap_or(f64::INFINITY);
        self.noise_over_accuracy <= other.noise_over_accuracy
            && dwell(self.min_dwell_s) <= dwell(other.min_dwell_s)
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
    let e2e = crate::end_to_end::simulator(&s2)?;
    let sigma = e2e
        .worst_noise_sigma(&s2.noise, timing)
        .map_err(|e| crate::input::library(e, &s2))?;
    let noise_over_accuracy = sigma
        .iter()
        .zip(e2e.accuracies())
        .filter_map(|(sg, a)| sg.map(|sg| DEFAULT_K_SIGMA * sg / a))
        .fold(0.0, f64::max);
    let min_dwell_s = e2e
        .tradeoff(
            &e2e.linearization(),
            &s2.lower_bounds_rad,
            &s2.noise,
            timing,
            DEFAULT_K_SIGMA,
            crate::end_to_end::DWELL_SEARCH_S,
        )
        .map_err(|e| crate::input::library(e, &s2))?
        .min_dwell_s();
    Ok(Some(NoiseStanding {
        noise_over_accuracy,
        min_dwell_s,
    }))
}

/// A schedule's direct allocation with the noise part kept free (the tolerances recommended
/// when the study gives noise): `allocation` `None` when no table suffices at the dwell.
pub(crate) struct NoiseCounted {
    allocation: Option<e2e_verify::DirectAllocation>,
    /// Whether it is certified on the exact chain (the table's part proven within each
    /// accuracy less the noise part); else first order only (the reading has no derived
    /// second-order bound, or none leaves room beside the noise).
    certified: bool,
}

impl NoiseCounted {
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
    let e2e = crate::end_to_end::simulator(s)?;
    let Some(budget) = crate::noise::budget(s, &e2e)? else {
        return Ok(None);
    };
    let linear = e2e.linearization();
    let answer = e2e
        .allocate_direct_with_noise_certified(
            &linear,
            &s.lower_bounds_rad,
            &budget,
            DEFAULT_K_SIGMA,
        )
        .map_err(|e| crate::input::library(e, s))?;
    let Ok(allocation) = answer else {
        return Ok(Some(NoiseCounted {
            allocation: None,
            certified: false,
        }));
    };
    // the certified allocation falls back to the first-order one where it cannot certify:
    // the same bounds as the first-order allocation mean it did
    let first_order = e2e
        .allocate_direct_with_noise(&linear, &s.lower_bounds_rad, &budget, DEFAULT_K_SIGMA)
        .map_err(|e| crate::input::library(e, s))?;
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

/// The combined comparison in words.
fn combined_text(c: &CombinedChoice) -> String {
    let j = |v: Option<f64>| {
        v.map_or("no table suffices".to_string(), |v| {
            format!("J = {}", num(v))
        })
    };
    let standing = c.both_fail.map_or(String::new(), |(st, de)| {
        let dwell = |d: Option<f64>| {
            d.map_or("none up to the longest accepted dwell".to_string(), |d| {
                format!("{} s", num(d))
            })
        };
        format!(
            " (neither leaves room for a table at the study's dwell: largest noise part / accuracy {} for the study's schedule, {} designed; shortest dwell at which some table suffices {} for the study's, {} designed)",
            num(st.noise_over_accuracy),
            num(de.noise_over_accuracy),
            dwell(st.min_dwell_s),
            dwell(de.min_dwell_s)
        )
    });
    format!(
        "with the noise counted ({} sigma, the study's timing; certified direct allocation with the noise part kept free): study's schedule {}, designed {}{standing}: {}\n",
        num(DEFAULT_K_SIGMA),
        j(c.study.objective_arcmin()),
        j(c.designed.objective_arcmin()),
        if c.designed_recommended {
            "the designed schedule does not lose on the combined answer"
        } else {
            "the designed schedule LOSES on the combined answer; keep the study's schedule (it is the one recommended and written)"
        }
    )
}

/// With noise and a timing: both schedules answered with the noise counted (`combined`).
#[derive(Debug, Serialize)]
struct CombinedJson {
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
#[derive(Debug, Serialize)]
struct OutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
}

/// One restart of the search.
#[derive(Debug, Serialize)]
struct RestartJson {
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
#[derive(Debug, Serialize)]
struct SearchJson {
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
#[derive(Debug, Serialize)]
struct DesignJson<'a> {
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
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_steps_note: Option<&'static str>,
    /// With `--rates-deg-per-s`: the rate chosen; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    rates: Option<tt_lab::design::rates::RatesJson<'a>>,
    /// With noise in the study: how it is counted; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    noise_note: Option<&'static str>,
    /// With noise and a timing: both schedules with the noise counted; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
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
    #[serde(skip_serializing_if = "Option::is_none")]
    pareto_svg_note: Option<&'a str>,
    /// With `--time-budget-s`: `time_budget` and `pareto` (at the top level); absent
    /// otherwise.
    #[serde(flatten)]
    budget: Option<crate::design_budget::BudgetJson<'a>>,
}

fn to_json<'a>(s: &'a Study, o: &'a Outcome) -> DesignJson<'a> {
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
        command: &o.command,
        rate_steps_note: rate_steps_note(s),
        rates: o
            .rates
            .as_ref()
            .map(tt_lab::design::rates::RateChoice::view),
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
            local_optimum: search.designed().local_optimum(),
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
                    exchanges: r.exchange().map(|e| e.exchanges()),
                    exact_evaluations: r.exchange().map(|e| e.exact_evaluations()),
                    screened_swaps: r.exchange().map(|e| e.screened_swaps()),
                    unevaluated_swaps: r.exchange().map(|e| e.unevaluated_swaps()),
                    local_optimum: r.exchange().map(|e| e.local_optimum()),
                })
                .collect(),
            d_optimal_log_det: search.d_optimal().log_det(),
            random_drawn: search.random_drawn(),
            random_feasible: search.random_feasible(),
        },
        groups: GroupJson::all(&s.turntable, &group_bounds(o)),
        written_study: o.written.as_deref(),
        pareto_svg_note: o.pareto_svg_note.as_deref(),
        budget: o.budget.as_ref().map(crate::design_budget::json),
    }
}

/// A schedule's condition numbers by output, for the written study's comment.
fn condition_list(s: &Study, r: &ScheduleReport) -> String {
    s.sensor
        .outputs()
        .iter()
        .zip(r.condition_numbers())
        .map(|(o, c)| format!("{} {}", o.name, num(*c)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `v` rounded down to `digits` significant digits, printed: a tolerance read back from the
/// text is never looser than the one computed.
fn sig_down(v: f64, digits: usize) -> String {
    if !(v.is_finite() && v > 0.0) {
        return sig(v, digits);
    }
    let scale = 10f64.powi(digits as i32 - 1 - v.log10().floor() as i32);
    let mut m = (v * scale).floor();
    loop {
        let shown = sig(m / scale, digits);
        if m <= 0.0 || shown.parse::<f64>().is_ok_and(|x| x <= v) {
            return shown;
        }
        m -= 1.0;
    }
}

/// `ub` (rad) by error name in arcmin, `shown` formatting each finite bound; `free` where
/// there is none.
fn bound_list(s: &Study, ub: &[f64], shown: &dyn Fn(f64) -> String) -> String {
    s.turntable
        .rotation_error_names()
        .iter()
        .zip(ub)
        .map(|(n, u)| {
            format!(
                "{n} {}",
                if u.is_finite() {
                    shown(rad_to_arcmin(*u))
                } else {
                    "free".into()
                }
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The tolerances recommended with the noise counted (`n`) in words: what is proven (the
/// table's part, on the exact chain) and what the noise adds; `None` for the bounds when no
/// table suffices.
fn noise_counted_words(n: &NoiseCounted) -> (String, Option<&[f64]>) {
    let k = num(DEFAULT_K_SIGMA);
    match &n.allocation {
        None => (
            format!(
                "with the noise counted ({k} sigma, the study's timing): none: no table suffices at the study's dwell (the noise part alone fills an accuracy)"
            ),
            None,
        ),
        Some(a) if n.certified => (
            format!(
                "with the noise counted ({k} sigma, the study's timing), certified on the exact chain (J = {}; rounded down): every turntable within them is proven to stay within each accuracy less the noise part ({k} sigma of the calibration's noise, a statistical bound, not a proof), so table and noise together meet every accuracy at {k} sigma, as `check-turntable` on the written study finds",
                sig(a.objective_arcmin(), 6)
            ),
            Some(a.upper_bounds_rad()),
        ),
        Some(a) => (
            format!(
                "with the noise counted ({k} sigma, the study's timing), first order only (J = {}; rounded down; not certifiable on the exact chain for this reading): the table's part within each accuracy less the noise part ({k} sigma) to first order, not proven",
                sig(a.objective_arcmin(), 6)
            ),
            Some(a.upper_bounds_rad()),
        ),
    }
}

/// The tolerances a schedule allows (arcmin), the one to buy first (rounded down): with noise
/// in the study (`noise`) the allocation with the noise counted, then the table's part alone;
/// else the certified allocation; then the linearised direct allocation (the design
/// objective, not proven on the exact chain).
fn tolerance_lines(
    s: &Study,
    what: &str,
    r: &ScheduleReport,
    noise: Option<&NoiseCounted>,
) -> String {
    let down = |v: f64| sig_down(v, 3);
    let mut t = String::new();
    if let Some(n) = noise {
        let (words, ub) = noise_counted_words(n);
        t.push_str(&format!(
            "tolerances (arcmin) the {what} schedule allows {words}{}\n",
            ub.map_or(String::new(), |ub| format!(
                ": {}",
                bound_list(s, ub, &down)
            ))
        ));
    }
    let lead = if noise.is_some() {
        "  the table's part alone (noise not counted: a turntable within these can miss once the noise is counted),".to_string()
    } else {
        format!("tolerances (arcmin) the {what} schedule allows,")
    };
    t.push_str(&match &r.certified() {
        Some(c) => format!(
            "{lead} certified on the exact chain (J = {}; rounded down{}): {}\n",
            sig(c.objective_arcmin(), 6),
            if noise.is_some() {
                ""
            } else {
                "; every turntable within them meets every accuracy: `check-turntable` proves them"
            },
            bound_list(s, c.upper_bounds_rad(), &down)
        ),
        None => format!(
            "{lead} certified on the exact chain: none ({})\n",
            r.certified_note().unwrap_or("not certifiable")
        ),
    });
    t.push_str(&format!(
        "  linearised (J = {}, the design objective; not proven on the exact chain): {}\n",
        sig(r.allocation().objective_arcmin(), 6),
        bound_list(s, r.allocation().upper_bounds_rad(), &|v| sig(v, 3))
    ));
    t
}

/// What the "worst case with the study's tolerances" column is, and the precision of any 0.
fn study_tolerances_note(s: &Study, d: &ScheduleDesign) -> String {
    let outputs = s.sensor.outputs();
    let errs = s.turntable.rotation_error_names();
    let w = &d.study().with_study_tolerances();
    let mut t = format!(
        "  worst case with the study's tolerances: per output, on the exact chain at the worst vertex, over the tolerances {} for the study's schedule (what one would buy for it)",
        if w.certified() {
            "certified on the exact chain"
        } else {
            "of the linearised direct allocation (not certifiable here)"
        }
    );
    let mut unbounded: Vec<usize> = Vec::new();
    let mut zeroed: Vec<(&str, &str, f64)> = Vec::new();
    for r in [
        Some(d.designed()),
        Some(d.study()),
        Some(d.d_optimal()),
        d.random_best(),
    ]
    .into_iter()
    .flatten()
    {
        for &j in r.with_study_tolerances().unbounded() {
            if !unbounded.contains(&j) {
                unbounded.push(j);
            }
        }
        for (k, o) in r.with_study_tolerances().outputs().iter().enumerate() {
            if let Some(o) = o {
                if o.exact_at_vertex() == 0.0 && !zeroed.iter().any(|z| z.0 == outputs[k].name) {
                    zeroed.push((&outputs[k].name, &outputs[k].unit, o.precision()));
                }
            }
        }
    }
    if !unbounded.is_empty() {
        unbounded.sort_unstable();
        t.push_str(&format!(
            "; unbounded: the output depends on {}, which those tolerances leave free (the study's schedule needs no bound there)",
            unbounded.iter().map(|&j| errs[j]).collect::<Vec<_>>().join(", ")
        ));
    }
    if let Some(n) = crate::out::precision_note(&zeroed) {
        t.push_str(&format!("; {n}"));
    }
    t.push('\n');
    t
}

fn to_text(s: &Study, o: &Outcome) -> String {
    let d = &o.design;
    let outputs = s.sensor.outputs();
    let names = outputs
        .iter()
        .map(|x| x.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let mut t = format!(
        "design-schedule: study {} ({}), reading {}\n  {} candidates ({} deg grid over {}, and the study's positions), {} positions, condition numbers <= {}, seed {}\n\n",
        s.name,
        s.path,
        s.reading,
        o.candidates,
        num(o.step_deg),
        s.turntable.joint_names().join(", "),
        o.settings.positions,
        num(o.settings.max_condition),
        o.settings.seed
    );
    if let Some(n) = rate_steps_note(s) {
        t.push_str(&format!("note: {n}\n"));
    }
    if let Some(r) = &o.rates {
        t.push_str(&crate::design_rates::text(r));
    }
    if let Some(n) = noise_note(s) {
        t.push_str(&format!("note: {n}\n"));
        if let Some(c) = &o.combined {
            t.push_str(&combined_text(c));
        }
        t.push('\n');
    }
    if let Some(b) = &o.budget {
        t.push_str(&crate::design_budget::text(s, b));
    }
    let study_j = d.study().allocation().objective_arcmin();
    let head = [
        "schedule",
        "J (arcmin^-2)",
        "vs study",
        "condition numbers",
        "requirement psi/theta/gamma (deg)",
        "worst case with the study's tolerances",
    ];
    t.push_str(&format!(
        "{:<12} {:>13} {:>8}  {:<22} {:<34} {}\n",
        head[0], head[1], head[2], head[3], head[4], head[5]
    ));
    let line = |label: &str, r: &ScheduleReport| -> String {
        let req = match &r.requirement() {
            Ok(q) => q
                .requirement()
                .deg()
                .iter()
                .map(|v| v.map_or("-".into(), |x| sig(x, 3)))
                .collect::<Vec<_>>()
                .join(" / "),
            Err(_) => "none".into(),
        };
        let wc = r
            .with_study_tolerances()
            .outputs()
            .iter()
            .map(|x| {
                x.as_ref()
                    .map_or("unbounded".into(), |x| sig(x.exact_at_vertex(), 3))
            })
            .collect::<Vec<_>>()
            .join(", ");
        let j = r.allocation().objective_arcmin();
        let cond = r
            .condition_numbers()
            .iter()
            .map(|c| sig(*c, 3))
            .collect::<Vec<_>>()
            .join(", ");
        // J of a schedule whose errors need no bound is 0: no ratio then
        let vs = if study_j > 0.0 {
            sig(j / study_j, 3)
        } else {
            "-".into()
        };
        format!(
            "{label:<12} {:>13} {vs:>8}  {cond:<22} {req:<34} {wc}\n",
            sig(j, 6)
        )
    };
    t.push_str(&line("designed", d.designed()));
    t.push_str(&line("study", d.study()));
    t.push_str(&line("D-optimal", d.d_optimal()));
    match &d.random_best() {
        Some(r) => t.push_str(&line("random best", r)),
        None => t.push_str("random best  none of the random schedules meets the condition bound\n"),
    }
    t.push_str(&format!(
        "  outputs {names}; accuracies {}; random best: best of {} random schedules ({} meet the condition bound)\n",
        outputs.iter().map(|x| format!("{} {}", num(x.accuracy), x.unit)).collect::<Vec<_>>().join(", "),
        d.search().random_drawn(),
        d.search().random_feasible()
    ));
    if d.designed().allocation().no_bound_needed() {
        t.push_str(&format!(
            "  the designed schedule: {}\n",
            e2e_verify::NO_BOUND_NEEDED
        ));
    }
    t.push_str(&study_tolerances_note(s, d));
    t.push('\n');
    let c = o.combined.as_ref();
    for (what, r, n) in [
        ("designed", &d.designed(), c.map(|c| &c.designed)),
        ("study's", &d.study(), c.map(|c| &c.study)),
    ] {
        t.push_str(&tolerance_lines(s, what, r, n));
    }
    t.push_str(&crate::groups::text(&s.turntable, &group_bounds(o), ""));
    t.push_str(&format!(
        "\ndesigned positions [{}] deg:\n",
        s.turntable.joint_names().join(", ")
    ));
    for chunk in d.designed().positions_deg().chunks(8) {
        let row: Vec<String> = chunk
            .iter()
            .map(|p| {
                format!(
                    "[{}]",
                    p.iter().map(|a| num(*a)).collect::<Vec<_>>().join(", ")
                )
            })
            .collect();
        t.push_str(&format!("  {}\n", row.join(", ")));
    }
    let search = &d.search();
    t.push_str(&format!(
        "\nsearch: {} restarts, best from {}; {}; {:.1} s\n",
        search.restarts().len(),
        start_name(search.restarts()[search.best_restart()].start()),
        if search.designed().local_optimum() {
            "no single exchange of a position for a candidate improves J (a local optimum, not proven global)"
        } else {
            "stopped before proving local optimality"
        },
        o.seconds
    ));
    if let Some(w) = &o.written {
        t.push_str(&format!("wrote {w}\n"));
    }
    if let Some(n) = &o.pareto_svg_note {
        t.push_str(&format!("{n}\n"));
    }
    t
}

/// Run the command.
///
/// # Errors
/// [`InputError`] for bad inputs (exit 2, nothing on standard output); other errors if a
/// solver fails.
pub fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    if let Some(rates) = &args.rates_deg_per_s {
        crate::design_rates::check(&s, rates)?;
    }
    if args.pareto_svg.is_some() && args.time_budget_s.is_none() {
        return Err(
            InputError::new("--pareto-svg", "the Pareto front needs --time-budget-s").into(),
        );
    }
    let outputs: Vec<(&str, &std::path::Path)> = [
        ("--write-study", args.write_study.as_deref()),
        ("--pareto-svg", args.pareto_svg.as_deref()),
    ]
    .into_iter()
    .filter_map(|(f, p)| p.map(|p| (f, p)))
    .collect();
    crate::newfile::check_all(&outputs)?;
    if let Some(b) = args.time_budget_s {
        crate::design_budget::check_affords(&s, b)?;
    }
    let positions = args.positions.map_or(s.positions_deg.len(), |n| n as usize);
    let seed = args.seed.unwrap_or(s.monte_carlo.seed);
    let mut settings = DesignSettings::new(positions, seed);
    settings.max_condition = args.max_condition;
    let pb = progress_bar(settings.work_units() + coarse_levels(args.step_deg));
    let tick = || {
        if let Some(pb) = &pb {
            pb.inc(1);
        }
    };
    let inputs = DesignInputs {
        turntable: &s.turntable,
        sensor: &s.sensor,
        site: &s.site,
        reading: s.reading,
        delta_r_kind: s.delta_r_kind,
        lower_bounds_rad: &s.lower_bounds_rad,
        study_positions_deg: &s.positions_deg,
    };
    let t0 = Instant::now();
    let (problem, design) = design_on_grid(&inputs, args.step_deg, &settings, &tick)
        .map_err(|e| crate::input::library(e, &s))?;
    let seconds = t0.elapsed().as_secs_f64();
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    // the report's J comes from the same path as `end-to-end`; the search's must agree
    let searched = design.search().designed().evaluation().objective();
    let reported = design.designed().allocation().objective();
    let agree = (searched - reported).abs() <= 1e-9 * reported;
    if !agree {
        anyhow::bail!(
            "internal: the search's J {searched} and the end-to-end path's {reported} differ"
        );
    }
    let combined = combined_choice(&s, &design)?;
    let keep_study = combined.as_ref().is_some_and(|c| !c.designed_recommended);
    let rates = match &args.rates_deg_per_s {
        Some(r) => Some(crate::design_rates::choose(
            &s,
            if keep_study {
                design.study().positions_deg()
            } else {
                design.designed().positions_deg()
            },
            r,
        )?),
        None => None,
    };
    let budget = args
        .time_budget_s
        .map(|b| {
            crate::design_budget::run(
                &s,
                &problem,
                design.search().designed().evaluation().schedule(),
                design.search().d_optimal().schedule(),
                args.max_condition,
                b,
            )
        })
        .transpose()?;
    // an empty front is an answer: no figure, and the output says so
    let mut pareto_svg_note = None;
    let svg = match (&args.pareto_svg, &budget) {
        (Some(out), Some(crate::design_budget::Budgeted::Design(d))) => {
            let figure = crate::design_budget::svg(d)?;
            if figure.is_none() {
                pareto_svg_note = Some(format!(
                    "--pareto-svg {}: {}",
                    out.display(),
                    crate::design_budget::EMPTY_FRONT_NOTE
                ));
            }
            figure.map(|text| (out, text))
        }
        (Some(_), Some(crate::design_budget::Budgeted::Noiseless { .. })) => {
            return Err(InputError::new(
                "--pareto-svg",
                "the study gives no noise: there is no trade-off of test time against the table to draw",
            )
            .into());
        }
        _ => None,
    };
    let mut command = format!(
        "cargo xtask design-schedule --study {} --positions {} --step-deg {} --max-condition {} --seed {}",
        crate::paths::shell_quote(&crate::paths::shown(args.study.as_deref())),
        positions,
        num(args.step_deg),
        num(args.max_condition),
        seed
    );
    if let Some(b) = args.time_budget_s {
        command.push_str(&format!(" --time-budget-s {}", study::fmt::exact(b)));
    }
    if let Some(r) = &args.rates_deg_per_s {
        let list: Vec<String> = r.iter().map(|v| study::fmt::exact(*v)).collect();
        command.push_str(&format!(
            " {} {}",
            crate::design_rates::FLAG,
            list.join(",")
        ));
    }
    let written = match &args.write_study {
        Some(out) => {
            let rate_keeps_study = rates
                .as_ref()
                .is_some_and(|r| r.chosen().is_some() && r.chosen_study_positions());
            // with a time budget and noise: the count, positions and dwell it chose
            let chosen = match &budget {
                Some(crate::design_budget::Budgeted::Design(d)) => d.chosen().map(|p| (d, p)),
                _ => None,
            };
            let study_kept = keep_study || rate_keeps_study;
            // the comment describes what is written: which positions, their J and the
            // tolerances recommended for exactly them (with the noise counted when the
            // study gives noise)
            let (positions, which, counted): (&[Vec<f64>], String, Option<&NoiseCounted>) =
                match chosen {
                    Some((d, p)) => (
                        p.positions_deg(),
                        crate::design_budget::chosen_comment(d, p),
                        d.chosen_counted.as_ref(),
                    ),
                    None if study_kept => (
                        design.study().positions_deg(),
                        format!(
                            "The study's own positions are kept ({}): J = {} arcmin^-2 (direct allocation, table alone, reading {}; designed: {}), condition numbers {}.",
                            if keep_study {
                                "the designed ones lose once the noise is counted"
                            } else {
                                "with the chosen rate they give the least J"
                            },
                            num(design.study().allocation().objective_arcmin()),
                            s.reading,
                            num(design.designed().allocation().objective_arcmin()),
                            condition_list(&s, design.study())
                        ),
                        combined.as_ref().map(|c| &c.study),
                    ),
                    None => (
                        design.designed().positions_deg(),
                        format!(
                            "Designed positions: J = {} arcmin^-2 (direct allocation, table alone, reading {}; the study's schedule: {}, D-optimal: {}),\ncondition numbers {}, best of {} restarts over {} candidates.",
                            num(design.designed().allocation().objective_arcmin()),
                            s.reading,
                            num(design.study().allocation().objective_arcmin()),
                            num(design.d_optimal().allocation().objective_arcmin()),
                            condition_list(&s, design.designed()),
                            design.search().restarts().len(),
                            problem.n_candidates()
                        ),
                        combined.as_ref().map(|c| &c.designed),
                    ),
                };
            let tolerances = match counted {
                Some(n) => {
                    let (words, ub) = noise_counted_words(n);
                    format!(
                        "Tolerances for these positions (arcmin) {}{}.",
                        words.replacen("the study's timing", "this file's timing", 1),
                        ub.map_or(String::new(), |ub| format!(
                            ":\n{}",
                            bound_list(&s, ub, &|v| sig_down(v, 3))
                        ))
                    )
                }
                None => {
                    let r = if study_kept {
                        design.study()
                    } else {
                        design.designed()
                    };
                    match r.certified() {
                        Some(c) => format!(
                            "Tolerances certified on the exact chain for these positions (arcmin, rounded down; every turntable within them meets every accuracy: `check-turntable` proves them):\n{}.",
                            bound_list(&s, c.upper_bounds_rad(), &|v| sig_down(v, 3))
                        ),
                        None => format!(
                            "Tolerances certified on the exact chain for these positions: none ({}).",
                            r.certified_note().unwrap_or("not certifiable")
                        ),
                    }
                }
            };
            let mut comment = format!(
                "The positions below replace the schedule described above. Made by\n`{command}`.\n{which}\n{tolerances}"
            );
            if let (Some(c), None) = (&combined, chosen) {
                comment.push('\n');
                comment.push_str(combined_text(c).trim_end());
            }
            if let Some(r) = &rates {
                comment.push('\n');
                comment.push_str(crate::design_rates::text(r).trim());
            }
            if let Some(crate::design_budget::Budgeted::Design(d)) = &budget {
                if d.chosen().is_none() {
                    comment.push_str(&format!(
                        "\nWith --time-budget-s {}: no table suffices within the budget (the noise fills an accuracy),\nso the positions below are those chosen without the budget, and the study's dwell is kept.",
                        num(d.budget_s())
                    ));
                }
            }
            let chosen = chosen.map(|(_, p)| p);
            let text = match chosen {
                Some(p) => s.text_with_dwell(positions, p.dwell_s(), &comment),
                None => s.text_with_positions(positions, &comment),
            }
            .map_err(InputError::from)?;
            let text = match rates
                .as_ref()
                .and_then(tt_lab::design::rates::RateChoice::chosen)
            {
                Some((rate, _)) => crate::design_rates::text_with_rate(&s, &text, rate)?,
                None => text,
            };
            let shown = out.display().to_string();
            let back = Study::parse(&shown, &text)
                .map_err(|e| anyhow::anyhow!("internal: the written study does not parse: {e}"))?;
            if back.positions_deg.as_slice() != positions {
                anyhow::bail!(
                    "internal: the written study's positions differ from the designed ones"
                );
            }
            if let Some(p) = chosen {
                let dwells = back.timing.as_ref().map(calib_lsq::Timing::dwell_s);
                if !dwells.is_some_and(|d| d.iter().all(|t| t.to_bits() == p.dwell_s().to_bits())) {
                    anyhow::bail!(
                        "internal: the written study's dwell differs from the chosen {} s",
                        p.dwell_s()
                    );
                }
            }
            Some((shown, crate::newfile::stage(out, text.as_bytes())?))
        }
        None => None,
    };
    // both files staged before either is linked into place
    let svg = svg
        .map(|(out, text)| crate::newfile::stage(out, text.as_bytes()))
        .transpose()?;
    let written = match written {
        Some((shown, staged)) => {
            staged.commit("--write-study")?;
            Some(shown)
        }
        None => None,
    };
    if let Some(staged) = svg {
        staged.commit("--pareto-svg")?;
    }
    let outcome = Outcome {
        design,
        combined,
        budget,
        settings,
        candidates: problem.n_candidates(),
        step_deg: args.step_deg,
        seconds,
        command,
        written,
        pareto_svg_note,
        rates,
    };
    if args.json {
        crate::json::print(&to_json(&s, &outcome))
    } else {
        crate::out::print(&to_text(&s, &outcome))
    }
}
