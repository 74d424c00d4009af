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
use crate::json::{ArcminBounds, CombinedYieldJson, GroupJson, PerAngle, Split, arcmin_bounds};
use crate::loaded as st;
use anyhow::Result;
use clap::Parser;
use e2e_verify::{
    BoxAnswer, BuyersAnswer, EndToEnd, EndToEndInputs, McSettings, NoiseAnswer, NoisyDirect,
    ReadingAnswer, Tradeoff, YieldVerdict, answer,
};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;
use study::Study;
use study::fmt::{num, sig};
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
    /// What the trade-off scanned.
    pub scanned: Scanned,
    /// The answers at the noise parameters' +- 1 standard uncertainty (`None`: the study
    /// gives no uncertainty, `[sensor.outputs.noise.uncertainty]`).
    pub sensitivity: Option<e2e_verify::NoiseSensitivity>,
}

/// What the time/table trade-off scanned: the study's dwells scaled alike (one factor for
/// every position, the move time and sample rate kept), the factor over a range; with one
/// dwell at every position that is the dwell itself, with a per-position list the list's mean.
#[derive(Debug, Clone, Serialize)]
pub struct Scanned {
    /// Whether the study gives per-position dwells that differ (scaled alike, not each
    /// searched).
    per_position_list: bool,
    /// The factors applied to the study's dwells.
    scale_range: (f64, f64),
    /// The mean dwell over the scan, s (the trade-off's `dwell_s`).
    mean_dwell_range_s: (f64, f64),
    /// The study's shortest dwell scaled over the scan, s.
    shortest_dwell_range_s: (f64, f64),
    /// The study's longest dwell scaled over the scan, s.
    longest_dwell_range_s: (f64, f64),
}

impl Scanned {
    /// What `tr` scanned for the study's `timing`.
    #[must_use]
    pub fn new(tr: &Tradeoff, timing: &calib_lsq::Timing) -> Self {
        let d = timing.dwell_s();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let (lo, hi) = tr.range_s();
        let (f0, f1) = (lo / mean, hi / mean);
        let shortest = d.iter().copied().fold(f64::INFINITY, f64::min);
        let longest = d.iter().copied().fold(0.0, f64::max);
        Self {
            per_position_list: crate::design_budget::uniform_dwell(d).is_none(),
            scale_range: (f0, f1),
            mean_dwell_range_s: (lo, hi),
            shortest_dwell_range_s: (shortest * f0, shortest * f1),
            longest_dwell_range_s: (longest * f0, longest * f1),
        }
    }

    /// With a per-position list: what was scanned, in words (the factor range applied to the
    /// list and the resulting dwell range of its shortest and longest position); `None` for one
    /// dwell at every position.
    #[must_use]
    pub fn list_words(&self) -> Option<String> {
        let r = |(a, b): (f64, f64)| format!("{} to {} s", sig(a, 4), sig(b, 4));
        self.per_position_list.then(|| {
            format!(
                "the study's per-position dwells scaled alike by x{} to x{} (mean dwell {}; its shortest position {}, its longest {}), not each dwell searched on its own",
                sig(self.scale_range.0, 4),
                sig(self.scale_range.1, 4),
                r(self.mean_dwell_range_s),
                r(self.shortest_dwell_range_s),
                r(self.longest_dwell_range_s)
            )
        })
    }
}

