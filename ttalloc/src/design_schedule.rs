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
//! origin, bounds_arcmin}`: each point's tolerance box), and `--pareto-svg OUT` the front as a figure (a new file, staged with
//! `--write-study`; an empty front, no table at any dwell, is an answer: no figure, and the
//! text and JSON `pareto_svg_note` say so). With `--write-study` the written study has the chosen point's positions
//! and its one dwell (`calibration.timing.dwell_s`), so `end-to-end` on it answers the
//! chosen J (`direct_with_noise`) and its combined answer. Without noise the budget only

use crate::InputError;
use crate::input::lab;
use anyhow::Result;
use clap::Parser;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use schedule_design::{DEFAULT_MAX_CONDITION, DEFAULT_STEP_DEG, ScheduleDesign, ScheduleReport};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use study::Study;
use study::fmt::{num, sig};
use tt_core::units::rad_to_arcmin;
use tt_lab::design::budget::Budgeted;
use tt_lab::design::rates::RateChoice;
use tt_lab::design::schedule::{
    CombinedChoice, NoiseCounted, Options, RunView, ScheduleAnswer, noise_note, rate_steps_note,
    start_name,
};

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
    /// With `--time-budget-s`: positions beyond the fewest that identify every output that
    /// every proposed point of the front keeps (the study's own schedule is evaluated
    /// whatever its count).
    #[arg(long, default_value_t = schedule_design::DEFAULT_REDUNDANCY)]
    pub redundancy: usize,
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

/// Everything the command prints: the library's answer and what the command did.
struct Outcome {
    answer: ScheduleAnswer,
    command: String,
    written: Option<String>,
    /// With `--pareto-svg` and an empty front: why no figure was written.
    pareto_svg_note: Option<String>,
}

