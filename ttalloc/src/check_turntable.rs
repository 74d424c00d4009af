//! `cargo xtask check-turntable [--study FILE] --tolerances FILE.toml [--samples N] [--seed S]
//! [--k-sigma K] [--json]`: "the vendor's sheet says these tolerances: will my calibration meet its
//! accuracy, and which error dominates?"
//!
//! For every output: the end-to-end worst case over the tolerance box (linearised, confirmed
//! on the exact chain at the worst vertex, with the derived second-order bound when the
//! reading has one) against its accuracy, the Monte Carlo yield with a 95% interval, and each
//! error's share of the worst case and of the variance (one share per group of errors that act
//! only together, named by their combination, e.g. `dphi_o + deps_om_z`); then one verdict
//! line. JSON: `groups` lists those groups.
//!
//! With noise and a timing in the study, every output's answer is split into the table's part
//! and the noise's ("table 0.0061, noise 0.0047 at 3 sigma", `--k-sigma`, default 3): the
//! verdict counts both (JSON `verdict`; `table_verdict` is the table's alone), every output
//! gets `table_part`, `noise_sigma` and `combined` (the unit of `accuracy`), and the yield
//! over turntables and noise is given with its interval (`combined_yield`). The
//! angle-dependent and the compensated sections count the same noise part in their verdicts
//! (the rule stated in the verdict's sentence; JSON `verdict`, with `table_verdict` the
//! table's alone). A study without noise gets exactly today's answer.

use crate::InputError;
use crate::json::{ArcminBounds, CombinedYieldJson, GroupJson, Split, arcmin_bounds};
use anyhow::Result;
use calib_lsq::Reading;
use clap::Parser;
use e2e_verify::{
    CombinedOutput, EndToEnd, McSettings, ToleranceSheet, TurntableCheck, Verdict, YieldCount,
};
use serde::Serialize;
use std::path::PathBuf;
use study::fmt::num;

/// Arguments of `check-turntable`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file: turntable, sensor and its accuracies, site, schedule, reading (default:
    /// the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// The vendor's tolerances (TOML: `[tolerances_arcmin]` with every angular error,
    /// optional `[tolerances_mm]`).
    #[arg(long)]
    pub tolerances: PathBuf,
    /// Monte Carlo turntables (default: the study's `monte_carlo.samples`).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::samples)]
    pub samples: Option<u64>,
    /// Seed of the random streams (default: the study's).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// Confidence multiplier of the noise part (combined = table + k sigma), in (0, 10];
    /// used when the study gives noise and a timing.
    #[arg(long, allow_negative_numbers = true, default_value_t = e2e_verify::DEFAULT_K_SIGMA, value_parser = crate::args::k_sigma)]
    pub k_sigma: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// One reading's check with the noise part: every output's combined answer, the verdict with
/// the noise counted and the yield over turntables and noise.
#[derive(Debug, Clone)]
pub struct NoisyCheck {
    /// One per output.
    pub outputs: Vec<CombinedOutput>,
    /// The weakest of the outputs' combined verdicts.
    pub verdict: Verdict,
    /// The yield over turntables in the box and random noise.
    pub combined_yield: YieldCount,
}

/// One error's (or group's) contribution to an output's worst case.
#[derive(Debug, Serialize)]
struct ContributionJson<'a> {
    /// The error's name, or its group's combination.
    error: String,
    /// The errors of the group (one when the error acts alone).
    errors: Vec<&'a str>,
    /// Its share of the linearised worst case, in [0, 1].
    worst_case_share: f64,
    /// Its share of the variance over the box, in [0, 1].
    variance_share: f64,
}