/// The dwells the time/table trade-off searches, s: from one sample per position to the
/// study's longest accepted dwell.
pub(crate) const DWELL_SEARCH_S: (f64, f64) = (f64::MIN_POSITIVE, study::limits::DWELL_S.1);

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
    let lb = &a.inputs().lower_bounds_rad;
    let settings = McSettings::new(a.inputs().samples, a.inputs().seed);
    // the trade-off (allocations) beside the readings' answers; those run one after the other
    // (each has a Monte Carlo already on every thread: one at a time keeps the memory of one
    // run); the first error in the serial order returned
    let (readings, tradeoff) = rayon::join(
        || {
            a.readings()
                .iter()
                .map(|r| {
                    let sim = if r.reading() == e2e.reading() {
                        e2e.clone()
                    } else {
                        e2e.with_reading(r.reading())
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
                DWELL_SEARCH_S,
            )
            .map_err(|e| crate::input::library(e, s))
        },
    );
    let readings = readings.into_iter().collect::<Result<Vec<_>>>()?;
    let tradeoff = tradeoff?;
    let scanned = Scanned::new(&tradeoff, timing);
    let sensitivity = e2e
        .noise_sensitivity(
            &e2e.linearization(),
            lb,
            &s.noise,
            timing,
            k_sigma,
            DWELL_SEARCH_S,
        )
        .map_err(|e| crate::input::library(e, s))?;
    Ok(Some(NoisyAnswer {
        readings,
        tradeoff,
        scanned,
        sensitivity,
    }))
}

/// The noise part of the text: per reading, every box's combined answer and the direct
/// allocation with the noise part kept free; then the trade-off.
#[must_use]
pub fn noise_text(e2e: &EndToEnd, a: &BuyersAnswer, n: &NoisyAnswer) -> String {
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
                crate::noise::yield_text(b.combined_yield())
            ));
            for c in b.outputs() {
                let out = outputs[c.output()].output();
                t.push_str(&format!(
                    "    {}: {}\n",
                    out.name,
                    crate::noise::split_text(c, &out.unit)
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
                crate::noise::yield_text(answer.combined_yield())
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
pub fn sensitivity_text(
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
pub fn tradeoff_text(tr: &Tradeoff, scanned: &Scanned) -> String {
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
    tt_lab::loaded::simulator(s).map_err(crate::input::lab)
}

/// The inputs of the answer for a study: its lower bounds and requirement, the paper's
/// Table 4 as an extra box when the study's turntable is the paper's.
///
/// `req` is the study's resolved requirement ([`st::requirement`]): a box search per output,
/// so the caller, which needs it too, resolves it once.
#[must_use]
pub fn inputs_with(
    s: &Study,
    req: &st::StudyRequirement,
    samples: u64,
    seed: u64,
    yield_fraction: f64,
) -> EndToEndInputs {
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
    inputs
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
    let r = &a.readings()[0];
    let lb = &a.inputs().lower_bounds_rad;
    let bounds = e2e
        .box_of(r.direct().upper_bounds_rad(), lb)
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

/// The direct allocations' bounds by label (`direct, <reading>`), for the groups of errors
/// that act only together.
fn direct_bounds(a: &BuyersAnswer) -> Vec<(&str, &[f64])> {
    a.readings()
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let label = if i == 0 {
                "direct, study's reading"
            } else {
                "direct, user's reading"
            };
            (label, r.direct().upper_bounds_rad())
        })
        .collect()
}

/// One output of the calibration (`end-to-end --json` `outputs`).
#[derive(Debug, Serialize)]
struct OutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's, e.g. `deg_per_h`).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// The computation's precision for it ([`EndToEnd::precisions`]), output's unit.
    precision: f64,
}

/// One output's worst case over a box (`worst_case[]`), output's unit.
#[derive(Debug, Serialize)]
struct WorstCaseJson<'a> {
    /// The output's name.
    output: &'a str,
    /// The exact chain at the worst vertex, output's unit.
    exact_at_vertex: f64,
    /// The linearised worst case, output's unit.
    linear: f64,
    /// The certified second-order bound (`null` when not computed), output's unit.
    second_order_bound: Option<f64>,
    /// The worst test position (index into the schedule).
    position: usize,
    /// The linearised worst case at every position, output's unit.
    per_position: &'a [f64],
}

/// A quantile of the Monte Carlo distribution.
#[derive(Debug, Serialize)]
struct QuantileJson<'a> {
    /// The probability, in (0, 1).
    p: f64,
    /// Each output's quantile, output's unit.
    per_output: &'a [f64],
    /// The quantile of the worst ratio to the accuracy (dimensionless).
    ratio: f64,
}

/// A histogram of one output's Monte Carlo distribution.
#[derive(Debug, Serialize)]
struct HistogramJson<'a> {
    /// Bin edges, output's unit.
    edges: Vec<f64>,
    /// Counts per bin.
    counts: &'a [u64],
    /// Draws beyond the last edge.
    overflow: u64,
}

