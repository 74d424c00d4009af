//! The end-to-end question ([`end_to_end`], the command line's `end-to-end`): does the
//! allocated turntable deliver every output's calibration accuracy?
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
use crate::Result;
use crate::allocation::spec::NoTableSuffices;
use crate::json::{ArcminBounds, CombinedYieldJson, GroupJson, PerAngle, Split, arcmin_bounds};
use crate::loaded as st;
use e2e_verify::{
    BoxAnswer, BuyersAnswer, EndToEnd, EndToEndInputs, McSettings, NoiseAnswer, NoisyDirect,
    ReadingAnswer, Tradeoff, TradeoffInputs, answer,
};
use std::collections::BTreeMap;
use std::time::Instant;
use study::Study;
use tt_core::human::{num, sig};
use tt_core::units::objective_to_arcmin;

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
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
            per_position_list: crate::end_to_end::uniform_dwell(d).is_none(),
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

/// The time/table trade-off's inputs for study `s` on `linear`: its noise with `timing`, the
/// lower bounds `lower_bounds_rad`, $\kappa$ `k_sigma` and the dwells [`DWELL_SEARCH_S`].
pub(crate) fn tradeoff_inputs<'a>(
    s: &'a Study,
    linear: &'a e2e_verify::Linearization,
    lower_bounds_rad: &'a [f64],
    timing: &'a calib_lsq::Timing,
    k_sigma: f64,
) -> TradeoffInputs<'a> {
    TradeoffInputs {
        linear,
        lower_bounds_rad,
        noise: &s.noise,
        timing,
        k_sigma,
        dwell_range_s: DWELL_SEARCH_S,
    }
}

/// The answer for both error sources, when the study gives noise and a timing.
///
/// # Errors
/// As [`e2e_verify::NoiseQuestions::noise_answer`] and [`e2e_verify::NoiseQuestions::tradeoff`].
pub fn noisy_answer(
    s: &Study,
    e2e: &EndToEnd,
    a: &BuyersAnswer,
    k_sigma: f64,
) -> Result<Option<NoisyAnswer>> {
    let (Some(budget), Some(timing)) = (crate::end_to_end::noise_budget(s, e2e)?, &s.timing) else {
        return Ok(None);
    };
    let lb = &a.inputs().lower_bounds_rad;
    let settings = McSettings::new(a.inputs().samples, a.inputs().seed);
    let linear = e2e.linearization();
    let question = tradeoff_inputs(s, &linear, lb, timing, k_sigma);
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
                            .map_err(|e| crate::error::library(e, s))?
                    };
                    sim.noise()
                        .noise_answer(r, lb, &budget, k_sigma, &settings)
                        .map_err(|e| crate::error::library(e, s))
                })
                .collect::<Vec<Result<_>>>()
        },
        || {
            e2e.noise()
                .tradeoff(&question)
                .map_err(|e| crate::error::library(e, s))
        },
    );
    let readings = readings.into_iter().collect::<Result<Vec<_>>>()?;
    let tradeoff = tradeoff?;
    let scanned = Scanned::new(&tradeoff, timing);
    let sensitivity = e2e
        .noise()
        .noise_sensitivity(&question)
        .map_err(|e| crate::error::library(e, s))?;
    Ok(Some(NoisyAnswer {
        readings,
        tradeoff,
        scanned,
        sensitivity,
    }))
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
    // the paper's named box beside the answer (the `paper` feature)
    #[cfg(feature = "paper")]
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
/// As [`e2e_verify::MonteCarloQuestions::rate_distribution`] (through [`crate::error::library`]).
pub(crate) fn throughput(e2e: &EndToEnd, a: &BuyersAnswer, seed: u64) -> Result<Throughput> {
    const FAST: u64 = 200_000;
    const REFERENCE: u64 = 400;
    let r = &a.readings()[0];
    let lb = &a.inputs().lower_bounds_rad;
    let bounds = e2e
        .box_of(r.direct().upper_bounds_rad(), lb)
        .map_err(crate::LabError::internal)?;
    let linear = e2e.linearization();
    let t = Instant::now();
    e2e.monte_carlo()
        .rate_distribution(&linear, &bounds, &McSettings::new(FAST, seed))
        .map_err(crate::LabError::internal)?;
    let fast = t.elapsed().as_secs_f64();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(crate::LabError::internal)?;
    let t = Instant::now();
    pool.install(|| {
        e2e.monte_carlo()
            .rate_distribution(&linear, &bounds, &McSettings::new(FAST / 4, seed))
    })
    .map_err(crate::LabError::internal)?;
    let one = t.elapsed().as_secs_f64();
    let chis = e2e
        .monte_carlo()
        .sample_chi(&bounds, &McSettings::new(REFERENCE, seed))
        .map_err(crate::LabError::internal)?;
    let t = Instant::now();
    let mut sink = 0.0;
    for chi in &chis {
        sink += e2e
            .run(chi)
            .map_err(crate::LabError::internal)?
            .delta_omega()[0];
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
pub fn direct_bounds(a: &BuyersAnswer) -> Vec<(&str, &[f64])> {
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct OutputJson<'a> {
    /// The output's name.
    pub name: &'a str,
    /// Its unit (the study's, e.g. `deg_per_h`).
    pub unit: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// The computation's precision for it ([`EndToEnd::precisions`]), output's unit.
    pub precision: f64,
}

/// One output's worst case over a box (`worst_case[]`), output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct WorstCaseJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// The exact chain at the worst vertex, output's unit.
    pub exact_at_vertex: f64,
    /// The linearised worst case, output's unit.
    pub linear: f64,
    /// The certified second-order bound (`null` when not computed), output's unit.
    pub second_order_bound: Option<f64>,
    /// The worst test position (index into the schedule).
    pub position: usize,
    /// The linearised worst case at every position, output's unit.
    pub per_position: &'a [f64],
}

/// A quantile of the Monte Carlo distribution.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct QuantileJson<'a> {
    /// The probability, in (0, 1).
    pub p: f64,
    /// Each output's quantile, output's unit.
    pub per_output: &'a [f64],
    /// The quantile of the worst ratio to the accuracy (dimensionless).
    pub ratio: f64,
}