/// One output's check (`outputs[]`), output's unit.
#[derive(Debug, Serialize)]
struct CheckOutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// Its verdict (with the noise part: counting both).
    verdict: &'static str,
    /// With the noise part: the table's verdict alone; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    table_verdict: Option<&'static str>,
    /// The linearised worst case over the sheet's box, output's unit.
    worst_case_linear: f64,
    /// The exact chain at the worst vertex, output's unit.
    worst_case_exact_at_vertex: f64,
    /// The second-order bound (`null` when not computed), output's unit.
    second_order_bound: Option<f64>,
    /// The certified bound (`null` when not computed), output's unit.
    certified_bound: Option<f64>,
    /// The worst test position (index into the schedule).
    worst_position: usize,
    /// The computation's precision, output's unit.
    precision: f64,
    /// Fraction of the Monte Carlo turntables meeting this output's accuracy, in [0, 1].
    meeting_fraction: f64,
    /// Largest error over the Monte Carlo turntables, output's unit.
    monte_carlo_max: f64,
    /// Each error's (or group's) contribution.
    contributions: Vec<ContributionJson<'a>>,
    /// With the noise part: the split between the table and the noise; absent otherwise.
    #[serde(flatten)]
    split: Option<Split>,
}

/// One reading's check; with the noise part, every output gets the split, `verdict` counts
/// the noise and `table_verdict` is the table's alone.
#[derive(Debug, Serialize)]
struct ReadingCheckJson<'a> {
    /// The reading of eq 13.
    reading: String,
    /// The verdict (with the noise part: counting both).
    verdict: &'static str,
    /// With the noise part: the table's verdict alone; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    table_verdict: Option<&'static str>,
    /// Monte Carlo yield over the sheet's box, in [0, 1].
    #[serde(rename = "yield")]
    yield_fraction: f64,
    /// Its 95% interval.
    yield_interval_95: (f64, f64),
    /// Turntables drawn.
    samples: u64,
    /// Seed of the random streams.
    seed: u64,
    /// Every output's check.
    outputs: Vec<CheckOutputJson<'a>>,
    /// With the noise part: its confidence multiplier (`null` without outputs); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    k_sigma: Option<Option<f64>>,
    /// With the noise part: the yield over turntables and noise; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    combined_yield: Option<CombinedYieldJson>,
}

impl<'a> ReadingCheckJson<'a> {
    fn new(e2e: &'a EndToEnd, c: &'a TurntableCheck, noisy: Option<&NoisyCheck>) -> Self {
        let names = e2e.turntable().rotation_error_names();
        let d = &c.distribution();
        Self {
            reading: e2e.reading().to_string(),
            verdict: noisy.map_or(c.verdict(), |n| n.verdict).name(),
            table_verdict: noisy.map(|_| c.verdict().name()),
            yield_fraction: d.count().fraction(),
            yield_interval_95: d.count().interval_95(),
            samples: d.count().samples(),
            seed: d.count().seed(),
            outputs: c
                .outputs()
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let out = e2e.calibration().outputs()[o.output()].output();
                    let co = noisy.and_then(|n| n.outputs.get(i));
                    CheckOutputJson {
                        name: &out.name,
                        unit: &out.unit,
                        accuracy: o.accuracy(),
                        verdict: co.map_or(o.verdict(), |co| co.verdict()).name(),
                        table_verdict: co.map(|_| o.verdict().name()),
                        worst_case_linear: o.worst_case().linear_bound(),
                        worst_case_exact_at_vertex: o.worst_case().exact_at_vertex(),
                        second_order_bound: o.worst_case().second_order_bound(),
                        certified_bound: o.worst_case().certified_bound(),
                        worst_position: o.worst_case().position(),
                        precision: o.worst_case().precision(),
                        meeting_fraction: d.count().meeting_per_output()[o.output()] as f64
                            / d.count().samples() as f64,
                        monte_carlo_max: d.worst()[o.output()].value(),
                        contributions: o
                            .contributions()
                            .iter()
                            .map(|k| ContributionJson {
                                error: crate::groups::contribution_name(e2e.turntable(), k.group()),
                                errors: k.group().names(&names),
                                worst_case_share: k.worst_share(),
                                variance_share: k.variance_share(),
                            })
                            .collect(),
                        split: co.map(Split::from),
                    }
                })
                .collect(),
            k_sigma: noisy.map(|n| n.outputs.first().map(|o| o.k_sigma())),
            combined_yield: noisy.map(|n| (&n.combined_yield).into()),
        }
    }
}