/// One box's answer: worst case, verdict and Monte Carlo yield.
#[derive(Debug, Serialize)]
struct BoxJson<'a> {
    /// The box's name.
    name: &'a str,
    /// `meets`, `does_not_meet`, ... ([`e2e_verify::BoxMeets::name`]).
    meets: &'static str,
    /// The same in the words of the text and the report.
    meets_text: String,
    /// By how much it misses (dimensionless ratio), `null` when it meets.
    meets_excess: Option<f64>,
    /// J of the box, arcmin^-2.
    objective: f64,
    /// The box's bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// Every output's worst case.
    worst_case: Vec<WorstCaseJson<'a>>,
    /// Monte Carlo yield, in [0, 1].
    #[serde(rename = "yield")]
    yield_fraction: f64,
    /// Its 95% interval.
    yield_interval_95: (f64, f64),
    /// Turntables meeting every accuracy.
    meeting: u64,
    /// Turntables drawn.
    samples: u64,
    /// Seed of the random streams.
    seed: u64,
    /// Largest error of each output over the draws, output's unit.
    max: Vec<f64>,
    /// Largest ratio of an output's error to its accuracy (dimensionless).
    worst_ratio: f64,
    /// Quantiles of the distribution.
    quantiles: Vec<QuantileJson<'a>>,
    /// One histogram per output.
    histograms: Vec<HistogramJson<'a>>,
}

impl<'a> BoxJson<'a> {
    fn new(e2e: &'a EndToEnd, b: &'a BoxAnswer) -> Self {
        let d = &b.distribution();
        let meets = b.worst_case().meets(&e2e.accuracies());
        Self {
            name: b.name(),
            meets: meets.name(),
            meets_text: meets.to_string(),
            meets_excess: meets.excess(),
            objective: objective_to_arcmin(b.objective()),
            bounds_arcmin: arcmin_bounds(
                &e2e.turntable().rotation_error_names(),
                b.upper_bounds_rad(),
            ),
            worst_case: b
                .worst_case()
                .outputs()
                .iter()
                .map(|w| WorstCaseJson {
                    output: &e2e.calibration().outputs()[w.output()].output().name,
                    exact_at_vertex: w.exact_at_vertex(),
                    linear: w.linear_bound(),
                    second_order_bound: w.second_order_bound(),
                    position: w.position(),
                    per_position: w.per_position(),
                })
                .collect(),
            yield_fraction: d.count().fraction(),
            yield_interval_95: d.count().interval_95(),
            meeting: d.count().meeting(),
            samples: d.count().samples(),
            seed: d.count().seed(),
            max: d.max(),
            worst_ratio: d.worst_ratio().value(),
            quantiles: d
                .quantiles()
                .iter()
                .map(|q| QuantileJson {
                    p: q.p(),
                    per_output: q.per_output(),
                    ratio: q.ratio(),
                })
                .collect(),
            histograms: d
                .histograms()
                .iter()
                .map(|h| HistogramJson {
                    edges: h.edges(),
                    counts: h.counts(),
                    overflow: h.overflow(),
                })
                .collect(),
        }
    }
}

/// A row of the direct allocation that binds (`active_rows[]`).
#[derive(Debug, Serialize)]
struct ActiveRowJson<'a> {
    /// The output's name.
    output: &'a str,
    /// The test position (index into the schedule).
    position: usize,
    /// Its joint angles, degrees.
    joint_angles_deg: &'a [f64],
}

/// The direct allocation of one reading.
#[derive(Debug, Serialize)]
struct DirectJson<'a> {
    /// J, arcmin^-2.
    objective: f64,
    /// Its bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// The errors no output constrains.
    unconstrained: Vec<&'a str>,
    /// Whether no error needs a bound.
    no_bound_needed: bool,
    /// The binding rows.
    active_rows: Vec<ActiveRowJson<'a>>,
    /// Its box's answer.
    #[serde(rename = "box")]
    box_answer: BoxJson<'a>,
}