/// A histogram of one output's Monte Carlo distribution.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct HistogramJson<'a> {
    /// Bin edges, output's unit.
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: &'a [u64],
    /// Draws beyond the last edge.
    pub overflow: u64,
}

/// One box's answer: worst case, verdict and Monte Carlo yield.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct BoxJson<'a> {
    /// The box's name.
    pub name: &'a str,
    /// `meets`, `does_not_meet`, ... ([`e2e_verify::BoxMeets::name`]).
    pub meets: &'static str,
    /// The same in the words of the text and the report.
    pub meets_text: String,
    /// By how much it misses (dimensionless ratio), `null` when it meets.
    pub meets_excess: Option<f64>,
    /// J of the box, arcmin^-2.
    pub objective: f64,
    /// The box's bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// Every output's worst case.
    pub worst_case: Vec<WorstCaseJson<'a>>,
    /// Monte Carlo yield, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables meeting every accuracy.
    pub meeting: u64,
    /// Turntables drawn.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Largest error of each output over the draws, output's unit.
    pub max: Vec<f64>,
    /// Largest ratio of an output's error to its accuracy (dimensionless).
    pub worst_ratio: f64,
    /// Quantiles of the distribution.
    pub quantiles: Vec<QuantileJson<'a>>,
    /// One histogram per output.
    pub histograms: Vec<HistogramJson<'a>>,
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ActiveRowJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// The test position (index into the schedule).
    pub position: usize,
    /// Its joint angles, degrees.
    pub joint_angles_deg: &'a [f64],
}

/// The errors a direct allocation leaves without a bound (`unconstrained`,
/// `no_bound_needed`): flattened into `end-to-end --json`'s `direct` and into the report's
/// `results.json` end to end.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct UnconstrainedJson<'a> {
    /// The errors no output constrains.
    pub unconstrained: Vec<&'a str>,
    /// Whether no error needs a bound.
    pub no_bound_needed: bool,
}