/// `check-turntable --json`: the study's reading at the top level (`verdict`, `yield`,
/// `outputs`, ...), and `user_reading`, the same for outputs simulated at the actual
/// orientation when the study's reading is another one (else `null`).
#[derive(Debug, Serialize)]
pub struct CheckJson<'a> {
    /// The study's reading's check (its keys at the top level).
    #[serde(flatten)]
    study_reading: ReadingCheckJson<'a>,
    /// The sheet's path.
    tolerances: &'a str,
    /// The sheet's angular tolerances, arcmin.
    tolerances_arcmin: ArcminBounds,
    /// Errors that act only together.
    groups: Vec<GroupJson>,
    /// The user's reading's check, `null` when it is the study's.
    user_reading: Option<ReadingCheckJson<'a>>,
    /// Without rate steps: the check when the errors vary with the shaft angle; absent with
    /// rate steps.
    #[serde(skip_serializing_if = "Option::is_none")]
    angle_dependent: Option<crate::angle::AngleCheckJson<'a>>,
    /// Without rate steps: the check of the compensated table (`null` without measured
    /// errors); absent with rate steps.
    #[serde(skip_serializing_if = "Option::is_none")]
    compensated: Option<Option<crate::angle::CompensatedJson<'a>>>,
    /// With rate steps: what the angular check holds at zero; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_steps_note: Option<&'static str>,
    /// With rate steps: per reading, the check with the errors only rotation exposes bounded
    /// by the sheet; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_steps: Option<Vec<crate::rate::RateCheckJson<'a>>>,
    /// The decision rule and the verdict against the study's specifications per quantity
    /// (the GUM budget of each over the sheet's tolerances); the accuracy rule without.
    decision: Option<crate::spec_verdict::SpecVerdictJson>,
}

impl<'a> CheckJson<'a> {
    /// The check's view: `checks` per reading (the study's first), with their noise parts.
    #[must_use]
    pub fn new(
        checks: &'a [(EndToEnd, TurntableCheck)],
        sheet: &'a ToleranceSheet,
        noisy: &'a [NoisyCheck],
    ) -> Self {
        let (e2e, c) = &checks[0];
        let names = e2e.turntable().rotation_error_names();
        Self {
            study_reading: ReadingCheckJson::new(e2e, c, noisy.first()),
            tolerances: sheet.source(),
            tolerances_arcmin: arcmin_bounds(&names, c.upper_bounds_rad()),
            groups: GroupJson::all(e2e.turntable(), &[]),
            user_reading: checks
                .get(1)
                .map(|(e, c)| ReadingCheckJson::new(e, c, noisy.get(1))),
            angle_dependent: None,
            compensated: None,
            rate_steps_note: None,
            rate_steps: None,
            decision: None,
        }
    }
}

/// Below this share of its accuracy an output's linearised worst case is rounding: the output
/// does not depend on these errors to first order (dimensionless).
const INSENSITIVE_SHARE: f64 = 1e-9;