/// The certified direct allocation of one reading.
#[derive(Debug, Serialize)]
struct DirectCertifiedJson<'a> {
    /// J, arcmin^-2.
    objective: f64,
    /// Its bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// Each output's margin kept for the second-order terms, output's unit.
    second_order_margins: &'a [f64],
    /// The exact chain's worst case per output, output's unit.
    worst_case_exact: Vec<f64>,
    /// The certified bound per output (`null` when not computed), output's unit.
    certified_bounds: Vec<Option<f64>>,
}

/// The yield-based allocation of one reading.
#[derive(Debug, Serialize)]
struct YieldBasedJson<'a> {
    /// J, arcmin^-2.
    objective: f64,
    /// The target yield, in (0, 1).
    target: f64,
    /// The scale of the direct shape that reaches it (dimensionless).
    scale: f64,
    /// Whether the scale hit its cap.
    capped: bool,
    /// The yield on the design draws, in [0, 1].
    design_yield: f64,
    /// Its 95% interval.
    design_interval_95: (f64, f64),
    /// The design draws' verdict against the target.
    design_verdict: &'static str,
    /// The re-measured verdict against the target.
    verdict: &'static str,
    /// The fewest draws that can show the target ([`e2e_verify::min_yield_samples`]).
    min_samples: u64,
    /// Its bounds, arcmin.
    bounds_arcmin: ArcminBounds,
    /// The box re-measured on independent draws.
    remeasured: BoxJson<'a>,
}

/// One reading's answer (`readings[]`).
#[derive(Debug, Serialize)]
struct ReadingJson<'a> {
    /// The reading of eq 13.
    reading: String,
    /// Every box's answer.
    boxes: Vec<BoxJson<'a>>,
    /// The direct allocation.
    direct: DirectJson<'a>,
    /// The certified direct allocation, `null` when there is none (`direct_certified_note`).
    direct_certified: Option<DirectCertifiedJson<'a>>,
    /// Why there is no certified allocation, else `null`.
    direct_certified_note: Option<&'a str>,
    /// The yield-based allocation.
    yield_based: YieldBasedJson<'a>,
    /// With noise in the study: the noise part of this reading; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    noise: Option<NoiseReadingJson<'a>>,
}

impl<'a> ReadingJson<'a> {
    fn new(e2e: &'a EndToEnd, r: &'a ReadingAnswer, noise: Option<&'a NoiseAnswer>) -> Self {
        let names = e2e.turntable().rotation_error_names();
        Self {
            reading: r.reading().to_string(),
            boxes: r.boxes().iter().map(|b| BoxJson::new(e2e, b)).collect(),
            direct: DirectJson {
                objective: r.direct().objective_arcmin(),
                bounds_arcmin: arcmin_bounds(&names, r.direct().upper_bounds_rad()),
                unconstrained: r
                    .direct()
                    .unconstrained()
                    .iter()
                    .map(|&j| names[j])
                    .collect(),
                no_bound_needed: r.direct().no_bound_needed(),
                active_rows: r
                    .direct()
                    .active_rows()
                    .iter()
                    .map(|row| ActiveRowJson {
                        output: &e2e.calibration().outputs()[row.output()].output().name,
                        position: row.position(),
                        joint_angles_deg: e2e.calibration().schedule().positions()[row.position()]
                            .joint_angles_deg(),
                    })
                    .collect(),
                box_answer: BoxJson::new(e2e, r.direct_box()),
            },
            direct_certified: r.direct_certified().map(|(d, wc)| DirectCertifiedJson {
                objective: d.objective_arcmin(),
                bounds_arcmin: arcmin_bounds(&names, d.upper_bounds_rad()),
                second_order_margins: d.second_order_margins(),
                worst_case_exact: wc.exact(),
                certified_bounds: wc.outputs().iter().map(|w| w.certified_bound()).collect(),
            }),
            direct_certified_note: r.direct_certified_note(),
            yield_based: YieldBasedJson {
                objective: r.yield_based().objective_arcmin(),
                target: r.yield_based().target(),
                scale: r.yield_based().scale(),
                capped: r.yield_based().capped(),
                design_yield: r.yield_based().count().fraction(),
                design_interval_95: r.yield_based().count().interval_95(),
                design_verdict: r.yield_based().design_verdict().name(),
                verdict: r.yield_verdict().name(),
                min_samples: e2e_verify::min_yield_samples(r.yield_based().target()),
                bounds_arcmin: arcmin_bounds(&names, r.yield_based().upper_bounds_rad()),
                remeasured: BoxJson::new(e2e, r.yield_box()),
            },
            noise: noise.map(|n| NoiseReadingJson::new(e2e, n)),
        }
    }
}