impl<'a> UnconstrainedJson<'a> {
    /// Those of `d`, named by `names` (the errors in the order of $\chi$).
    #[must_use]
    pub fn new(d: &e2e_verify::DirectAllocation, names: &[&'a str]) -> Self {
        Self {
            unconstrained: d.unconstrained().iter().map(|&j| names[j]).collect(),
            no_bound_needed: d.no_bound_needed(),
        }
    }
}

/// The direct allocation of one reading.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct DirectJson<'a> {
    /// J, arcmin^-2.
    pub objective: f64,
    /// Its bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// The errors no output constrains and whether any error needs a bound.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub unconstrained: UnconstrainedJson<'a>,
    /// The binding rows.
    pub active_rows: Vec<ActiveRowJson<'a>>,
    /// The specifications whose rows bind it, `label (unit)` (empty without specifications;
    /// [`e2e_verify::DirectAllocation::limited_by`]).
    pub limited_by: Vec<&'a str>,
    /// Its box's answer.
    #[cfg_attr(feature = "serde", serde(rename = "box"))]
    pub box_answer: BoxJson<'a>,
}

/// The certified direct allocation of one reading.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct DirectCertifiedJson<'a> {
    /// J, arcmin^-2.
    pub objective: f64,
    /// Its bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// Each output's margin kept for the second-order terms, output's unit.
    pub second_order_margins: &'a [f64],
    /// The exact chain's worst case per output, output's unit.
    pub worst_case_exact: Vec<f64>,
    /// The certified bound per output (`null` when not computed), output's unit.
    pub certified_bounds: Vec<Option<f64>>,
}

/// The yield-based allocation of one reading.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct YieldBasedJson<'a> {
    /// J, arcmin^-2.
    pub objective: f64,
    /// The target yield, in (0, 1).
    pub target: f64,
    /// The scale of the direct shape that reaches it (dimensionless).
    pub scale: f64,
    /// Whether the scale hit its cap.
    pub capped: bool,
    /// The yield on the design draws, in [0, 1].
    pub design_yield: f64,
    /// Its 95% interval.
    pub design_interval_95: (f64, f64),
    /// The design draws' verdict against the target.
    pub design_verdict: &'static str,
    /// The re-measured verdict against the target.
    pub verdict: &'static str,
    /// The fewest draws that can show the target ([`e2e_verify::min_yield_samples`]).
    pub min_samples: u64,
    /// Its bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// The box re-measured on independent draws.
    pub remeasured: BoxJson<'a>,
    /// With specifications: what the yield counts and the draws meeting every specification
    /// (design and re-measured); absent without (the yield counts every accuracy).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub specifications: Option<YieldSpecificationsJson<'a>>,
    /// The specifications no table can meet, left out of the allocations and not counted by
    /// the yield (the list the text and the report give, its figures in each one's unit,
    /// unrounded; [`EndToEndAnswer::no_table_suffices`]); absent when there is none. Beside
    /// `specifications`, not in it: that view is absent when no specification leaves room.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "<[_]>::is_empty"))]
    pub not_counted: &'a [NoTableSuffices],
}

/// The yield-based allocation's count against the specifications
/// (`readings[].yield_based.specifications`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct YieldSpecificationsJson<'a> {
    /// What the yield counts ([`e2e_verify::SPECIFIED_YIELD_COUNTS`], with the
    /// specifications no table can meet named as not counted: [`yield_counts_words`]).
    pub counts: String,
    /// Design draws.
    pub design_samples: u64,
    /// Design draws meeting every accuracy and every specification.
    pub design_meeting: u64,
    /// Per specification, the design draws meeting it.
    pub design_per_specification: Vec<SpecificationMeetingJson<'a>>,
    /// Re-measured draws (independent seed).
    pub remeasured_samples: u64,
    /// Re-measured draws meeting every accuracy and every specification.
    pub remeasured_meeting: u64,
    /// Their yield and its 95% interval (the verdict's).
    pub remeasured_yield: f64,
    /// Its 95% interval.
    pub remeasured_interval_95: (f64, f64),
    /// Per specification, the re-measured draws meeting it.
    pub remeasured_per_specification: Vec<SpecificationMeetingJson<'a>>,
}

/// The draws meeting one specification.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct SpecificationMeetingJson<'a> {
    /// The specification, `label in unit`.
    pub specification: &'a str,
    /// Draws meeting it.
    pub meeting: u64,
}

