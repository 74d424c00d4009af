//! `cargo xtask end-to-end [--study FILE] [--samples N] [--seed S] [--yield-fraction P]
//! [--jcgm101 [--mc-digits D]] [--json]`: does the allocated turntable deliver every output's calibration accuracy?
//!
//! For the study's reading of eq 13 and for the user's reading (outputs at the actual
//! orientation): the worst case and Monte Carlo yield of the two-step allocation (and of the
//! paper's Table 4 when the study's turntable is the paper's), and the direct, certified and
//! yield-based allocations against the outputs' accuracies. `--json` prints one object with
//! `direct_objective` (J of the direct allocation under the study's reading, arcmin^-2),
//! `two_step_objective`, `bounds_arcmin`, `groups` (errors that act only together, with the
//! bound of their combination under each direct allocation), `readings` (per reading: every
//! box's worst case, whether it meets every accuracy (`meets`, `meets_text`, in the words
//! of the text and the report) and yield) and `throughput` (turntables per second of the fast path, all threads and one, and of
//! the reference path, measured in the same run).

use anyhow::Result;
use clap::Parser;
use e2e_verify::{
    BoxAnswer, BuyersAnswer, EndToEnd, NoisyDirect, ReadingAnswer, Tradeoff, YieldVerdict,
};
use study::Study;
use tt_core::human::num;
use tt_core::units::objective_to_arcmin;
pub(crate) use tt_lab::end_to_end::{
    EndToEndJson, NoisyAnswer, Scanned, Throughput, check_yield_samples, direct_bounds,
};

/// Arguments of `end-to-end`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// `--study` (default: the paper's).
    #[command(flatten)]
    pub study: crate::args::StudyFile,
    /// `--samples` and `--seed` (default: the study's `monte_carlo`).
    #[command(flatten)]
    pub sampling: crate::args::Sampling,
    /// Target yield of the yield-based allocation, in (0, 1).
    #[arg(long, allow_negative_numbers = true, default_value_t = e2e_verify::DEFAULT_YIELD_FRACTION, value_parser = crate::args::fraction)]
    pub yield_fraction: f64,
    /// `--k-sigma` and the JCGM 101 Monte Carlo of every specification (`--jcgm101`,
    /// `--mc-digits`).
    #[command(flatten)]
    pub uncertainty: crate::args::Uncertainty,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// A vendor sheet whose magnitudes (`[axes.<joint>]` wobble, orthogonality) pair the
    /// errors: adds the direct and certified allocation with one tolerance per pair, as a
    /// disc and as a square (JSON `disc_allocation`).
    #[arg(long)]
    pub tolerances: Option<std::path::PathBuf>,
}

/// The noise part of the text: per reading, every box's combined answer and the direct
/// allocation with the noise part kept free; then the trade-off.
#[must_use]
pub(crate) fn noise_text(e2e: &EndToEnd, a: &BuyersAnswer, n: &NoisyAnswer) -> String {
    let mut t = String::new();
    let outputs = e2e.calibration().outputs();
    let sigma = n.readings[0].sigma();
    t.push_str(&format!(
        "\nwith the sensor's noise (calib-lsq's covariance of the calibration, the study's timing), noise part at {} sigma:\n",
        num(n.tradeoff.k_sigma())
    ));
    for (o, s) in outputs.iter().zip(sigma) {
        t.push_str(&format!(
            "  output {}: noise sigma {} {} at the worst position\n",
            o.output().name,
            num(*s),
            o.output().unit
        ));
    }
    for (r, nr) in a.readings().iter().zip(&n.readings) {
        t.push_str(&format!("reading {} with noise\n", r.reading()));
        for b in nr.boxes() {
            t.push_str(&format!(
                "  {:<14} verdict {}; {}\n",
                b.name(),
                b.verdict().name(),
                crate::text::noise::yield_text(b.combined_yield())
            ));
            for c in b.outputs() {
                let out = outputs[c.output()].output();
                t.push_str(&format!(
                    "    {}: {}\n",
                    out.name,
                    crate::text::noise::split_text(c, &out.unit)
                ));
            }
        }
        match &nr.direct() {
            NoisyDirect::Allocated { allocation, answer } => t.push_str(&format!(
                "  {:<14} J = {} arcmin^-2 (the table gets what the noise leaves; {} without noise); verdict {}; {}\n",
                "direct, noise",
                num(allocation.objective_arcmin()),
                num(r.direct().objective_arcmin()),
                answer.verdict().name(),
                crate::text::noise::yield_text(answer.combined_yield())
            )),
            NoisyDirect::NoTableSuffices { outputs: blocked } => {
                let what: Vec<String> = blocked
                    .iter()
                    .map(|b| {
                        let out = outputs[b.output()].output();
                        format!(
                            "{} noise part {} of {} {}",
                            out.name,
                            num(b.noise_part()),
                            num(out.accuracy),
                            out.unit
                        )
                    })
                    .collect();
                t.push_str(&format!(
                    "  {:<14} no table suffices at this dwell: {}\n",
                    "direct, noise",
                    what.join(", ")
                ));
            }
        }
    }
    t.push_str(&tradeoff_text(&n.tradeoff, &n.scanned));
    if let Some(sens) = &n.sensitivity {
        t.push_str(&sensitivity_text(e2e, sens, &n.tradeoff));
    }
    t
}