/// One output of a box with the noise part (`noise.boxes[].outputs[]`).
#[derive(Debug, Serialize)]
struct CombinedOutputJson<'a> {
    /// The output's name.
    output: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// The verdict counting the noise.
    verdict: &'static str,
    /// The split between the table and the noise.
    #[serde(flatten)]
    split: Split,
}

/// A box's answer with the noise part.
#[derive(Debug, Serialize)]
struct CombinedBoxJson<'a> {
    /// The box's name.
    name: &'a str,
    /// The weakest output's verdict counting the noise.
    verdict: &'static str,
    /// Every output's split.
    outputs: Vec<CombinedOutputJson<'a>>,
    /// The yield over turntables and noise.
    combined_yield: CombinedYieldJson,
}

impl<'a> CombinedBoxJson<'a> {
    fn new(e2e: &'a EndToEnd, b: &'a e2e_verify::CombinedBox) -> Self {
        Self {
            name: b.name(),
            verdict: b.verdict().name(),
            outputs: b
                .outputs()
                .iter()
                .map(|c| CombinedOutputJson {
                    output: &e2e.calibration().outputs()[c.output()].output().name,
                    accuracy: c.accuracy(),
                    verdict: c.verdict().name(),
                    split: c.into(),
                })
                .collect(),
            combined_yield: b.combined_yield().into(),
        }
    }
}

/// An output that leaves no room for the table (`direct_with_noise.outputs[]`), output's unit.
#[derive(Debug, Serialize)]
struct NoRoomJson<'a> {
    /// The output's name.
    output: &'a str,
    /// k sigma of the noise, output's unit.
    noise_part: f64,
    /// The part the errors' lower bounds take, output's unit.
    lower_bounds_part: f64,
}

/// The direct allocation with the noise part kept free.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum DirectWithNoiseJson<'a> {
    /// A table suffices.
    Allocated {
        /// `false`.
        no_table_suffices: bool,
        /// J, arcmin^-2.
        objective: f64,
        /// Its bounds, arcmin.
        bounds_arcmin: ArcminBounds,
        /// Each output's noise part kept free, output's unit.
        noise_parts: &'a [f64],
        /// Its box with the noise part.
        #[serde(rename = "box")]
        box_answer: CombinedBoxJson<'a>,
    },
    /// No table suffices at this dwell.
    NoTableSuffices {
        /// `true`.
        no_table_suffices: bool,
        /// The outputs whose noise leaves no room.
        outputs: Vec<NoRoomJson<'a>>,
    },
}

/// The noise part of one reading (`readings[].noise`).
#[derive(Debug, Serialize)]
struct NoiseReadingJson<'a> {
    /// The confidence multiplier.
    k_sigma: f64,
    /// Each output's noise sigma, output's unit.
    noise_sigma: &'a [f64],
    /// Every box with the noise part.
    boxes: Vec<CombinedBoxJson<'a>>,
    /// The direct allocation with the noise part kept free.
    direct_with_noise: DirectWithNoiseJson<'a>,
}

