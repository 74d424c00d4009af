//! `cargo xtask end-to-end [--study FILE] [--samples N] [--seed S] [--yield-fraction P]
//! [--json]`: does the allocated turntable deliver every output's calibration accuracy?
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

use crate::InputError;
use crate::study as st;
use anyhow::Result;
use clap::Parser;
use e2e_verify::{
    BoxAnswer, BuyersAnswer, EndToEnd, EndToEndInputs, McSettings, NoiseAnswer, NoisyDirect,
    ReadingAnswer, Tradeoff, YieldVerdict, answer,
};
use serde_json::{Map, Value, json};
use std::path::PathBuf;
use std::time::Instant;
use study::Study;
use study::fmt::num;
use tt_core::units::objective_to_arcmin;

/// Arguments of `end-to-end`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// Monte Carlo turntables per box (default: the study's `monte_carlo.samples`; accepts
    /// `1e6`, `1000000`, `1_000_000`).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::samples)]
    pub samples: Option<u64>,
    /// Seed of the random streams (default: the study's).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// Target yield of the yield-based allocation, in (0, 1).
    #[arg(long, allow_negative_numbers = true, default_value_t = e2e_verify::DEFAULT_YIELD_FRACTION, value_parser = crate::args::fraction)]
    pub yield_fraction: f64,
    /// Confidence multiplier of the noise part (combined = table + k sigma), in (0, 10];
    /// used when the study gives noise and a timing.
    #[arg(long, allow_negative_numbers = true, default_value_t = e2e_verify::DEFAULT_K_SIGMA, value_parser = crate::args::k_sigma)]
    pub k_sigma: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// A vendor sheet whose magnitudes (`[axes.<joint>]` wobble, orthogonality) pair the
    /// errors: adds the direct and certified allocation with one tolerance per pair, as a
    /// disc and as a square (JSON `disc_allocation`).
    #[arg(long)]
    pub tolerances: Option<std::path::PathBuf>,
}

/// The answer with the noise part: per reading (the order of the answer's readings) every
/// box combined with the noise and the direct allocation that keeps the noise part free; the
/// time/table trade-off under the study's reading.
#[derive(Debug, Clone)]
pub struct NoisyAnswer {
    /// Per reading.
    pub readings: Vec<NoiseAnswer>,
    /// The trade-off (study's reading).
    pub tradeoff: Tradeoff,
}

/// The answer for both error sources, when the study gives noise and a timing.
///
/// # Errors
/// As [`e2e_verify::EndToEnd::noise_answer`] and [`e2e_verify::EndToEnd::tradeoff`].
pub fn noisy_answer(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    k_sigma: f64,
) -> Result<Option<NoisyAnswer>> {
    let (Some(budget), Some(timing)) = (crate::noise::budget(s, e2e)?, &s.timing) else {
        return Ok(None);
    };
    let lb = &a.inputs.lower_bounds_rad;
    let settings = McSettings::new(a.inputs.samples, a.inputs.seed);
    // the trade-off (allocations) beside the readings' answers; those run one after the other
    // (each has a Monte Carlo already on every thread: one at a time keeps the memory of one
    // run); the first error in the serial order returned
    let (readings, tradeoff) = rayon::join(
        || {
            a.readings
                .iter()
                .map(|r| {
                    let sim = if r.reading == e2e.reading() {
                        e2e.clone()
                    } else {
                        e2e.with_reading(r.reading)
                            .map_err(|e| crate::input::library(e, s))?
                    };
                    sim.noise_answer(r, lb, &budget, k_sigma, &settings)
                        .map_err(|e| crate::input::library(e, s))
                })
                .collect::<Vec<Result<_>>>()
        },
        || {
            e2e.tradeoff(
                &e2e.linearization(),
                lb,
                &s.noise,
                timing,
                k_sigma,
                (f64::MIN_POSITIVE, study::limits::DWELL_S.1),
            )
            .map_err(|e| crate::input::library(e, s))
        },
    );
    let readings = readings.into_iter().collect::<Result<Vec<_>>>()?;
    let tradeoff = tradeoff?;
    Ok(Some(NoisyAnswer { readings, tradeoff }))
}