impl<'a> YieldSpecificationsJson<'a> {
    /// The view of `r`'s count, `left_out` specifications no table can meet named as not
    /// counted in its words ([`yield_counts_words`]).
    fn new(r: &'a ReadingAnswer, left_out: usize) -> Option<Self> {
        let again = r.yield_recheck()?;
        let y = r.yield_based().counted();
        let each = |per: &'a [(String, u64)]| -> Vec<SpecificationMeetingJson<'a>> {
            per.iter()
                .map(|(label, meeting)| SpecificationMeetingJson {
                    specification: label,
                    meeting: *meeting,
                })
                .collect()
        };
        Some(Self {
            counts: yield_counts_words(r, left_out),
            design_samples: y.count().samples(),
            design_meeting: y.count().meeting(),
            design_per_specification: each(y.per_specification()),
            remeasured_samples: again.count().samples(),
            remeasured_meeting: again.count().meeting(),
            remeasured_yield: again.count().fraction(),
            remeasured_interval_95: again.count().interval_95(),
            remeasured_per_specification: each(again.per_specification()),
        })
    }
}

/// One reading's answer (`readings[]`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ReadingJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// Every box's answer.
    pub boxes: Vec<BoxJson<'a>>,
    /// The direct allocation.
    pub direct: DirectJson<'a>,
    /// The certified direct allocation, `null` when there is none (`direct_certified_note`).
    pub direct_certified: Option<DirectCertifiedJson<'a>>,
    /// Why there is no certified allocation, else `null`.
    pub direct_certified_note: Option<&'a str>,
    /// The yield-based allocation.
    pub yield_based: YieldBasedJson<'a>,
    /// With noise in the study: the noise part of this reading; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub noise: Option<NoiseReadingJson<'a>>,
}

impl<'a> ReadingJson<'a> {
    /// The view of reading `r` of `e2e`, with its noise answer and the specifications no
    /// table can meet (`not_counted`: left out of its allocations and its yield's count).
    fn new(
        e2e: &'a EndToEnd,
        r: &'a ReadingAnswer,
        noise: Option<&'a NoiseAnswer>,
        not_counted: &'a [NoTableSuffices],
    ) -> Self {
        let names = e2e.turntable().rotation_error_names();
        Self {
            reading: r.reading().to_string(),
            boxes: r.boxes().iter().map(|b| BoxJson::new(e2e, b)).collect(),
            direct: DirectJson {
                objective: r.direct().objective_arcmin(),
                bounds_arcmin: arcmin_bounds(&names, r.direct().upper_bounds_rad()),
                unconstrained: UnconstrainedJson::new(r.direct(), &names),
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
                limited_by: r.direct().limited_by(),
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
                design_yield: r.yield_based().counted().count().fraction(),
                design_interval_95: r.yield_based().counted().count().interval_95(),
                design_verdict: r.yield_based().design_verdict().name(),
                verdict: r.yield_verdict().name(),
                min_samples: e2e_verify::min_yield_samples(r.yield_based().target()),
                bounds_arcmin: arcmin_bounds(&names, r.yield_based().upper_bounds_rad()),
                remeasured: BoxJson::new(e2e, r.yield_box()),
                specifications: YieldSpecificationsJson::new(r, not_counted.len()),
                not_counted,
            },
            noise: noise.map(|n| NoiseReadingJson::new(e2e, n)),
        }
    }
}

/// One output of a box with the noise part (`noise.boxes[].outputs[]`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CombinedOutputJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// The verdict counting the noise.
    pub verdict: &'static str,
    /// The split between the table and the noise.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub split: Split,
}

/// A box's answer with the noise part.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CombinedBoxJson<'a> {
    /// The box's name.
    pub name: &'a str,
    /// The weakest output's verdict counting the noise.
    pub verdict: &'static str,
    /// Every output's split.
    pub outputs: Vec<CombinedOutputJson<'a>>,
    /// The yield over turntables and noise.
    pub combined_yield: CombinedYieldJson,
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct NoRoomJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// k sigma of the noise, output's unit.
    pub noise_part: f64,
    /// The part the errors' lower bounds take, output's unit.
    pub lower_bounds_part: f64,
}

