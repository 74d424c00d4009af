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
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use schedule_design::{DEFAULT_MAX_CONDITION, DEFAULT_STEP_DEG, ScheduleDesign, ScheduleReport};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use study::Study;
use tt_core::human::{num, sig};
use tt_lab::design::budget::Budgeted;
use tt_lab::design::schedule::{
    CombinedChoice, NoiseCounted, Options, RunView, ScheduleAnswer, noise_note, rate_steps_note,
    start_name,
};
use tt_lab::design::written::{self, bound_list, noise_counted_words, sig_down};

/// Arguments of `design-schedule`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// `--study` (default: the paper's).
    #[command(flatten)]
    pub study: crate::args::StudyFile,
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
        t.push_str(&written::rates_text(r));
    }
    if let Some(n) = noise_note(s) {
        t.push_str(&format!("note: {n}\n"));
        if let Some(c) = o.combined() {
            t.push_str(&written::combined_text(c));
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
        if search.designed().stop().local_optimum() {
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
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = args.study.load()?;
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
            let text = written::study_text(&s, &answer, &command, &shown).map_err(lab)?;
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
        crate::paths::shell_quote(&crate::paths::shown(args.study.path())),
        answer.settings().positions,
        num(args.step_deg),
        num(args.max_condition),
        answer.settings().seed
    );
    if let Some(b) = args.time_budget_s {
        command.push_str(&format!(" --time-budget-s {}", tt_core::human::exact(b)));
    }
    if let Some(r) = &args.rates_deg_per_s {
        let list: Vec<String> = r.iter().map(|v| tt_core::human::exact(*v)).collect();
        command.push_str(&format!(
            " {} {}",
            crate::design_rates::FLAG,
            list.join(",")
        ));
    }
    command
}