/// The noise part of one reading as JSON.
fn noise_reading_json(e2e: &EndToEnd, n: &NoiseAnswer) -> Value {
    let names = e2e.turntable().rotation_error_names();
    let out_name = |k: usize| e2e.calibration().outputs()[k].output().name.clone();
    let combined = |b: &e2e_verify::CombinedBox| {
        json!({
            "name": b.name,
            "verdict": b.verdict.name(),
            "outputs": b.outputs.iter().map(|c| {
                let mut m = Map::new();
                m.insert("output".into(), json!(out_name(c.output)));
                m.insert("accuracy".into(), json!(c.accuracy));
                m.insert("verdict".into(), json!(c.verdict.name()));
                crate::noise::insert_output_json(&mut m, c);
                Value::Object(m)
            }).collect::<Vec<_>>(),
            "combined_yield": crate::noise::yield_json(&b.combined_yield),
        })
    };
    json!({
        "k_sigma": n.k_sigma,
        "noise_sigma": n.sigma,
        "boxes": n.boxes.iter().map(combined).collect::<Vec<_>>(),
        "direct_with_noise": match &n.direct {
            NoisyDirect::Allocated { allocation, answer } => json!({
                "no_table_suffices": false,
                "objective": allocation.objective_arcmin(),
                "bounds_arcmin": crate::out::arcmin_json(&names, &allocation.upper_bounds_rad),
                "noise_parts": allocation.second_order_margins,
                "box": combined(answer),
            }),
            NoisyDirect::NoTableSuffices { outputs } => json!({
                "no_table_suffices": true,
                "outputs": outputs.iter().map(|o| json!({
                    "output": out_name(o.output),
                    "noise_part": o.noise_part,
                    "lower_bounds_part": o.lower_bounds_part,
                })).collect::<Vec<_>>(),
            }),
        },
    })
}

/// The trade-off's JSON keys: `min_dwell_s`, `knee_dwell_s`, `tradeoff` (list of
/// `{dwell_s, total_s, objective_arcmin}`, `null` where no table suffices) and
/// `noiseless_objective_arcmin`.
fn insert_tradeoff_json(m: &mut Map<String, Value>, t: &Tradeoff) {
    m.insert("k_sigma".into(), json!(t.k_sigma));
    m.insert("min_dwell_s".into(), json!(t.min_dwell_s));
    m.insert(
        "min_dwell_at_one_sample".into(),
        json!(t.min_dwell_at_range_start),
    );
    m.insert("knee_dwell_s".into(), json!(t.knee_dwell_s));
    m.insert("dwell_range_s".into(), json!([t.range_s.0, t.range_s.1]));
    m.insert(
        "noiseless_objective_arcmin".into(),
        json!(objective_to_arcmin(t.noiseless_objective)),
    );
    m.insert(
        "tradeoff".into(),
        Value::Array(
            t.points
                .iter()
                .map(|p| {
                    json!({
                        "dwell_s": p.dwell_s,
                        "total_s": p.total_s,
                        "objective_arcmin": p.objective.map(objective_to_arcmin),
                    })
                })
                .collect(),
        ),
    );
}