impl<'a> NoiseReadingJson<'a> {
    fn new(e2e: &'a EndToEnd, n: &'a NoiseAnswer) -> Self {
        let names = e2e.turntable().rotation_error_names();
        Self {
            k_sigma: n.k_sigma(),
            noise_sigma: n.sigma(),
            boxes: n
                .boxes()
                .iter()
                .map(|b| CombinedBoxJson::new(e2e, b))
                .collect(),
            direct_with_noise: match &n.direct() {
                NoisyDirect::Allocated { allocation, answer } => DirectWithNoiseJson::Allocated {
                    no_table_suffices: false,
                    objective: allocation.objective_arcmin(),
                    bounds_arcmin: arcmin_bounds(&names, allocation.upper_bounds_rad()),
                    noise_parts: allocation.second_order_margins(),
                    box_answer: CombinedBoxJson::new(e2e, answer),
                },
                NoisyDirect::NoTableSuffices { outputs } => DirectWithNoiseJson::NoTableSuffices {
                    no_table_suffices: true,
                    outputs: outputs
                        .iter()
                        .map(|o| NoRoomJson {
                            output: &e2e.calibration().outputs()[o.output()].output().name,
                            noise_part: o.noise_part(),
                            lower_bounds_part: o.lower_bounds_part(),
                        })
                        .collect(),
                },
            },
        }
    }
}

/// A point of the time/table trade-off.
#[derive(Debug, Serialize)]
struct TradeoffPointJson {
    /// Dwell per position, s.
    dwell_s: f64,
    /// Total test time, s.
    total_s: f64,
    /// J of the direct allocation with the noise part kept free, arcmin^-2; `null` where no
    /// table suffices.
    objective_arcmin: Option<f64>,
}

/// The time/table trade-off (top-level keys, with noise in the study).
#[derive(Debug, Serialize)]
struct TradeoffJson {
    /// The confidence multiplier.
    k_sigma: f64,
    /// The shortest dwell at which some table suffices, s (`null`: none in the range).
    min_dwell_s: Option<f64>,
    /// Whether that shortest dwell is the range's start (one sample).
    min_dwell_at_one_sample: bool,
    /// The dwell past which a longer one buys little, s.
    knee_dwell_s: Option<f64>,
    /// The dwells searched, s (the mean dwell for a per-position list).
    dwell_range_s: (f64, f64),
    /// What was scanned: the study's dwells scaled alike (`per_position_list`,
    /// `scale_range`, `mean_dwell_range_s`, `shortest_dwell_range_s`,
    /// `longest_dwell_range_s`).
    dwell_scan: Scanned,
    /// J without noise, arcmin^-2.
    noiseless_objective_arcmin: f64,
    /// The trade-off's points.
    tradeoff: Vec<TradeoffPointJson>,
}

impl From<&NoisyAnswer> for TradeoffJson {
    fn from(n: &NoisyAnswer) -> Self {
        let t = &n.tradeoff;
        Self {
            dwell_scan: n.scanned.clone(),
            k_sigma: t.k_sigma(),
            min_dwell_s: t.min_dwell_s(),
            min_dwell_at_one_sample: t.min_dwell_at_range_start(),
            knee_dwell_s: t.knee_dwell_s(),
            dwell_range_s: t.range_s(),
            noiseless_objective_arcmin: objective_to_arcmin(t.noiseless_objective()),
            tradeoff: t
                .points()
                .iter()
                .map(|p| TradeoffPointJson {
                    dwell_s: p.dwell_s(),
                    total_s: p.total_s(),
                    objective_arcmin: p.objective().map(objective_to_arcmin),
                })
                .collect(),
        }
    }
}

/// The throughput measured in the same run (`throughput`).
#[derive(Debug, Serialize)]
struct ThroughputJson {
    /// Fast path, all threads, turntables/s.
    fast_path_turntables_per_s: f64,
    /// Fast path, one thread, turntables/s.
    fast_path_one_thread_turntables_per_s: f64,
    /// Reference path, one thread, turntables/s.
    reference_path_turntables_per_s: f64,
    /// The two one-thread rates' ratio (dimensionless).
    one_thread_ratio_fast_over_reference: f64,
    /// Threads of the fast path.
    threads: usize,
    /// Draws timed on the fast path.
    fast_draws: u64,
    /// Draws timed on the reference path.
    reference_draws: u64,
}