fn reading_text(e2e: &EndToEnd, c: &TurntableCheck, noisy: Option<&NoisyCheck>) -> String {
    let mut s = String::new();
    for o in c.outputs() {
        let split = noisy.map(|n| &n.outputs[o.output()]);
        let out = e2e.calibration().outputs()[o.output()].output();
        let w = &o.worst_case();
        s.push_str(&format!(
            "  output {}: accuracy {} {u}; worst case {} {u} (linearised {}{}), Monte Carlo max {} {u}, {:.2}% meet it: {}\n",
            out.name,
            num(o.accuracy()),
            num(w.exact_at_vertex()),
            num(w.linear_bound()),
            w.second_order_bound().map_or(String::new(), |t| format!(", proven below {}", num(w.linear_bound() + t))),
            num(c.distribution().worst()[o.output()].value()),
            100.0 * c.distribution().count().meeting_per_output()[o.output()] as f64 / c.distribution().count().samples() as f64,
            o.verdict().name(),
            u = out.unit
        ));
        let max = c.distribution().worst()[o.output()].value();
        if w.exact_at_vertex() == 0.0 || max == 0.0 {
            if let Some(n) = crate::out::precision_note(&[(&out.name, &out.unit, w.precision())]) {
                s.push_str(&format!("    ({n})\n"));
            }
        }
        if let Some(co) = split {
            s.push_str(&format!(
                "    with noise: {}: {}\n",
                crate::noise::split_text(co, &out.unit),
                if co.meets() { "meets" } else { "does NOT meet" }
            ));
        }
        if w.linear_bound() <= INSENSITIVE_SHARE * o.accuracy() {
            s.push_str("    dominant errors: none (the output does not depend on these errors to first order)\n");
            continue;
        }
        let dominant: Vec<String> = o
            .dominant(3)
            .iter()
            .map(|k| {
                format!(
                    "{} {:.0}% of the worst case, {:.0}% of the variance",
                    crate::groups::contribution_name(e2e.turntable(), k.group()),
                    100.0 * k.worst_share(),
                    100.0 * k.variance_share()
                )
            })
            .collect();
        s.push_str(&format!("    dominant errors: {}\n", dominant.join("; ")));
    }
    let (lo, hi) = c.distribution().count().interval_95();
    if let Some(n) = noisy {
        let verdict = match n.verdict {
            Verdict::Guaranteed => {
                "MEETS every accuracy with the noise counted: the table's part is proven for every turntable within these tolerances, the noise counted at k sigma at the worst position (not a probability)"
            }
            Verdict::Likely => {
                "likely meets every accuracy with the noise counted: the worst vertex does, but no bound proves it for the whole box"
            }
            Verdict::Fails => "does NOT meet every accuracy once the noise is counted",
        };
        s.push_str(&format!(
            "  verdict: {verdict} (table alone: {}); {}; table alone: Monte Carlo yield {:.2}% (95% interval {:.2}%-{:.2}%)\n",
            c.verdict().name(),
            crate::noise::yield_text(&n.combined_yield),
            100.0 * c.distribution().count().fraction(),
            100.0 * lo,
            100.0 * hi,
        ));
        return s;
    }
    let verdict = match c.verdict() {
        Verdict::Guaranteed => {
            "MEETS every accuracy: proven for every turntable within these tolerances (the table's errors only: no noise is modelled)"
        }
        Verdict::Likely => {
            "likely meets every accuracy: the worst vertex does, but no bound proves it for the whole box"
        }
        Verdict::Fails => {
            "does NOT meet every accuracy: a turntable within these tolerances (the worst vertex) misses"
        }
    };
    s.push_str(&format!(
        "  verdict: {verdict}; Monte Carlo yield {:.2}% (95% interval {:.2}%-{:.2}%, {} turntables, seed {})\n",
        100.0 * c.distribution().count().fraction(),
        100.0 * lo,
        100.0 * hi,
        c.distribution().count().samples(),
        c.distribution().count().seed()
    ));
    s
}