/// The noise part of the text: per reading, every box's combined answer and the direct
/// allocation with the noise part kept free; then the trade-off.
#[must_use]
pub fn noise_text(e2e: &EndToEnd, a: &BuyersAnswer, n: &NoisyAnswer) -> String {
    let mut t = String::new();
    let outputs = e2e.calibration().outputs();
    let sigma = &n.readings[0].sigma;
    t.push_str(&format!(
        "\nwith the sensor's noise (calib-lsq's covariance of the calibration, the study's timing), noise part at {} sigma:\n",
        num(n.tradeoff.k_sigma)
    ));
    for (o, s) in outputs.iter().zip(sigma) {
        t.push_str(&format!(
            "  output {}: noise sigma {} {} at the worst position\n",
            o.output().name,
            num(*s),
            o.output().unit
        ));
    }
    for (r, nr) in a.readings.iter().zip(&n.readings) {
        t.push_str(&format!("reading {} with noise\n", r.reading));
        for b in &nr.boxes {
            t.push_str(&format!(
                "  {:<14} verdict {}; {}\n",
                b.name,
                b.verdict.name(),
                crate::noise::yield_text(&b.combined_yield)
            ));
            for c in &b.outputs {
                let out = outputs[c.output].output();
                t.push_str(&format!(
                    "    {}: {}\n",
                    out.name,
                    crate::noise::split_text(c, &out.unit)
                ));
            }
        }
        match &nr.direct {
            NoisyDirect::Allocated { allocation, answer } => t.push_str(&format!(
                "  {:<14} J = {} arcmin^-2 (the table gets what the noise leaves; {} without noise); verdict {}; {}\n",
                "direct, noise",
                num(allocation.objective_arcmin()),
                num(r.direct.objective_arcmin()),
                answer.verdict.name(),
                crate::noise::yield_text(&answer.combined_yield)
            )),
            NoisyDirect::NoTableSuffices { outputs: blocked } => {
                let what: Vec<String> = blocked
                    .iter()
                    .map(|b| {
                        let out = outputs[b.output].output();
                        format!(
                            "{} noise part {} of {} {}",
                            out.name,
                            num(b.noise_part),
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
    t.push_str(&tradeoff_text(&n.tradeoff));
    t
}

/// The trade-off in words and as a table.
#[must_use]
pub fn tradeoff_text(tr: &Tradeoff) -> String {
    let mut t = String::new();
    match tr.min_dwell_s {
        None => t.push_str(&format!(
            "time/table trade-off: no dwell up to {} s per position lets any table meet every accuracy (noise alone exceeds one)\n",
            num(tr.range_s.1)
        )),
        Some(d) => {
            t.push_str(&format!(
                "time/table trade-off: the shortest dwell at which some table meets every accuracy is {} s per position{}; the knee (d ln J / d ln T = -1) {}; without noise J = {} arcmin^-2\n",
                num(d),
                if tr.min_dwell_at_range_start { " (one sample per position already suffices)" } else { "" },
                tr.knee_dwell_s.map_or("is not on the curve".into(), |k| format!("at {} s", num(k))),
                num(objective_to_arcmin(tr.noiseless_objective))
            ));
            t.push_str("  dwell (s)     total test time (s)   J (arcmin^-2)\n");
            for p in &tr.points {
                t.push_str(&format!(
                    "  {:<13} {:<21} {}\n",
                    num(p.dwell_s),
                    num(p.total_s),
                    p.objective.map_or("none".into(), |j| num(objective_to_arcmin(j)))
                ));
            }
        }
    }
    t
}

/// Refuse a Monte Carlo size that cannot resolve the yield target `target` (exit 2, before any
/// work), naming where it came from: `--samples` when `from_flag`, else the study's
/// `monte_carlo.samples` ([`e2e_verify::min_yield_samples`]).
///
/// # Errors
/// An [`InputError`] naming the flag or the key and the smallest count that can do.
pub fn check_yield_samples(
    samples: u64,
    from_flag: bool,
    target: f64,
    s: &Study,
) -> Result<(), InputError> {
    let needed = e2e_verify::min_yield_samples(target);
    if samples >= needed {
        return Ok(());
    }
    let at = if from_flag {
        "--samples".to_string()
    } else {
        format!("{}: key `monte_carlo.samples`", s.path)
    };
    Err(InputError::new(
        at,
        format!(
            "{samples} turntables cannot resolve the yield target {}% of the yield-based allocation: even with none failing, the 95% Wilson interval of the yield reaches below it; at least {needed} are needed (z^2 p / (1 - p), z = 1.96)",
            num(100.0 * target)
        ),
    ))
}

/// The simulator of a study.
///
/// # Errors
/// An [`InputError`] naming the study.
pub fn simulator(s: &Study) -> Result<EndToEnd> {
    EndToEnd::new(&s.turntable, &s.calibration, &st::poses(s)?, s.reading)
        .map_err(|e| crate::input::library(e, s))
}

/// The inputs of the answer for a study: its lower bounds and requirement, the paper's
/// Table 4 as an extra box when the study's turntable is the paper's.
///
/// # Errors
/// An [`InputError`] naming the key.
pub fn inputs(s: &Study, samples: u64, seed: u64, yield_fraction: f64) -> Result<EndToEndInputs> {
    let req = st::requirement(s)?;
    // the requirement of eq 15-16 is static: no two-step allocation with rate steps
    let used = if s.has_rate_steps() { None } else { req.used };
    let mut inputs = EndToEndInputs::new(s.lower_bounds_rad.clone(), used, seed);
    inputs.samples = samples;
    inputs.yield_fraction = yield_fraction;
    if s.turntable == tt_kinematics::paper::table3() {
        inputs
            .extra_boxes
            .push(("Table 4".into(), alloc_opt::paper::table4_rad()));
    }
    Ok(inputs)
}

/// Turntables per second of the fast path (all threads and one) and of the reference path
/// (the plain matrix chain per position and calib-lsq's eq 7-14 analysis of every output, one
/// thread), on draws of the same box, measured in the same run.
#[derive(Debug, Clone, Copy)]
pub struct Throughput {
    /// Draws timed on the fast path.
    pub fast_draws: u64,
    /// Fast path, all threads, turntables/s.
    pub fast_per_s: f64,
    /// Fast path, one thread, turntables/s.
    pub fast_one_thread_per_s: f64,
    /// Draws timed on the reference path.
    pub reference_draws: u64,
    /// Reference path, one thread, turntables/s.
    pub reference_per_s: f64,
    /// Threads of the fast path.
    pub threads: usize,
}

/// Measure [`Throughput`] on the direct allocation's box of `a` (study's reading).
///
/// # Errors
/// As [`EndToEnd::rate_distribution`] (through [`crate::input::library`]).
pub fn throughput(e2e: &EndToEnd, a: &BuyersAnswer, seed: u64) -> Result<Throughput> {
    const FAST: u64 = 200_000;
    const REFERENCE: u64 = 400;
    let r = &a.readings[0];
    let lb = &a.inputs.lower_bounds_rad;
    let bounds = e2e
        .box_of(&r.direct.upper_bounds_rad, lb)
        .map_err(anyhow::Error::new)?;
    let linear = e2e.linearization();
    let t = Instant::now();
    e2e.rate_distribution(&linear, &bounds, &McSettings::new(FAST, seed))
        .map_err(anyhow::Error::new)?;
    let fast = t.elapsed().as_secs_f64();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let t = Instant::now();
    pool.install(|| e2e.rate_distribution(&linear, &bounds, &McSettings::new(FAST / 4, seed)))
        .map_err(anyhow::Error::new)?;
    let one = t.elapsed().as_secs_f64();
    let chis = e2e
        .sample_chi(&bounds, &McSettings::new(REFERENCE, seed))
        .map_err(anyhow::Error::new)?;
    let t = Instant::now();
    let mut sink = 0.0;
    for chi in &chis {
        sink += e2e.run(chi).map_err(anyhow::Error::new)?.delta_omega()[0];
    }
    let reference = t.elapsed().as_secs_f64();
    std::hint::black_box(sink);
    Ok(Throughput {
        fast_draws: FAST,
        fast_per_s: FAST as f64 / fast,
        fast_one_thread_per_s: (FAST / 4) as f64 / one,
        reference_draws: REFERENCE,
        reference_per_s: REFERENCE as f64 / reference,
        threads: rayon::current_num_threads(),
    })
}

fn box_json(e2e: &EndToEnd, b: &BoxAnswer) -> Value {
    let d = &b.distribution;
    let (lo, hi) = d.yield_interval_95();
    let meets = b.worst_case.meets(&e2e.accuracies());
    json!({
        "name": b.name,
        "meets": meets.name(),
        "meets_text": meets.to_string(),
        "meets_excess": meets.excess(),
        "objective": objective_to_arcmin(b.objective),
        "bounds_arcmin": crate::out::arcmin_json(&e2e.turntable().rotation_error_names(), &b.upper_bounds_rad),
        "worst_case": b.worst_case.outputs.iter().map(|w| json!({
            "output": e2e.calibration().outputs()[w.output].output().name,
            "exact_at_vertex": w.exact_at_vertex,
            "linear": w.linear_bound,
            "second_order_bound": w.second_order_bound,
            "position": w.position,
            "per_position": w.per_position,
        })).collect::<Vec<_>>(),
        "yield": d.yield_fraction(),
        "yield_interval_95": [lo, hi],
        "meeting": d.meeting,
        "samples": d.samples,
        "seed": d.seed,
        "max": d.max(),
        "worst_ratio": d.worst_ratio.value,
        "quantiles": d.quantiles.iter().map(|q| json!({"p": q.p, "per_output": q.per_output, "ratio": q.ratio})).collect::<Vec<_>>(),
        "histograms": d.histograms.iter().map(|h| json!({"edges": h.edges(), "counts": h.counts, "overflow": h.overflow})).collect::<Vec<_>>(),
    })
}

fn reading_json(e2e: &EndToEnd, r: &ReadingAnswer) -> Value {
    let names = e2e.turntable().rotation_error_names();
    let mut m = Map::new();
    m.insert("reading".into(), json!(r.reading.to_string()));
    m.insert(
        "boxes".into(),
        Value::Array(r.boxes.iter().map(|b| box_json(e2e, b)).collect()),
    );
    m.insert("direct".into(), json!({
        "objective": r.direct.objective_arcmin(),
        "bounds_arcmin": crate::out::arcmin_json(&names, &r.direct.upper_bounds_rad),
        "unconstrained": r.direct.unconstrained.iter().map(|&j| names[j]).collect::<Vec<_>>(),
        "no_bound_needed": r.direct.no_bound_needed(),
        "active_rows": r.direct.active_rows().iter().map(|row| json!({
            "output": e2e.calibration().outputs()[row.output].output().name,
            "position": row.position,
            "joint_angles_deg": e2e.calibration().schedule().positions()[row.position].joint_angles_deg(),
        })).collect::<Vec<_>>(),
        "box": box_json(e2e, &r.direct_box),
    }));
    m.insert("direct_certified".into(), match &r.direct_certified {
        Some((d, wc)) => json!({
            "objective": d.objective_arcmin(),
            "bounds_arcmin": crate::out::arcmin_json(&names, &d.upper_bounds_rad),
            "second_order_margins": d.second_order_margins,
            "worst_case_exact": wc.exact(),
            "certified_bounds": wc.outputs.iter().map(|w| w.certified_bound()).collect::<Vec<_>>(),
        }),
        None => Value::Null,
    });
    m.insert(
        "direct_certified_note".into(),
        json!(r.direct_certified_note),
    );
    m.insert(
        "yield_based".into(),
        json!({
            "objective": r.yield_based.objective_arcmin(),
            "target": r.yield_based.target,
            "scale": r.yield_based.scale,
            "capped": r.yield_based.capped,
            "design_yield": r.yield_based.yield_fraction(),
            "design_interval_95": [r.yield_based.interval_95.0, r.yield_based.interval_95.1],
            "design_verdict": r.yield_based.design_verdict().name(),
            "verdict": r.yield_verdict().name(),
            "min_samples": e2e_verify::min_yield_samples(r.yield_based.target),
            "bounds_arcmin": crate::out::arcmin_json(&names, &r.yield_based.upper_bounds_rad),
            "remeasured": box_json(e2e, &r.yield_box),
        }),
    );
    Value::Object(m)
}

/// The direct allocations' bounds by label (`direct, <reading>`), for the groups of errors
/// that act only together.
fn direct_bounds(a: &BuyersAnswer) -> Vec<(&str, &[f64])> {
    a.readings
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let label = if i == 0 {
                "direct, study's reading"
            } else {
                "direct, user's reading"
            };
            (label, r.direct.upper_bounds_rad.as_slice())
        })
        .collect()
}

/// The command's JSON object.
#[must_use]
pub fn to_json(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    note: Option<&String>,
    seconds: f64,
    speed: &Throughput,
    noisy: Option<&NoisyAnswer>,
) -> Value {
    let mut v = table_json(s, e2e, a, note, seconds, speed);
    if let (Some(n), Value::Object(m)) = (noisy, &mut v) {
        insert_tradeoff_json(m, &n.tradeoff);
        if let Some(Value::Array(rs)) = m.get_mut("readings") {
            for (r, nr) in rs.iter_mut().zip(&n.readings) {
                if let Value::Object(rm) = r {
                    rm.insert("noise".into(), noise_reading_json(e2e, nr));
                }
            }
        }
    }
    v
}

/// The command's JSON object, the table's part only.
fn table_json(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    note: Option<&String>,
    seconds: f64,
    speed: &Throughput,
) -> Value {
    let names = e2e.turntable().rotation_error_names();
    let r0 = &a.readings[0];
    let mut bounds = Map::new();
    for b in &r0.boxes {
        bounds.insert(
            b.name.clone(),
            crate::out::arcmin_json(&names, &b.upper_bounds_rad),
        );
    }
    bounds.insert(
        "direct".into(),
        crate::out::arcmin_json(&names, &r0.direct.upper_bounds_rad),
    );
    if let Some((d, _)) = &r0.direct_certified {
        bounds.insert(
            "direct_certified".into(),
            crate::out::arcmin_json(&names, &d.upper_bounds_rad),
        );
    }
    bounds.insert(
        "yield_based".into(),
        crate::out::arcmin_json(&names, &r0.yield_based.upper_bounds_rad),
    );
    json!({
        "study": s.path,
        "reading": e2e.reading().to_string(),
        "samples": a.inputs.samples,
        "seed": a.inputs.seed,
        "seconds": seconds,
        "outputs": e2e.calibration().outputs().iter().zip(e2e.precisions()).map(|(o, p)| json!({"name": o.output().name, "unit": o.output().unit, "accuracy": o.output().accuracy, "precision": p})).collect::<Vec<_>>(),
        "errors": names,
        "groups": crate::groups::json(e2e.turntable(), &direct_bounds(a)),
        "two_step_requirement_deg": a.inputs.two_step_requirement.map(|r| crate::out::deg3(&r.to_array())),
        "requirement_note": note,
        "two_step_objective": a.two_step.as_ref().map(|t| t.objective_arcmin()),
        "direct_objective": r0.direct.objective_arcmin(),
        "bounds_arcmin": bounds,
        "readings": a.readings.iter().map(|r| reading_json(e2e, r)).collect::<Vec<_>>(),
        "throughput": {
            "fast_path_turntables_per_s": speed.fast_per_s,
            "fast_path_one_thread_turntables_per_s": speed.fast_one_thread_per_s,
            "reference_path_turntables_per_s": speed.reference_per_s,
            "one_thread_ratio_fast_over_reference": speed.fast_one_thread_per_s / speed.reference_per_s,
            "threads": speed.threads,
            "fast_draws": speed.fast_draws,
            "reference_draws": speed.reference_draws,
        },
    })
}

/// The yield-based box against its target: the re-measured yield's 95% interval and the
/// verdict, one line.
fn yield_text(r: &ReadingAnswer) -> String {
    let (lo, hi) = r.yield_box.distribution.yield_interval_95();
    format!(
        "  {:<14} target {}%: re-measured on {} independent turntables, yield {:.2}% (95% interval {:.2}-{:.2}%): {}\n",
        "",
        num(100.0 * r.yield_based.target),
        r.yield_box.distribution.samples,
        100.0 * r.yield_box.distribution.yield_fraction(),
        100.0 * lo,
        100.0 * hi,
        match r.yield_verdict() {
            YieldVerdict::Meets => "meets its target",
            YieldVerdict::DoesNotMeet => "does NOT meet its target",
            YieldVerdict::CannotTell => "cannot tell (the interval contains the target)",
        }
    )
}

/// The outputs (name, unit, precision) with a worst case or Monte Carlo maximum shown as 0 in
/// this reading's boxes: at or below the computation's precision.
fn zeroed_outputs<'a>(e2e: &'a EndToEnd, r: &ReadingAnswer) -> Vec<(&'a str, &'a str, f64)> {
    let mut boxes: Vec<&BoxAnswer> = r.boxes.iter().collect();
    boxes.push(&r.direct_box);
    boxes.push(&r.yield_box);
    e2e.calibration()
        .outputs()
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            boxes.iter().any(|b| {
                b.worst_case.outputs[*k].exact_at_vertex == 0.0
                    || b.distribution.worst[*k].value == 0.0
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

/// The command's text.
#[must_use]
pub fn to_text(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    note: Option<&String>,
    seconds: f64,
    speed: &Throughput,
) -> String {
    let mut t = format!(
        "end to end: study {} ({}), {} turntables per box, seed {}\n",
        s.name, s.path, a.inputs.samples, a.inputs.seed
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
    t.push_str(&crate::groups::text(
        e2e.turntable(),
        &direct_bounds(a),
        "  ",
    ));
    for r in &a.readings {
        t.push_str(&format!(
            "\nreading {} ({})\n",
            r.reading,
            r.reading.formula()
        ));
        let line = |b: &BoxAnswer| -> String {
            let worst: Vec<String> = b
                .worst_case
                .outputs
                .iter()
                .map(|w| {
                    format!(
                        "{} {}",
                        e2e.calibration().outputs()[w.output].output().name,
                        num(w.exact_at_vertex)
                    )
                })
                .collect();
            let (lo, hi) = b.distribution.yield_interval_95();
            format!(
                "  {:<14} J = {:>9} arcmin^-2  worst case {} (meets every accuracy: {})  yield {:.2}% [{:.2}, {:.2}]\n",
                b.name,
                num(objective_to_arcmin(b.objective)),
                worst.join(", "),
                b.worst_case.meets(&e2e.accuracies()),
                100.0 * b.distribution.yield_fraction(),
                100.0 * lo,
                100.0 * hi
            )
        };
        for b in &r.boxes {
            t.push_str(&line(b));
        }
        t.push_str(&line(&r.direct_box));
        if let Some((d, wc)) = &r.direct_certified {
            t.push_str(&format!(
                "  {:<14} J = {:>9} arcmin^-2  proven worst case {}\n",
                "certified",
                num(d.objective_arcmin()),
                wc.outputs
                    .iter()
                    .map(|w| w.certified_bound().map_or("-".into(), num))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        } else if let Some(n) = &r.direct_certified_note {
            t.push_str(&format!("  {:<14} none: {n}\n", "certified"));
        }
        t.push_str(&line(&r.yield_box));
        t.push_str(&yield_text(r));
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
pub fn run(args: &Args) -> Result<()> {
    let s = st::load(args.study.as_deref())?;
    let e2e = simulator(&s)?;
    let samples = args.samples.unwrap_or(s.monte_carlo.samples);
    let seed = args.seed.unwrap_or(s.monte_carlo.seed);
    check_yield_samples(samples, args.samples.is_some(), args.yield_fraction, &s)?;
    let inputs = inputs(&s, samples, seed, args.yield_fraction)?;
    let note = if s.has_rate_steps() {
        Some(crate::rate::rate_steps_note(&e2e))
    } else {
        st::requirement(&s)?.disagreement
    };
    let t0 = Instant::now();
    let a = answer(&e2e, &inputs).map_err(|e| crate::input::library(e, &s))?;
    let noisy = noisy_answer(&s, &e2e, &a, args.k_sigma)?;
    let seconds = t0.elapsed().as_secs_f64();
    let speed = throughput(&e2e, &a, seed)?;
    let angle = crate::angle_alloc::compute(&s, &e2e)?;
    let sheet = crate::angle_alloc::sheet(&s, args.tolerances.as_deref())?;
    let rate = crate::rate::allocation(&s, &e2e, &e2e_verify::McSettings::new(samples, seed))?;
    if args.json {
        let mut v = to_json(&s, &e2e, &a, note.as_ref(), seconds, &speed, noisy.as_ref());
        if let (Some(an), Value::Object(m)) = (&angle, &mut v) {
            m.insert(
                "angle_dependent".into(),
                crate::angle_alloc::to_json(&e2e, an),
            );
        }
        if let (Some((path, al)), Value::Object(m)) = (&sheet, &mut v) {
            m.insert(
                "disc_allocation".into(),
                crate::angle::sheet_allocations_json(path, al),
            );
        }
        if let (Some(r), Value::Object(m)) = (&rate, &mut v) {
            m.insert(
                "rate_allocation".into(),
                crate::rate::allocation_json(&e2e, r),
            );
        }
        crate::out::print(&(serde_json::to_string_pretty(&v)? + "\n"))
    } else {
        let mut t = to_text(&s, &e2e, &a, note.as_ref(), seconds, &speed);
        if let Some(n) = &noisy {
            t.push_str(&noise_text(&e2e, &a, n));
        }
        if let Some(an) = &angle {
            t.push_str(&crate::angle_alloc::to_text(&e2e, an));
        }
        if let Some((path, al)) = &sheet {
            t.push_str(&crate::angle::sheet_allocations_text(path, al));
        }
        if let Some(r) = &rate {
            t.push_str(&crate::rate::allocation_text(&e2e, r));
        }
        if let Some(n) = crate::noise::note(&s) {
            t.push_str(&n);
            t.push('\n');
        }
        crate::out::print(&t)
    }
}