/// `end-to-end --json`: the command's whole answer.
#[derive(Debug, Serialize)]
pub struct EndToEndJson<'a> {
    /// The study's path.
    study: &'a str,
    /// The study's reading of eq 13.
    reading: String,
    /// Monte Carlo turntables per box.
    samples: u64,
    /// Seed of the random streams.
    seed: u64,
    /// Time of the answer, s.
    seconds: f64,
    /// The calibration's outputs.
    outputs: Vec<OutputJson<'a>>,
    /// The table's error names.
    errors: Vec<&'a str>,
    /// Errors that act only together, with their combination's bound under each direct
    /// allocation.
    groups: Vec<GroupJson>,
    /// The two-step allocation's orientation requirement, degrees (`null` without one).
    two_step_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// Why the requirement is not the study's, or the rate steps' note; else `null`.
    requirement_note: Option<&'a str>,
    /// J of the two-step allocation, arcmin^-2 (`null` without one).
    two_step_objective: Option<f64>,
    /// J of the direct allocation under the study's reading, arcmin^-2.
    direct_objective: f64,
    /// Every box's bounds under the study's reading (the boxes by name, `direct`,
    /// `direct_certified`, `yield_based`), arcmin.
    bounds_arcmin: BTreeMap<String, ArcminBounds>,
    /// Per reading: every box's answer and the allocations.
    readings: Vec<ReadingJson<'a>>,
    /// Turntables per second measured in the same run.
    throughput: ThroughputJson,
    /// With noise in the study: the time/table trade-off (its keys at the top level).
    #[serde(flatten)]
    tradeoff: Option<TradeoffJson>,
    /// `angle_dependent`, `disc_allocation` and `rate_allocation` (each absent when it does
    /// not apply).
    #[serde(flatten)]
    extras: crate::json::ExtrasJson<'a>,
    /// The decision rule and the verdict against the study's specifications per quantity
    /// (the GUM budget of each over the direct allocation's box, study's reading); the
    /// accuracy rule without.
    decision: Option<crate::spec_verdict::SpecVerdictJson>,
}

impl<'a> EndToEndJson<'a> {
    /// The command's JSON view of the answer `a` of `e2e` for study `s`.
    #[must_use]
    pub fn new(
        s: &'a Study,
        e2e: &'a EndToEnd,
        a: &'a BuyersAnswer,
        note: Option<&'a String>,
        seconds: f64,
        speed: &Throughput,
        noisy: Option<&'a NoisyAnswer>,
    ) -> Self {
        let names = e2e.turntable().rotation_error_names();
        let r0 = &a.readings()[0];
        let mut bounds: BTreeMap<String, ArcminBounds> = r0
            .boxes()
            .iter()
            .map(|b| {
                (
                    b.name().to_string(),
                    arcmin_bounds(&names, b.upper_bounds_rad()),
                )
            })
            .collect();
        bounds.insert(
            "direct".into(),
            arcmin_bounds(&names, r0.direct().upper_bounds_rad()),
        );
        if let Some((d, _)) = &r0.direct_certified() {
            bounds.insert(
                "direct_certified".into(),
                arcmin_bounds(&names, d.upper_bounds_rad()),
            );
        }
        bounds.insert(
            "yield_based".into(),
            arcmin_bounds(&names, r0.yield_based().upper_bounds_rad()),
        );
        Self {
            study: &s.path,
            reading: e2e.reading().to_string(),
            samples: a.inputs().samples,
            seed: a.inputs().seed,
            seconds,
            outputs: e2e
                .calibration()
                .outputs()
                .iter()
                .zip(e2e.precisions())
                .map(|(o, p)| OutputJson {
                    name: &o.output().name,
                    unit: &o.output().unit,
                    accuracy: o.output().accuracy,
                    precision: *p,
                })
                .collect(),
            errors: names.clone(),
            groups: GroupJson::all(e2e.turntable(), &direct_bounds(a)),
            two_step_requirement_deg: a
                .inputs()
                .two_step_requirement
                .map(|r| crate::json::deg3(&r.to_array())),
            requirement_note: note.map(String::as_str),
            two_step_objective: a.two_step().map(|t| t.objective_arcmin()),
            direct_objective: r0.direct().objective_arcmin(),
            bounds_arcmin: bounds,
            readings: a
                .readings()
                .iter()
                .enumerate()
                .map(|(i, r)| ReadingJson::new(e2e, r, noisy.and_then(|n| n.readings.get(i))))
                .collect(),
            throughput: ThroughputJson {
                fast_path_turntables_per_s: speed.fast_per_s,
                fast_path_one_thread_turntables_per_s: speed.fast_one_thread_per_s,
                reference_path_turntables_per_s: speed.reference_per_s,
                one_thread_ratio_fast_over_reference: speed.fast_one_thread_per_s
                    / speed.reference_per_s,
                threads: speed.threads,
                fast_draws: speed.fast_draws,
                reference_draws: speed.reference_draws,
            },
            tradeoff: noisy.map(Into::into),
            extras: crate::json::ExtrasJson::default(),
            decision: None,
        }
    }
}