/// The combined comparison in words.
fn combined_text(c: &CombinedChoice) -> String {
    let j = |v: Option<f64>| {
        v.map_or("no table suffices".to_string(), |v| {
            format!("J = {}", num(v))
        })
    };
    let standing = c.both_fail().map_or(String::new(), |(st, de)| {
        let dwell = |d: Option<f64>| {
            d.map_or("none up to the longest accepted dwell".to_string(), |d| {
                format!("{} s", num(d))
            })
        };
        format!(
            " (neither leaves room for a table at the study's dwell: largest noise part / accuracy {} for the study's schedule, {} designed; shortest dwell at which some table suffices {} for the study's, {} designed)",
            num(st.noise_over_accuracy()),
            num(de.noise_over_accuracy()),
            dwell(st.min_dwell_s()),
            dwell(de.min_dwell_s())
        )
    });
    format!(
        "with the noise counted ({} sigma, the study's timing; certified direct allocation with the noise part kept free): study's schedule {}, designed {}{standing}: {}\n",
        num(DEFAULT_K_SIGMA),
        j(c.study().objective_arcmin()),
        j(c.designed().objective_arcmin()),
        if c.designed_recommended() {
            "the designed schedule does not lose on the combined answer"
        } else {
            "the designed schedule LOSES on the combined answer; keep the study's schedule (it is the one recommended and written)"
        }
    )
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
    match n.allocation() {
        None => (
            format!(
                "with the noise counted ({k} sigma, the study's timing): none: no table suffices at the study's dwell (the noise part alone fills an accuracy)"
            ),
            None,
        ),
        Some(a) if n.certified() => (
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
    let mut t = header_text(s, &o.answer);
    t.push_str(&table_text(s, o.answer.design()));
    t.push_str(&tail_text(s, o));
    t
}

/// The study, the search's settings, the notes and what the options added.
fn header_text(s: &Study, o: &ScheduleAnswer) -> String {
    let mut t = format!(
        "design-schedule: study {} ({}), reading {}\n  {} candidates ({} deg grid over {}, and the study's positions), {} positions, condition numbers <= {}, seed {}\n\n",
        s.name,
        s.path,
        s.reading,
        o.candidates(),
        num(o.step_deg()),
        s.turntable.joint_names().join(", "),
        o.settings().positions,
        num(o.settings().max_condition),
        o.settings().seed
    );
    if let Some(n) = rate_steps_note(s) {
        t.push_str(&format!("note: {n}\n"));
    }
    if let Some(r) = o.rates() {
        t.push_str(&crate::design_rates::text(r));
    }
    if let Some(n) = noise_note(s) {
        t.push_str(&format!("note: {n}\n"));
        if let Some(c) = o.combined() {
            t.push_str(&combined_text(c));
        }
        t.push('\n');
    }
    if let Some(b) = o.budget() {
        t.push_str(&crate::design_budget::text(s, b));
    }
    t
}

/// The four schedules' table, the outputs and what the worst-case column is.
fn table_text(s: &Study, d: &ScheduleDesign) -> String {
    let outputs = s.sensor.outputs();
    let names = outputs
        .iter()
        .map(|x| x.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let mut t = String::new();
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
    t
}

/// The tolerances each schedule allows, the groups, the designed positions and the search.
fn tail_text(s: &Study, o: &Outcome) -> String {
    let d = o.answer.design();
    let mut t = String::new();
    let c = o.answer.combined();
    for (what, r, n) in [
        ("designed", &d.designed(), c.map(CombinedChoice::designed)),
        ("study's", &d.study(), c.map(CombinedChoice::study)),
    ] {
        t.push_str(&tolerance_lines(s, what, r, n));
    }
    t.push_str(&crate::groups::text(
        &s.turntable,
        &o.answer.group_bounds(),
        "",
    ));
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
        o.answer.seconds()
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
    let mut options = Options::default();
    options.positions = args.positions.map(|n| n as usize);
    options.step_deg = args.step_deg;
    options.max_condition = args.max_condition;
    options.seed = args.seed;
    options.time_budget_s = args.time_budget_s;
    options.redundancy = args.redundancy;
    options.rates_deg_per_s.clone_from(&args.rates_deg_per_s);
    check(args, &s, &options)?;
    let pb = progress_bar(options.work_units(&s));
    let tick = || {
        if let Some(pb) = &pb {
            pb.inc(1);
        }
    };
    let answer = tt_lab::design::schedule::design(&s, &options, &tick).map_err(lab)?;
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    // an empty front is an answer: no figure, and the output says so
    let mut pareto_svg_note = None;
    let svg = match (&args.pareto_svg, answer.budget()) {
        (Some(out), Some(Budgeted::Design(d))) => {
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
        (Some(_), Some(Budgeted::Noiseless { .. })) => {
            return Err(InputError::new(
                "--pareto-svg",
                "the study gives no noise: there is no trade-off of test time against the table to draw",
            )
            .into());
        }
        _ => None,
    };
    let command = command_line(args, &answer);
    let written = match &args.write_study {
        Some(out) => {
            let shown = out.display().to_string();
            let text = written_text(&s, &answer, &command, &shown)?;
            Some((
                shown,
                crate::newfile::stage(out, text.as_bytes()).map_err(lab)?,
            ))
        }
        None => None,
    };
    // both files staged before either is linked into place
    let svg = svg
        .map(|(out, text)| crate::newfile::stage(out, text.as_bytes()).map_err(lab))
        .transpose()?;
    let written = match written {
        Some((shown, staged)) => {
            staged.commit("--write-study").map_err(lab)?;
            Some(shown)
        }
        None => None,
    };
    if let Some(staged) = svg {
        staged.commit("--pareto-svg").map_err(lab)?;
    }
    let outcome = Outcome {
        answer,
        command,
        written,
        pareto_svg_note,
    };
    if args.json {
        let run = RunView {
            command: &outcome.command,
            written_study: outcome.written.as_deref(),
            pareto_svg_note: outcome.pareto_svg_note.as_deref(),
        };
        crate::json::print(&outcome.answer.view(&s, run))
    } else {
        crate::out::print(&to_text(&s, &outcome))
    }
}

/// The checks before the (long) search, in the order the command has always made them: the
/// candidate rates, `--pareto-svg` without a budget, the output files, the budget.
///
/// # Errors
/// The first [`InputError`] (exit 2).
fn check(args: &Args, s: &Study, options: &Options) -> Result<()> {
    if let Some(rates) = &args.rates_deg_per_s {
        crate::design_rates::check(s, rates)?;
    }
    if args.pareto_svg.is_some() && args.time_budget_s.is_none() {
        return Err(
            InputError::new("--pareto-svg", "the Pareto front needs --time-budget-s").into(),
        );
    }
    let outputs: Vec<(&str, &Path)> = [
        ("--write-study", args.write_study.as_deref()),
        ("--pareto-svg", args.pareto_svg.as_deref()),
    ]
    .into_iter()
    .filter_map(|(f, p)| p.map(|p| (f, p)))
    .collect();
    crate::newfile::check_all(&outputs)?;
    tt_lab::design::schedule::check(s, options).map_err(lab)
}

/// The command that reproduces the run.
fn command_line(args: &Args, answer: &ScheduleAnswer) -> String {
    let mut command = format!(
        "cargo xtask design-schedule --study {} --positions {} --step-deg {} --max-condition {} --seed {}",
        crate::paths::shell_quote(&crate::paths::shown(args.study.as_deref())),
        answer.settings().positions,
        num(args.step_deg),
        num(args.max_condition),
        answer.settings().seed
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
    command
}

/// The study `--write-study` writes (shown as `shown`): the positions chosen (designed, the
/// study's kept, or the budget's choice, with its dwell) and the chosen rate, under a comment
/// saying how they were made and the tolerances recommended for exactly them; checked by
/// parsing it back.
///
/// # Errors
/// An internal error when the text does not parse back to what was chosen.
fn written_text(s: &Study, answer: &ScheduleAnswer, command: &str, shown: &str) -> Result<String> {
    let design = answer.design();
    let combined = answer.combined();
    let keep_study = answer.keep_study();
    let rate_keeps_study = answer
        .rates()
        .is_some_and(|r| r.chosen().is_some() && r.chosen_study_positions());
    // with a time budget and noise: the count, positions and dwell it chose
    let chosen = match answer.budget() {
        Some(Budgeted::Design(d)) => d.chosen().map(|p| (d, p)),
        _ => None,
    };
    let study_kept = keep_study || rate_keeps_study;
    // the comment describes what is written: which positions, their J and the
    // tolerances recommended for exactly them (with the noise counted when the
    // study gives noise)
    let (positions, which, counted): (&[Vec<f64>], String, Option<&NoiseCounted>) = match chosen {
        Some((d, p)) => (
            p.positions_deg(),
            crate::design_budget::chosen_comment(d, p),
            d.chosen_counted(),
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
                condition_list(s, design.study())
            ),
            combined.map(CombinedChoice::study),
        ),
        None => (
            design.designed().positions_deg(),
            format!(
                "Designed positions: J = {} arcmin^-2 (direct allocation, table alone, reading {}; the study's schedule: {}, D-optimal: {}),\ncondition numbers {}, best of {} restarts over {} candidates.",
                num(design.designed().allocation().objective_arcmin()),
                s.reading,
                num(design.study().allocation().objective_arcmin()),
                num(design.d_optimal().allocation().objective_arcmin()),
                condition_list(s, design.designed()),
                design.search().restarts().len(),
                answer.candidates()
            ),
            combined.map(CombinedChoice::designed),
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
                    bound_list(s, ub, &|v| sig_down(v, 3))
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
                    bound_list(s, c.upper_bounds_rad(), &|v| sig_down(v, 3))
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
    if let (Some(c), None) = (combined, chosen) {
        comment.push('\n');
        comment.push_str(combined_text(c).trim_end());
    }
    if let Some(r) = answer.rates() {
        comment.push('\n');
        comment.push_str(crate::design_rates::text(r).trim());
    }
    if let Some(Budgeted::Design(d)) = answer.budget() {
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
    let text = match answer.rates().and_then(RateChoice::chosen) {
        Some((rate, _)) => crate::design_rates::text_with_rate(s, &text, rate)?,
        None => text,
    };
    let back = Study::parse(shown, &text)
        .map_err(|e| anyhow::anyhow!("internal: the written study does not parse: {e}"))?;
    if back.positions_deg.as_slice() != positions {
        anyhow::bail!("internal: the written study's positions differ from the designed ones");
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
    Ok(text)
}