/// The answers at the noise parameters' +- 1 standard uncertainty, per output the parameter
/// its noise sigma depends on most, and the shortest dwell at the two corners.
#[must_use]
pub(crate) fn sensitivity_text(
    e2e: &EndToEnd,
    sens: &e2e_verify::NoiseSensitivity,
    tr: &Tradeoff,
) -> String {
    let outputs = e2e.calibration().outputs();
    let mut t = String::from(
        "sensitivity to the noise model (each parameter at its value -+ 1 standard uncertainty, the others at their values; worst-position noise sigma):\n",
    );
    for sp in sens.spreads() {
        let out = outputs[sp.output()].output();
        t.push_str(&format!(
            "  {} {} = {} +- {}: noise sigma {} .. {} {}\n",
            out.name,
            sp.parameter().name(),
            num(sp.value()),
            num(sp.uncertainty()),
            num(sp.sigma_minus()),
            num(sp.sigma_plus()),
            out.unit
        ));
    }
    for (k, o) in outputs.iter().enumerate() {
        let (Some(d), Some(nom), Some(lo), Some(hi)) = (
            sens.dominant(k),
            sens.nominal_sigma()[k],
            sens.optimistic_sigma()[k],
            sens.pessimistic_sigma()[k],
        ) else {
            continue;
        };
        t.push_str(&format!(
            "  output {}: noise sigma {} {} ({} at the optimistic corner, {} at the pessimistic); it depends most on {}\n",
            o.output().name,
            num(nom),
            o.output().unit,
            num(lo),
            num(hi),
            d.parameter().name()
        ));
    }
    let dwell = |d: Option<f64>| {
        d.map_or("none up to the range's end".to_string(), |d| {
            format!("{} s", num(d))
        })
    };
    t.push_str(&format!(
        "  shortest dwell at which some table suffices: {} at the parameters' values, {} at the optimistic corner, {} at the pessimistic corner (every parameter moved by one uncertainty towards less or more noise)\n",
        dwell(tr.min_dwell_s()),
        dwell(sens.min_dwell_optimistic_s()),
        dwell(sens.min_dwell_pessimistic_s())
    ));
    t
}

/// The trade-off in words and as a table; with a per-position dwell list, what was scanned
/// (the list scaled alike) and the dwells as means.
#[must_use]
pub(crate) fn tradeoff_text(tr: &Tradeoff, scanned: &Scanned) -> String {
    let mut t = String::new();
    let list = scanned.list_words();
    let mean = if list.is_some() { "mean " } else { "" };
    match tr.min_dwell_s() {
        None => t.push_str(&match &list {
            None => format!(
                "time/table trade-off: no dwell up to {} s per position lets any table meet every accuracy (noise alone exceeds one)\n",
                num(tr.range_s().1)
            ),
            Some(w) => format!(
                "time/table trade-off: no table meets every accuracy at any scale of the study's dwells (noise alone exceeds one); scanned: {w}\n"
            ),
        }),
        Some(d) => {
            if let Some(w) = &list {
                t.push_str(&format!("time/table trade-off, scanned: {w}\n"));
            }
            t.push_str(&format!(
                "time/table trade-off: the shortest {mean}dwell at which some table meets every accuracy is {} s per position{}; the knee (d ln J / d ln T = -1) {}; without noise J = {} arcmin^-2\n",
                num(d),
                if tr.min_dwell_at_range_start() { " (one sample per position already suffices)" } else { "" },
                tr.knee_dwell_s().map_or("is not on the curve".into(), |k| format!("at {} s", num(k))),
                num(objective_to_arcmin(tr.noiseless_objective()))
            ));
            t.push_str(&format!(
                "  {:<13} total test time (s)   J (arcmin^-2)\n",
                format!("{mean}dwell (s)")
            ));
            for p in tr.points() {
                t.push_str(&format!(
                    "  {:<13} {:<21} {}\n",
                    num(p.dwell_s()),
                    num(p.total_s()),
                    p.objective().map_or("none".into(), |j| num(objective_to_arcmin(j)))
                ));
            }
        }
    }
    t
}