/// The yield-based box against its target: the re-measured yield's 95% interval and the
/// verdict, one line.
fn yield_text(r: &ReadingAnswer) -> String {
    let (lo, hi) = r.yield_box().distribution().count().interval_95();
    format!(
        "  {:<14} target {}%: re-measured on {} independent turntables, yield {:.2}% (95% interval {:.2}-{:.2}%): {}\n",
        "",
        num(100.0 * r.yield_based().target()),
        r.yield_box().distribution().count().samples(),
        100.0 * r.yield_box().distribution().count().fraction(),
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
    t.push_str(&crate::groups::text(
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
            let worst: Vec<String> = b
                .worst_case()
                .outputs()
                .iter()
                .map(|w| {
                    format!(
                        "{} {}",
                        e2e.calibration().outputs()[w.output()].output().name,
                        num(w.exact_at_vertex())
                    )
                })
                .collect();
            let (lo, hi) = b.distribution().count().interval_95();
            format!(
                "  {:<14} J = {:>9} arcmin^-2  worst case {} (meets every accuracy: {})  yield {:.2}% [{:.2}%, {:.2}%]\n",
                b.name(),
                num(objective_to_arcmin(b.objective())),
                worst.join(", "),
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
    // the requirement (a box search per output) once, for the inputs and the note
    let req = st::requirement(&s)?;
    let inputs = inputs_with(&s, &req, samples, seed, args.yield_fraction);
    let note = if s.has_rate_steps() {
        Some(crate::rate::rate_steps_note(&e2e))
    } else {
        req.disagreement
    };
    let t0 = Instant::now();
    let a = answer(&e2e, &inputs).map_err(|e| crate::input::library(e, &s))?;
    let noisy = noisy_answer(&s, &e2e, &a, args.k_sigma)?;
    let seconds = t0.elapsed().as_secs_f64();
    let speed = throughput(&e2e, &a, seed)?;
    let angle = crate::angle_alloc::compute(&s, &e2e)?;
    let sheet = crate::angle_alloc::sheet(&s, args.tolerances.as_deref())?;
    let rate = crate::rate::allocation(&s, &e2e, &e2e_verify::McSettings::new(samples, seed))?;
    let decision =
        crate::spec_verdict::compute(&s, &e2e, a.readings()[0].direct().upper_bounds_rad())?;
    if args.json {
        let mut v = EndToEndJson::new(&s, &e2e, &a, note.as_ref(), seconds, &speed, noisy.as_ref());
        v.extras.angle_dependent = angle
            .as_ref()
            .map(|an| crate::angle_alloc::AngleDependentJson::new(&e2e, an));
        v.extras.disc_allocation = sheet
            .as_ref()
            .map(|(path, al)| crate::angle::SheetAllocationsJson::new(path, al));
        v.extras.rate_allocation = rate
            .as_ref()
            .map(|r| crate::rate::RateAllocationJson::new(&e2e, r));
        v.decision = Some(crate::spec_verdict::SpecVerdictJson::new(
            &s,
            decision.as_ref(),
        ));
        crate::json::print(&v)
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
        t.push_str(&crate::spec_verdict::text(
            &s,
            decision.as_ref(),
            "over the direct allocation's box (the study's reading)",
        ));
        crate::out::print(&t)
    }
}