/// The direct allocation with the noise part kept free.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub(crate) enum DirectWithNoiseJson<'a> {
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
        #[cfg_attr(feature = "serde", serde(rename = "box"))]
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct NoiseReadingJson<'a> {
    /// The confidence multiplier.
    pub k_sigma: f64,
    /// Each output's noise sigma, output's unit.
    pub noise_sigma: &'a [f64],
    /// Every box with the noise part.
    pub boxes: Vec<CombinedBoxJson<'a>>,
    /// The direct allocation with the noise part kept free.
    pub direct_with_noise: DirectWithNoiseJson<'a>,
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct TradeoffPointJson {
    /// Dwell per position, s.
    pub dwell_s: f64,
    /// Total test time, s.
    pub total_s: f64,
    /// J of the direct allocation with the noise part kept free, arcmin^-2; `null` where no
    /// table suffices.
    pub objective_arcmin: Option<f64>,
}

/// The time/table trade-off (top-level keys, with noise in the study).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct TradeoffJson {
    /// The confidence multiplier.
    pub k_sigma: f64,
    /// The shortest dwell at which some table suffices, s (`null`: none in the range).
    pub min_dwell_s: Option<f64>,
    /// Whether that shortest dwell is the range's start (one sample).
    pub min_dwell_at_one_sample: bool,
    /// The dwell past which a longer one buys little, s.
    pub knee_dwell_s: Option<f64>,
    /// The dwells searched, s (the mean dwell for a per-position list).
    pub dwell_range_s: (f64, f64),
    /// What was scanned: the study's dwells scaled alike (`per_position_list`,
    /// `scale_range`, `mean_dwell_range_s`, `shortest_dwell_range_s`,
    /// `longest_dwell_range_s`).
    pub dwell_scan: Scanned,
    /// J without noise, arcmin^-2.
    pub noiseless_objective_arcmin: f64,
    /// The trade-off's points.
    pub tradeoff: Vec<TradeoffPointJson>,
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ThroughputJson {
    /// Fast path, all threads, turntables/s.
    pub fast_path_turntables_per_s: f64,
    /// Fast path, one thread, turntables/s.
    pub fast_path_one_thread_turntables_per_s: f64,
    /// Reference path, one thread, turntables/s.
    pub reference_path_turntables_per_s: f64,
    /// The two one-thread rates' ratio (dimensionless).
    pub one_thread_ratio_fast_over_reference: f64,
    /// Threads of the fast path.
    pub threads: usize,
    /// Draws timed on the fast path.
    pub fast_draws: u64,
    /// Draws timed on the reference path.
    pub reference_draws: u64,
}

/// `end-to-end --json`: the command's whole answer.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct EndToEndJson<'a> {
    /// The study's path.
    pub study: &'a str,
    /// The study's reading of eq 13.
    pub reading: String,
    /// Monte Carlo turntables per box.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Time of the answer, s.
    pub seconds: f64,
    /// The calibration's outputs.
    pub(crate) outputs: Vec<OutputJson<'a>>,
    /// The table's error names.
    pub errors: Vec<&'a str>,
    /// Errors that act only together, with their combination's bound under each direct
    /// allocation.
    pub groups: Vec<GroupJson>,
    /// The two-step allocation's orientation requirement, degrees (`null` without one).
    pub two_step_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// Why the requirement is not the study's, or the rate steps' note; else `null`.
    pub requirement_note: Option<&'a str>,
    /// J of the two-step allocation, arcmin^-2 (`null` without one).
    pub two_step_objective: Option<f64>,
    /// J of the direct allocation under the study's reading, arcmin^-2.
    pub direct_objective: f64,
    /// Every box's bounds under the study's reading (the boxes by name, `direct`,
    /// `direct_certified`, `yield_based`), arcmin.
    pub bounds_arcmin: BTreeMap<String, ArcminBounds>,
    /// Per reading: every box's answer and the allocations.
    pub(crate) readings: Vec<ReadingJson<'a>>,
    /// Turntables per second measured in the same run.
    pub(crate) throughput: ThroughputJson,
    /// With noise in the study: the time/table trade-off (its keys at the top level).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) tradeoff: Option<TradeoffJson>,
    /// `angle_dependent`, `disc_allocation` and `rate_allocation` (each absent when it does
    /// not apply).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub extras: crate::json::ExtrasJson<'a>,
    /// The decision rule and the verdict against the study's specifications per quantity
    /// (the GUM budget of each over the direct allocation's box, study's reading); the
    /// accuracy rule without.
    pub decision: Option<crate::vendor::spec::SpecVerdictJson>,
}

