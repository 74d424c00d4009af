//! `cargo xtask check-turntable [--study FILE] --tolerances FILE.toml [--samples N] [--seed S]
//! [--k-sigma K] [--jcgm101 [--mc-digits D]] [--json]`: "the vendor's sheet says these tolerances: will my calibration meet its
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

use anyhow::Result;
use calib_lsq::Reading;
use clap::Parser;
use e2e_verify::{EndToEnd, ToleranceSheet, TurntableCheck, Verdict};
use std::path::PathBuf;
use tt_core::human::num;
pub(crate) use tt_lab::vendor::{CheckJson, NoisyCheck};

/// Arguments of `check-turntable`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Study file: turntable, sensor and its accuracies, site, schedule, reading (default:
    /// the paper's).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// The vendor's tolerances (TOML: `[tolerances_arcmin]` with every angular error,
    /// optional `[tolerances_mm]`).
    #[arg(long)]
    pub tolerances: PathBuf,
    /// `--samples` and `--seed` (default: the study's `monte_carlo`).
    #[command(flatten)]
    pub sampling: crate::args::Sampling,
    /// `--k-sigma` and the JCGM 101 Monte Carlo of every specification (`--jcgm101`,
    /// `--mc-digits`).
    #[command(flatten)]
    pub uncertainty: crate::args::Uncertainty,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
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
                crate::text::noise::split_text(co, &out.unit),
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
                    crate::text::groups::contribution_name(e2e.turntable(), k.group()),
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
            crate::text::noise::yield_text(&n.combined_yield),
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
pub(crate) fn to_text(
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
    s.push_str(&crate::text::groups::text(
        checks[0].0.turntable(),
        &[],
        "  ",
    ));
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

/// Run the command.
///
/// # Errors
/// [`InputError`] for a bad study, tolerance file or flag; other errors if a computation fails.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = crate::loaded::load(args.study.as_deref())?;
    let options = tt_lab::vendor::Options {
        samples: args.sampling.samples,
        seed: args.sampling.seed,
        k_sigma: args.uncertainty.k_sigma,
    };
    let v = tt_lab::vendor::check(&s, &args.tolerances, &options).map_err(crate::input::lab)?;
    let mc = crate::text::jcgm101::run(
        &args.uncertainty.jcgm101,
        args.sampling.seed,
        &s,
        &v.checks()[0].0,
        v.sheet().upper_bounds_rad(),
        v.decision(),
    )?;
    if args.json {
        let view = crate::text::jcgm101::with_json(&CheckJson::of(&s, &v), &s, mc.as_ref())?;
        return crate::json::print(&view);
    }
    let checks = v.checks();
    let mut text = to_text(checks, &s.path, v.sheet(), v.noisy());
    if let Some(rate) = v.rate() {
        text.push_str(&format!("\n{}\n", tt_lab::vendor::RATE_STEPS_NOTE));
        for ((e2e, _), r) in checks.iter().zip(rate) {
            text.push_str(&crate::text::rate::text(e2e, r));
        }
    } else if let Some(angle) = v.angle() {
        if let Some(n) = crate::text::noise::note(&s) {
            text.push_str(&n);
            text.push('\n');
        }
        text.push_str(
            "\nerrors that vary with the shaft angle, same tolerances over the whole revolution:\n",
        );
        for (((e2e, c), a), counted) in checks.iter().zip(&angle.readings).zip(v.counted()) {
            text.push_str(&format!("reading {}\n", e2e.reading()));
            text.push_str(&crate::text::angle::text(e2e, c, *counted, a, angle));
        }
        if let Some(c) = v.compensated() {
            text.push_str(&crate::text::angle::compensated_text(
                checks,
                c,
                v.counted(),
            ));
        }
    }
    text.push_str(&crate::text::spec_verdict::text(
        &s,
        v.decision(),
        "over these tolerances",
    ));
    text.push_str(&crate::text::jcgm101::text(
        &args.uncertainty.jcgm101,
        &s,
        mc.as_ref(),
    ));
    crate::out::print(&text)
}