/// The check as text: one block per reading (the study's, then the user's when different).
#[must_use]
pub fn to_text(
    checks: &[(EndToEnd, TurntableCheck)],
    study_path: &str,
    sheet: &ToleranceSheet,
    noisy: &[NoisyCheck],
) -> String {
    let mut s = format!(
        "check of {} against the study {}\n",
        sheet.title(),
        study_path
    );
    s.push_str(&crate::groups::text(checks[0].0.turntable(), &[], "  "));
    if let Some(n) = noisy.first() {
        s.push_str(&format!(
            "  noise: the study's noise over its timing, noise part at {} sigma (calib-lsq's covariance of the calibration)\n",
            num(n.outputs.first().map_or(0.0, |o| o.k_sigma()))
        ));
    }
    for (i, (e2e, c)) in checks.iter().enumerate() {
        let what = if e2e.reading() == Reading::USER {
            "outputs at the actual orientation: what a calibrating lab gets"
        } else {
            "the study's reading"
        };
        s.push_str(&format!(
            "\nreading {} ({what}; {})\n",
            e2e.reading(),
            e2e.reading().formula()
        ));
        s.push_str(&reading_text(e2e, c, noisy.get(i)));
        let verdict = |i: usize| noisy.get(i).map_or(checks[i].1.verdict(), |n| n.verdict);
        if i == 0 && checks.len() > 1 && verdict(0) != verdict(1) {
            s.push_str(
                "  (the verdict depends on the reading of eq 13: see the user's reading below)\n",
            );
        }
    }
    s
}

/// The checks with the noise part, one per check (empty when the study gives no noise or no
/// timing): every output's combined answer, the verdict counting both and the yield over
/// turntables in the sheet's box and noise.
///
/// # Errors
/// As [`e2e_verify::EndToEnd::noise_budget`] and [`e2e_verify::EndToEnd::combined_yield`].
pub fn noisy_checks(
    s: &study::Study,
    e2e: &EndToEnd,
    checks: &[(EndToEnd, TurntableCheck)],
    sheet: &ToleranceSheet,
    settings: &McSettings,
    k_sigma: f64,
) -> Result<Vec<NoisyCheck>> {
    let Some(budget) = crate::noise::budget(s, e2e)? else {
        return Ok(Vec::new());
    };
    let sigma = budget.sigma();
    let bounds = e2e
        .box_of(sheet.upper_bounds_rad(), sheet.lower_bounds_rad())
        .map_err(|e| crate::input::library(e, s))?;
    checks
        .iter()
        .map(|(sim, c)| {
            let outputs: Vec<CombinedOutput> = c
                .outputs()
                .iter()
                .map(|o| {
                    CombinedOutput::of(o.worst_case(), o.accuracy(), sigma[o.output()], k_sigma)
                })
                .collect();
            let combined_yield = sim
                .combined_yield(&bounds, &budget, settings)
                .map_err(|e| crate::input::library(e, s))?;
            Ok(NoisyCheck {
                verdict: e2e_verify::noise::weakest(outputs.iter().map(|o| o.verdict())),
                outputs,
                combined_yield,
            })
        })
        .collect()
}