impl<'a> EndToEndJson<'a> {
    /// The command's JSON view of the answer `r` for study `s`, without the extras
    /// ([`EndToEndJson::of`] adds them).
    fn new(s: &'a Study, r: &'a EndToEndAnswer) -> Self {
        let (e2e, a, note, seconds) = (&r.simulator, &r.answer, r.note.as_ref(), r.seconds);
        let (speed, noisy) = (&r.throughput, r.noisy.as_ref());
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
                .map(|(i, reading)| {
                    ReadingJson::new(
                        e2e,
                        reading,
                        noisy.and_then(|n| n.readings.get(i)),
                        &r.no_table_suffices,
                    )
                })
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

/// The noise of a study's calibration for its timing: `None` when no output has noise or the
/// study gives no `[calibration.timing]`.
///
/// # Errors
/// An input error naming the study for a noise or timing the calibration refuses.
pub(crate) fn noise_budget(s: &Study, e2e: &EndToEnd) -> Result<Option<e2e_verify::NoiseBudget>> {
    if s.noise.iter().all(Option::is_none) {
        return Ok(None);
    }
    let Some(timing) = &s.timing else {
        return Ok(None);
    };
    Ok(Some(
        e2e.noise()
            .noise_budget(&s.noise, timing)
            .map_err(|e| crate::error::library(e, s))?,
    ))
}

/// The one dwell of every position (bit for bit), `None` for a per-position list that differs
/// (or an empty one).
#[must_use]
pub(crate) fn uniform_dwell(dwell_s: &[f64]) -> Option<f64> {
    let first = *dwell_s.first()?;
    dwell_s
        .iter()
        .all(|d| d.to_bits() == first.to_bits())
        .then_some(first)
}

/// The options of [`end_to_end`]: the Monte Carlo size and seed (default: the study's), the
/// yield-based allocation's target, the noise part's confidence multiplier and a vendor sheet
/// whose pairs are allocated as discs.
#[derive(Debug, Clone)]
pub struct Options {
    /// Monte Carlo turntables per box (`None`: the study's `monte_carlo.samples`); a given
    /// count is named `--samples` in an error.
    pub samples: Option<u64>,
    /// Seed of the random streams (`None`: the study's).
    pub seed: Option<u64>,
    /// Target yield of the yield-based allocation, in (0, 1).
    pub yield_fraction: f64,
    /// Confidence multiplier of the noise part (combined = table + k sigma).
    pub k_sigma: f64,
    /// A vendor sheet whose magnitudes pair the errors (the disc allocation).
    pub tolerances: Option<std::path::PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            samples: None,
            seed: None,
            yield_fraction: e2e_verify::DEFAULT_YIELD_FRACTION,
            k_sigma: e2e_verify::DEFAULT_K_SIGMA,
            tolerances: None,
        }
    }
}

/// The end-to-end answer of a study ([`end_to_end`]): every box's worst case and yield per
/// reading, the allocations, the noise part, the throughput measured in the same run, and
/// the answers of the angle-dependent model, a sheet's pairs, the rate tolerances and the
/// specifications where they apply.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct EndToEndAnswer {
    simulator: EndToEnd,
    answer: BuyersAnswer,
    note: Option<String>,
    seconds: f64,
    throughput: Throughput,
    noisy: Option<NoisyAnswer>,
    angle: Option<crate::allocation::angle::AngleAllocations>,
    sheet: Option<crate::allocation::angle::SheetAllocations>,
    rate: Option<crate::vendor::rate::RateAllocated>,
    decision: Option<e2e_verify::budget::PlanVerdict>,
    no_table_suffices: Vec<NoTableSuffices>,
}