/// The yield-based box against its target: the re-measured yield's 95% interval and the
/// verdict, one line; with specifications, then the same turntables against each limit the
/// yield counts ([`tt_lab::end_to_end::yield_limit_lines`], the study's labels escaped).
fn yield_text(r: &ReadingAnswer, left_out: usize) -> String {
    let count = r.yield_count();
    let (lo, hi) = count.interval_95();
    let mut t = format!(
        "  {:<14} target {}%: re-measured on {} independent turntables, yield {:.2}% of {} (95% interval {:.2}-{:.2}%): {}\n",
        "",
        num(100.0 * r.yield_based().target()),
        count.samples(),
        100.0 * count.fraction(),
        tt_lab::end_to_end::yield_counts_words(r, left_out),
        100.0 * lo,
        100.0 * hi,
        match r.yield_verdict() {
            YieldVerdict::Meets => "meets its target",
            YieldVerdict::DoesNotMeet => "does NOT meet its target",
            YieldVerdict::CannotTell => "cannot tell (the interval contains the target)",
        }
    );
    let limits =
        tt_lab::end_to_end::yield_limit_lines(r, &|l| tt_core::human::visible(l).into_owned());
    if !limits.is_empty() {
        t.push_str(&format!(
            "  {:<14} the same turntables against each limit the yield counts:\n",
            ""
        ));
        for l in limits {
            t.push_str(&format!("  {:<14}   {l}\n", ""));
        }
    }
    t
}

/// The outputs (name, unit, precision) with a worst case or Monte Carlo maximum shown as 0 in
/// this reading's boxes: at or below the computation's precision.
fn zeroed_outputs<'a>(e2e: &'a EndToEnd, r: &ReadingAnswer) -> Vec<(&'a str, &'a str, f64)> {
    let mut boxes: Vec<&BoxAnswer> = r.boxes().iter().collect();
    boxes.push(r.direct_box());
    boxes.push(r.yield_box());
    e2e.calibration()
        .outputs()
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            boxes.iter().any(|b| {
                b.worst_case().outputs()[*k].exact_at_vertex() == 0.0
                    || b.distribution().worst()[*k].value() == 0.0
            })
        })
        .map(|(k, o)| {
            (
                o.output().name.as_str(),
                o.output().unit.as_str(),
                e2e.precisions()[k],
            )
        })
        .collect()
}