/// Run the command.
///
/// # Errors
/// [`InputError`] for a bad study, tolerance file or flag; other errors if a computation fails.
pub fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    // a measured table outside the sheet is refused before any computation
    let sheet = s.load_sheet(&args.tolerances).map_err(InputError::from)?;
    let e2e = crate::end_to_end::simulator(&s)?;
    let settings = McSettings::new(
        args.samples.unwrap_or(s.monte_carlo.samples),
        args.seed.unwrap_or(s.monte_carlo.seed),
    );
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != Reading::USER {
        sims.push(
            e2e.with_reading(Reading::USER)
                .map_err(|e| crate::input::library(e, &s))?,
        );
    }
    let checks = sims
        .into_iter()
        .map(|sim| {
            let c = sim
                .check_sheet(&sheet, &settings)
                .map_err(|e| crate::input::library(e, &s))?;
            Ok((sim, c))
        })
        .collect::<Result<Vec<_>>>()?;
    let noisy = noisy_checks(&s, &e2e, &checks, &sheet, &settings, args.k_sigma)?;
    if e2e.has_rate_steps() {
        return run_with_rate_steps(args, &s, &sheet, &checks, &noisy, &settings);
    }
    let noise = noisy.first().map(|n| crate::angle::NoisePart {
        sigma: n.outputs.iter().map(CombinedOutput::noise_sigma).collect(),
        k_sigma: args.k_sigma,
    });
    let angle = crate::angle::check(
        &s,
        &checks,
        &sheet,
        settings.samples,
        settings.seed,
        true,
        noise.as_ref(),
    )?;
    let compensated = crate::angle::compensated(&s, &checks, &sheet, &settings, noise.as_ref())?;
    let decision = crate::spec_verdict::compute(&s, &e2e, sheet.upper_bounds_rad())?;
    let counted: Vec<Verdict> = checks
        .iter()
        .enumerate()
        .map(|(i, (_, c))| noisy.get(i).map_or(c.verdict(), |n| n.verdict))
        .collect();
    if args.json {
        let mut v = CheckJson::new(&checks, &sheet, &noisy);
        v.angle_dependent = Some(crate::angle::AngleCheckJson::new(&checks, &angle));
        v.compensated = Some(
            compensated
                .as_ref()
                .map(|c| crate::angle::CompensatedJson::new(&checks, c)),
        );
        v.decision = Some(crate::spec_verdict::SpecVerdictJson::new(
            &s,
            decision.as_ref(),
        ));
        crate::json::print(&v)
    } else {
        let mut text = to_text(&checks, &s.path, &sheet, &noisy);
        if let Some(n) = crate::noise::note(&s) {
            text.push_str(&n);
            text.push('\n');
        }
        text.push_str(
            "\nerrors that vary with the shaft angle, same tolerances over the whole revolution:\n",
        );
        for (((e2e, c), a), v) in checks.iter().zip(&angle.readings).zip(&counted) {
            text.push_str(&format!("reading {}\n", e2e.reading()));
            text.push_str(&crate::angle::text(e2e, c, *v, a, &angle));
        }
        if let Some(c) = &compensated {
            text.push_str(&crate::angle::compensated_text(&checks, c, &counted));
        }
        text.push_str(&crate::spec_verdict::text(
            &s,
            decision.as_ref(),
            "over these tolerances",
        ));
        crate::out::print(&text)
    }
}

/// The check of a study with rate steps: the angular check as for a static study, then the
/// check with the errors only rotation exposes bounded by the sheet ([`crate::rate`]); the
/// angle-dependent models are static (not evaluated at a rate step).
fn run_with_rate_steps(
    args: &Args,
    s: &study::Study,
    sheet: &ToleranceSheet,
    checks: &[(EndToEnd, TurntableCheck)],
    noisy: &[NoisyCheck],
    settings: &McSettings,
) -> Result<()> {
    let decision = crate::spec_verdict::compute(s, &checks[0].0, sheet.upper_bounds_rad())?;
    let decision = decision.as_ref();
    let rate = checks
        .iter()
        .map(|(e2e, _)| crate::rate::check(s, e2e, sheet, settings))
        .collect::<Result<Vec<_>>>()?;
    const NOTE: &str = "the study has rate steps: the angular errors' check above holds the rate errors and translations at zero; the check below bounds them by the sheet; errors that vary with a shaft angle are modelled at static positions only (not checked here)";
    if args.json {
        let mut v = CheckJson::new(checks, sheet, noisy);
        v.rate_steps_note = Some(NOTE);
        v.rate_steps = Some(
            checks
                .iter()
                .zip(&rate)
                .map(|((e2e, _), r)| crate::rate::RateCheckJson::new(e2e, r))
                .collect(),
        );
        v.decision = Some(crate::spec_verdict::SpecVerdictJson::new(s, decision));
        crate::json::print(&v)
    } else {
        let mut text = to_text(checks, &s.path, sheet, noisy);
        text.push_str(&format!("\n{NOTE}\n"));
        for ((e2e, _), r) in checks.iter().zip(&rate) {
            text.push_str(&crate::rate::text(e2e, r));
        }
        text.push_str(&crate::spec_verdict::text(
            s,
            decision,
            "over these tolerances",
        ));
        crate::out::print(&text)
    }
}