impl EndToEndAnswer {
    /// The study's simulator (its reading of eq 13).
    #[must_use]
    pub fn simulator(&self) -> &EndToEnd {
        &self.simulator
    }
    /// The answer per reading (worst cases, yields, allocations).
    #[must_use]
    pub fn answer(&self) -> &BuyersAnswer {
        &self.answer
    }
    /// Why the requirement is not the study's, or the rate steps' note.
    #[must_use]
    pub fn note(&self) -> Option<&String> {
        self.note.as_ref()
    }
    /// Time of the answer (with its noise part), s.
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.seconds
    }
    /// Turntables per second measured in the same run.
    #[must_use]
    pub fn throughput(&self) -> &Throughput {
        &self.throughput
    }
    /// The noise part, when the study gives noise and a timing.
    #[must_use]
    pub fn noisy(&self) -> Option<&NoisyAnswer> {
        self.noisy.as_ref()
    }
    /// The allocations of the angle-dependent model, when the study has one.
    #[must_use]
    pub fn angle(&self) -> Option<&crate::allocation::angle::AngleAllocations> {
        self.angle.as_ref()
    }
    /// A sheet's pairs allocated as discs and squares, with [`Options::tolerances`].
    #[must_use]
    pub fn sheet(&self) -> Option<&crate::allocation::angle::SheetAllocations> {
        self.sheet.as_ref()
    }
    /// The direct allocation with the rate tolerances, for a study with rate steps.
    #[must_use]
    pub fn rate(&self) -> Option<&crate::vendor::rate::RateAllocated> {
        self.rate.as_ref()
    }
    /// The verdict against the study's specifications over the direct allocation's box.
    #[must_use]
    pub fn decision(&self) -> Option<&e2e_verify::budget::PlanVerdict> {
        self.decision.as_ref()
    }
    /// The specifications no table can meet (the noise part alone fills the limit), left out
    /// of the direct and the yield-based allocations, in the study's order: the text's and the
    /// report's list (each one's sentence) and `--json`'s
    /// `readings[].yield_based.not_counted` (its figures).
    #[must_use]
    pub fn no_table_suffices(&self) -> &[NoTableSuffices] {
        &self.no_table_suffices
    }
}

/// Does the allocated turntable deliver every output's calibration accuracy? The study's
/// answer end to end.
///
/// # Errors
/// An [`InputError`] for a Monte Carlo size that cannot resolve the yield target, a study or
/// sheet the computation refuses; a library error if a solver fails.
pub fn end_to_end(s: &Study, o: &Options) -> Result<EndToEndAnswer> {
    let e2e = crate::loaded::simulator(s)?;
    let samples = o.samples.unwrap_or(s.monte_carlo.samples);
    let seed = o.seed.unwrap_or(s.monte_carlo.seed);
    check_yield_samples(samples, o.samples.is_some(), o.yield_fraction, s)?;
    // the requirement (a box search per output) once, for the inputs and the note
    let req = st::requirement(s)?;
    let mut inputs = inputs_with(s, &req, samples, seed, o.yield_fraction);
    // the direct allocations hold every specification that leaves the table room
    let specified = crate::allocation::spec::context(s, &e2e)?;
    inputs.specifications = specified.context;
    let note = if s.has_rate_steps() {
        Some(crate::vendor::rate::rate_steps_note(&e2e))
    } else {
        req.disagreement
    };
    let t0 = Instant::now();
    let a = answer(&e2e, &inputs).map_err(|e| crate::error::library(e, s))?;
    let noisy = noisy_answer(s, &e2e, &a, o.k_sigma)?;
    let seconds = t0.elapsed().as_secs_f64();
    let speed = throughput(&e2e, &a, seed)?;
    let angle = crate::allocation::angle::compute(s, &e2e)?;
    let sheet = crate::allocation::angle::sheet(s, o.tolerances.as_deref())?;
    let rate = crate::vendor::rate::allocation_with_k(
        s,
        &e2e,
        &e2e_verify::McSettings::new(samples, seed),
        o.k_sigma,
    )?;
    let decision =
        crate::vendor::spec::compute(s, &e2e, a.readings()[0].direct().upper_bounds_rad())?;
    Ok(EndToEndAnswer {
        simulator: e2e,
        answer: a,
        note,
        seconds,
        throughput: speed,
        noisy,
        angle,
        sheet,
        rate,
        decision,
        no_table_suffices: specified.no_table_suffices,
    })
}

impl<'a> EndToEndJson<'a> {
    /// The `end-to-end --json` view of a whole answer (with `angle_dependent`,
    /// `disc_allocation`, `rate_allocation` and `decision`).
    #[must_use]
    pub fn of(s: &'a Study, r: &'a EndToEndAnswer) -> Self {
        let e2e = &r.simulator;
        let mut v = Self::new(s, r);
        v.extras.angle_dependent = r
            .angle
            .as_ref()
            .map(|an| crate::allocation::angle::AngleDependentJson::new(e2e, an));
        v.extras.disc_allocation = r
            .sheet
            .as_ref()
            .map(|(path, al)| crate::vendor::angle::SheetAllocationsJson::new(path, al));
        v.extras.rate_allocation = r
            .rate
            .as_ref()
            .map(|x| crate::vendor::rate::RateAllocationJson::new(e2e, x));
        v.decision = Some(crate::vendor::spec::SpecVerdictJson::new(
            s,
            r.decision.as_ref(),
        ));
        v
    }
}