/// The command's text; `left_out` is the count of the study's specifications no table can
/// meet (left out of the allocations, so not counted by the yield).
#[must_use]
pub(crate) fn to_text(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    note: Option<&String>,
    seconds: f64,
    speed: &Throughput,
    left_out: usize,
) -> String {
    let mut t = format!(
        "end to end: study {} ({}), {} turntables per box, seed {}\n",
        s.name,
        s.path,
        a.inputs().samples,
        a.inputs().seed
    );
    for o in e2e.calibration().outputs() {
        t.push_str(&format!(
            "  output {}: accuracy {} {}\n",
            o.output().name,
            num(o.output().accuracy),
            o.output().unit
        ));
    }
    if let Some(n) = note {
        t.push_str(n);
        t.push('\n');
    }
    t.push_str(&crate::text::groups::text(
        e2e.turntable(),
        &direct_bounds(a),
        "  ",
    ));
    for r in a.readings() {
        t.push_str(&format!(
            "\nreading {} ({})\n",
            r.reading(),
            r.reading().formula()
        ));
        let line = |b: &BoxAnswer| -> String {
            let worst = tt_lab::end_to_end::worst_turntable_words(b, |k, v| {
                format!(
                    "{} {}",
                    e2e.calibration().outputs()[k].output().name,
                    num(v)
                )
            });
            let (lo, hi) = b.distribution().count().interval_95();
            format!(
                "  {:<14} J = {:>9} arcmin^-2  worst case {} (meets every accuracy: {})  yield {:.2}% [{:.2}%, {:.2}%]\n",
                b.name(),
                num(objective_to_arcmin(b.objective())),
                worst,
                b.worst_case().meets(&e2e.accuracies()),
                100.0 * b.distribution().count().fraction(),
                100.0 * lo,
                100.0 * hi
            )
        };
        for b in r.boxes() {
            t.push_str(&line(b));
        }
        t.push_str(&line(r.direct_box()));
        if let Some((d, wc)) = &r.direct_certified() {
            t.push_str(&format!(
                "  {:<14} J = {:>9} arcmin^-2  proven worst case {}\n",
                "certified",
                num(d.objective_arcmin()),
                wc.outputs()
                    .iter()
                    .map(|w| w.certified_bound().map_or("-".into(), num))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        } else if let Some(n) = &r.direct_certified_note() {
            t.push_str(&format!("  {:<14} none: {n}\n", "certified"));
        }
        t.push_str(&line(r.yield_box()));
        t.push_str(&yield_text(r, left_out));
        let zeroed = zeroed_outputs(e2e, r);
        if let Some(n) = crate::out::precision_note(&zeroed) {
            t.push_str(&format!("  ({n})\n"));
        }
    }
    t.push_str(&format!(
        "\nthroughput: fast path {} turntables/s ({} threads), {} on one thread, reference path {} on one thread ({}x); {:.1} s in all\n",
        num(speed.fast_per_s),
        speed.threads,
        num(speed.fast_one_thread_per_s),
        num(speed.reference_per_s),
        num(speed.fast_one_thread_per_s / speed.reference_per_s),
        seconds
    ));
    t
}

/// Run the command.
///
/// # Errors
/// [`InputError`] for bad inputs; other errors if a solver fails.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = args.study.load()?;
    let options = tt_lab::end_to_end::Options {
        samples: args.sampling.samples,
        seed: args.sampling.seed,
        yield_fraction: args.yield_fraction,
        k_sigma: args.uncertainty.k_sigma,
        tolerances: args.tolerances.clone(),
    };
    let r = tt_lab::end_to_end::end_to_end(&s, &options).map_err(crate::input::lab)?;
    let mc = crate::text::jcgm101::run(
        &args.uncertainty.jcgm101,
        args.sampling.seed,
        &s,
        r.simulator(),
        r.answer().readings()[0].direct().upper_bounds_rad(),
        r.decision(),
    )?;
    if args.json {
        let view = crate::text::jcgm101::with_json(&EndToEndJson::of(&s, &r), &s, mc.as_ref())?;
        return crate::json::print(&view);
    }
    let (e2e, a) = (r.simulator(), r.answer());
    let mut t = to_text(
        &s,
        e2e,
        a,
        r.note(),
        r.seconds(),
        r.throughput(),
        r.no_table_suffices().len(),
    );
    if let Some(n) = r.noisy() {
        t.push_str(&noise_text(e2e, a, n));
    }
    if let Some(an) = r.angle() {
        t.push_str(&crate::text::angle_alloc::to_text(e2e, an));
    }
    if let Some((path, al)) = r.sheet() {
        t.push_str(&crate::text::angle::sheet_allocations_text(path, al));
    }
    if let Some(x) = r.rate() {
        t.push_str(&crate::text::rate::allocation_text(e2e, x));
    }
    if let Some(n) = crate::text::noise::note(&s) {
        t.push_str(&n);
        t.push('\n');
    }
    t.push_str(&crate::text::spec_verdict::text(
        &s,
        r.decision(),
        "over the direct allocation's box (the study's reading)",
    ));
    t.push_str(&crate::text::spec_verdict::limited_by(
        a.readings()[0].direct(),
        r.no_table_suffices(),
    ));
    t.push_str(&crate::text::jcgm101::text(
        &args.uncertainty.jcgm101,
        &s,
        mc.as_ref(),
    ));
    crate::out::print(&t)
}