/// The note for values printed as 0 because they lie at or below the computation's precision
/// ([`e2e_verify::EndToEnd::precisions`]): `None` when no output in `zeroed` (name, unit,
/// precision) had one.
#[must_use]
pub fn precision_note(zeroed: &[(&str, &str, f64)]) -> Option<String> {
    (!zeroed.is_empty()).then(|| {
        format!(
            "0 = at or below the computation's precision ({})",
            zeroed
                .iter()
                .map(|(n, u, p)| format!("{n} {} {u}", tt_core::human::sig(*p, 2)))
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

/// A box's worst turntable in words: each output's error there (the exact chain at the worst
/// vertex, output's unit) written by `shown(output index, value)`, joined by ", " (the text's
/// and the report's worst case of a box).
#[must_use]
pub fn worst_turntable_words(b: &BoxAnswer, shown: impl Fn(usize, f64) -> String) -> String {
    b.worst_case()
        .outputs()
        .iter()
        .map(|w| shown(w.output(), w.exact_at_vertex()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the yield-based box's yield counts, in words: [`e2e_verify::SpecifiedCount::counts`],
/// and, where `left_out` of the study's specifications are left out of the allocations because
/// no table can meet them (the noise part alone fills the limit:
/// [`EndToEndAnswer::no_table_suffices`]), that those are not counted, so the sentence never
/// says "every specification" of a count that skipped some.
#[must_use]
pub fn yield_counts_words(r: &ReadingAnswer, left_out: usize) -> String {
    let counted = r.yield_based().counted();
    let counts = counted.counts();
    let plural = if left_out == 1 { "" } else { "s" };
    match (left_out, counted.per_specification().is_empty()) {
        (0, _) => counts.to_string(),
        (_, false) => format!(
            "{counts} a table can meet ({left_out} specification{plural} no table can meet not counted: the noise alone fills the limit)"
        ),
        (_, true) => format!(
            "{counts} ({left_out} specification{plural} no table can meet not counted: the noise alone fills the limit)"
        ),
    }
}

/// What the yield-based box's re-measured turntables meet, one line per limit its yield
/// counts, with specifications (empty without: the yield then counts every accuracy, as its
/// own line says): every output's accuracy (eq 14, on the same draws: the yield box's count),
/// then each specification (`label in unit`, written by `shown`, which escapes it for the
/// terminal or Markdown) with the draws meeting it of those drawn, their fraction and 95%
/// Wilson interval in percent. The limit met by the fewest draws, when some draw fails it, is
/// marked as the one that limits the yield most (alone it removes the most draws). The figures are `end-to-end --json`'s
/// `readings[].yield_based.remeasured.meeting` and
/// `readings[].yield_based.specifications.remeasured_per_specification`.
#[must_use]
pub fn yield_limit_lines(r: &ReadingAnswer, shown: &dyn Fn(&str) -> String) -> Vec<String> {
    let Some(again) = r.yield_recheck() else {
        return Vec::new();
    };
    // the yield box and the recount draw the same turntables (the same box and settings)
    let samples = again.count().samples();
    let mut limits = vec![(
        "every output's accuracy (eq 14)".to_string(),
        r.yield_box().distribution().count().meeting(),
    )];
    limits.extend(
        again
            .per_specification()
            .iter()
            .map(|(label, meeting)| (shown(label), *meeting)),
    );
    let fewest = limits.iter().map(|l| l.1).min().unwrap_or(samples);
    limits
        .into_iter()
        .map(|(label, meeting)| {
            let (lo, hi) = e2e_verify::wilson_interval_95(meeting, samples);
            format!(
                "{label}: {meeting} of {samples} ({:.2}%, 95% interval {:.2}-{:.2}%){}",
                100.0 * meeting as f64 / samples as f64,
                100.0 * lo,
                100.0 * hi,
                if meeting == fewest && fewest < samples {
                    "; the fewest: it limits the yield most"
                } else {
                    ""
                }
            )
        })
        .collect()
}
