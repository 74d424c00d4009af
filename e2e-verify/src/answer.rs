//! The buyer's question for one study: worst case and yield of the two-step allocation (and of
//! any other named box, e.g. the paper's Table 4), and the direct and yield-based allocations,
//! for the study's reading and for the user's reading.

use crate::allocate::{
    DEFAULT_YIELD_FRACTION, DirectAllocation, YieldAllocation, YieldVerdict, check_yield_samples,
};
use crate::error::{E2eError, fraction};
use crate::linear::{Linearization, WorstCase};
use crate::montecarlo::{McSettings, RateDistribution};
use crate::simulate::EndToEnd;
use crate::specified_yield::{SpecCheck, SpecifiedCount};
use alloc_opt::{Allocation, AllocationProblem, Allocator, Requirement, SensitivityWeighted};
use calib_lsq::Reading;
use tt_kinematics::LinearModel;

/// Default number of Monte Carlo turntables per box.
pub const DEFAULT_SAMPLES: u64 = 20_000;

/// Everything the end-to-end answer depends on besides the simulator (radians inside; a study
/// file fills it at the edge).
#[derive(Debug, Clone, PartialEq)]
pub struct EndToEndInputs {
    /// Lower bounds LB (rad, order of $\chi$).
    pub lower_bounds_rad: Vec<f64>,
    /// The orientation requirement handed to the two-step allocation; `None` when there is
    /// none (no output constrains a constant orientation error).
    pub two_step_requirement: Option<Requirement>,
    /// Other boxes to evaluate beside the allocations, by name (e.g. the paper's Table 4).
    pub extra_boxes: Vec<(String, Vec<f64>)>,
    /// Monte Carlo turntables per box.
    pub samples: u64,
    /// Seed (the yield-allocation design uses `seed + 1`, its re-measure `seed + 2`).
    pub seed: u64,
    /// Target yield of the yield-based allocation (default 0.9973).
    pub yield_fraction: f64,
    /// The specifications the direct allocations hold beside every output's accuracy
    /// ([`crate::EndToEnd::allocate_direct_specified`]); `None`: the accuracies only.
    pub specifications: Option<crate::budget::SpecificationContext>,
}

impl EndToEndInputs {
    /// Inputs with defaults: no extra box, [`DEFAULT_SAMPLES`], [`DEFAULT_YIELD_FRACTION`].
    #[must_use]
    pub fn new(
        lower_bounds_rad: Vec<f64>,
        two_step_requirement: Option<Requirement>,
        seed: u64,
    ) -> Self {
        Self {
            lower_bounds_rad,
            two_step_requirement,
            extra_boxes: Vec::new(),
            samples: DEFAULT_SAMPLES,
            seed,
            yield_fraction: DEFAULT_YIELD_FRACTION,
            specifications: None,
        }
    }
}

/// Worst case and Monte Carlo distribution of one tolerance box.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BoxAnswer {
    /// The box's name (`two-step`, `Table 4`, `direct`, `yield-based`).
    pub(crate) name: String,
    /// The upper bounds (rad).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// $J$ of these bounds (rad$^{-2}$).
    pub(crate) objective: f64,
    /// Worst case per output (linearised vertex, exact confirmation, second-order bound).
    pub(crate) worst_case: WorstCase,
    /// Distribution and yield over turntables drawn from the box.
    pub(crate) distribution: RateDistribution,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BoxAnswer {
    /// The box's name (`two-step`, `Table 4`, `direct`, `yield-based`).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The upper bounds (rad).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// $J$ of these bounds (rad$^{-2}$).
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// Worst case per output (linearised vertex, exact confirmation, second-order bound).
    #[must_use]
    pub fn worst_case(&self) -> &WorstCase {
        &self.worst_case
    }

    /// Distribution and yield over turntables drawn from the box.
    #[must_use]
    pub fn distribution(&self) -> &RateDistribution {
        &self.distribution
    }
}

/// The answer under one reading.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ReadingAnswer {
    /// The reading.
    pub(crate) reading: Reading,
    /// The two-step allocation's box (if a requirement exists) and the extra boxes.
    pub(crate) boxes: Vec<BoxAnswer>,
    /// The direct allocation against every output's accuracy.
    pub(crate) direct: DirectAllocation,
    /// The direct allocation's box (worst case and yield).
    pub(crate) direct_box: BoxAnswer,
    /// The direct allocation certified on the exact chain
    /// ([`EndToEnd::allocate_direct_certified`]) with its worst case; `None` for a reading
    /// without a derived second-order bound, or when the certification cannot be had (see
    /// [`ReadingAnswer::direct_certified_note`]).
    pub(crate) direct_certified: Option<(DirectAllocation, WorstCase)>,
    /// Why [`ReadingAnswer::direct_certified`] is `None`: the reading has no derived bound, the
    /// second-order margin exceeds an output's accuracy (the derived bound is too coarse for
    /// this table and sensor), or the certification did not settle in
    /// [`crate::CertifyParams::steps`] solves. The direct allocation itself is unaffected.
    pub(crate) direct_certified_note: Option<String>,
    /// The yield-based allocation (shape of the direct one).
    pub(crate) yield_based: YieldAllocation,
    /// The yield-based box re-measured with an independent seed (`seed + 2`).
    pub(crate) yield_box: BoxAnswer,
    /// With specifications: the same re-measured draws counted against every accuracy and
    /// every specification (what the yield-based allocation counts); `None` without.
    pub(crate) yield_recheck: Option<SpecifiedCount>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ReadingAnswer {
    /// The reading.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// The two-step allocation's box (if a requirement exists) and the extra boxes.
    #[must_use]
    pub fn boxes(&self) -> &[BoxAnswer] {
        &self.boxes
    }

    /// The direct allocation against every output's accuracy.
    #[must_use]
    pub fn direct(&self) -> &DirectAllocation {
        &self.direct
    }

    /// The direct allocation's box (worst case and yield).
    #[must_use]
    pub fn direct_box(&self) -> &BoxAnswer {
        &self.direct_box
    }

    /// The direct allocation certified on the exact chain
    /// ([`EndToEnd::allocate_direct_certified`]) with its worst case; `None` for a reading
    /// without a derived second-order bound, or when the certification cannot be had (see
    /// [`ReadingAnswer::direct_certified_note`]).
    #[must_use]
    pub fn direct_certified(&self) -> Option<&(DirectAllocation, WorstCase)> {
        self.direct_certified.as_ref()
    }

    /// Why [`ReadingAnswer::direct_certified`] is `None`: the reading has no derived bound, the
    /// second-order margin exceeds an output's accuracy (the derived bound is too coarse for
    /// this table and sensor), or the certification did not settle in
    /// [`crate::CertifyParams::steps`] solves. The direct allocation itself is unaffected.
    #[must_use]
    pub fn direct_certified_note(&self) -> Option<&str> {
        self.direct_certified_note.as_deref()
    }

    /// The yield-based allocation (shape of the direct one).
    #[must_use]
    pub fn yield_based(&self) -> &YieldAllocation {
        &self.yield_based
    }

    /// The yield-based box re-measured with an independent seed (`seed + 2`).
    #[must_use]
    pub fn yield_box(&self) -> &BoxAnswer {
        &self.yield_box
    }

    /// With specifications: the re-measured draws of [`ReadingAnswer::yield_box`] counted
    /// against every accuracy and every specification, per specification too; `None`
    /// without.
    #[must_use]
    pub fn yield_recheck(&self) -> Option<&SpecifiedCount> {
        self.yield_recheck.as_ref()
    }

    /// The re-measured count the yield verdict is on: [`ReadingAnswer::yield_recheck`]'s with
    /// specifications, else the yield box's (every accuracy).
    #[must_use]
    pub fn yield_count(&self) -> &crate::YieldCount {
        match &self.yield_recheck {
            Some(c) => c.count(),
            None => self.yield_box.distribution.count(),
        }
    }
}

impl ReadingAnswer {
    /// The yield-based box re-measured on independent draws against its target: the 95%
    /// interval of [`ReadingAnswer::yield_box`]'s yield and whether it reaches
    /// [`YieldAllocation::target`] (meets: the whole interval at or above it; does not meet:
    /// the whole interval below it; cannot tell).
    #[must_use]
    pub fn yield_verdict(&self) -> YieldVerdict {
        YieldVerdict::of(self.yield_count().interval_95(), self.yield_based.target)
    }
}

/// The full answer.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BuyersAnswer {
    /// The inputs.
    pub(crate) inputs: EndToEndInputs,
    /// The two-step allocation (alloc-opt, sensitivity-weighted, full-range constraint)
    /// against the requirement; `None` without a requirement.
    pub(crate) two_step: Option<Allocation>,
    /// One answer per reading: the simulator's reading first, then [`Reading::USER`] (if
    /// different).
    pub(crate) readings: Vec<ReadingAnswer>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BuyersAnswer {
    /// The inputs.
    #[must_use]
    pub fn inputs(&self) -> &EndToEndInputs {
        &self.inputs
    }

    /// The two-step allocation (alloc-opt, sensitivity-weighted, full-range constraint)
    /// against the requirement; `None` without a requirement.
    #[must_use]
    pub fn two_step(&self) -> Option<&Allocation> {
        self.two_step.as_ref()
    }

    /// One answer per reading: the simulator's reading first, then [`Reading::USER`] (if
    /// different).
    #[must_use]
    pub fn readings(&self) -> &[ReadingAnswer] {
        &self.readings
    }
}

/// Answer the buyer's question for the simulator `e2e` (its reading first, then the user's).
///
/// # Errors
/// Typed errors naming the field for bad inputs; [`E2eError::TooFewSamples`] when
/// `inputs.samples` cannot resolve the yield target ([`crate::min_yield_samples`]); as the
/// allocations and the Monte Carlo.
pub fn answer(e2e: &EndToEnd, inputs: &EndToEndInputs) -> Result<BuyersAnswer, E2eError> {
    check_inputs(e2e, inputs)?;
    // the two-step allocation and the allocations that do not need it, side by side
    let (two_step, allocations) = rayon::join(
        || -> Result<Option<Allocation>, E2eError> {
            Ok(match inputs.two_step_requirement {
                Some(req) => Some(SensitivityWeighted::general().allocate(
                    &AllocationProblem::new(
                        LinearModel::new(e2e.turntable()),
                        req,
                        inputs.lower_bounds_rad.clone(),
                    )?,
                )?),
                None => None,
            })
        },
        || allocations_checked(e2e, inputs),
    );
    let two_step = two_step?;
    check_two_step(e2e, inputs, two_step.as_ref())?;
    allocations?.answer(two_step)
}

/// [`answer()`] with the two-step allocation already computed (by the caller, for the same
/// turntable, requirement and lower bounds as `inputs`): the allocation of a table with two
/// or more free joints takes seconds, and a report that also prints it need not pay twice.
///
/// # Errors
/// As [`answer()`]; [`E2eError::Alloc`] ([`alloc_opt::AllocError::Field`], wrong length) when the
/// allocation's length is not the turntable's error count.
pub fn answer_with_two_step(
    e2e: &EndToEnd,
    inputs: &EndToEndInputs,
    two_step: Option<Allocation>,
) -> Result<BuyersAnswer, E2eError> {
    check_inputs(e2e, inputs)?;
    check_two_step(e2e, inputs, two_step.as_ref())?;
    allocations_checked(e2e, inputs)?.answer(two_step)
}

/// The part of the answer that does not depend on the two-step allocation: per reading the
/// direct allocation, its certification, the yield-based allocation and their boxes. Computed
/// by [`answer_allocations`] (for example while the caller allocates the two-step box, which
/// takes seconds on a table with two or more free joints) and completed by
/// [`AnswerAllocations::answer`]; together they give what [`answer_with_two_step`] gives.
#[derive(Debug, Clone)]
pub struct AnswerAllocations {
    inputs: EndToEndInputs,
    /// The simulator's reading first (never empty).
    readings: Vec<ReadingAllocations>,
}

/// One reading's part of [`AnswerAllocations`], with its simulator and linearisation.
#[derive(Debug, Clone)]
struct ReadingAllocations {
    sim: EndToEnd,
    linear: Linearization,
    direct: DirectAllocation,
    direct_box: BoxAnswer,
    direct_certified: Option<(DirectAllocation, WorstCase)>,
    direct_certified_note: Option<String>,
    yield_based: YieldAllocation,
    yield_box: BoxAnswer,
    yield_recheck: Option<SpecifiedCount>,
}

/// The readings of the answer: the simulator's first, then [`Reading::USER`] (if different).
fn readings_of(e2e: &EndToEnd) -> Vec<Reading> {
    let mut readings = vec![e2e.reading()];
    if e2e.reading() != Reading::USER {
        readings.push(Reading::USER);
    }
    readings
}

/// The inputs' checks (before any heavy work): the yield target, the Monte Carlo settings and
/// every extra box containing the lower bounds.
fn check_inputs(e2e: &EndToEnd, inputs: &EndToEndInputs) -> Result<(), E2eError> {
    fraction("yield_fraction", inputs.yield_fraction)?;
    McSettings::new(inputs.samples, inputs.seed).validate()?;
    check_yield_samples(inputs.samples, inputs.yield_fraction)?;
    for (name, ub) in &inputs.extra_boxes {
        check_box(e2e, inputs, name, ub)?;
    }
    Ok(())
}

/// The two-step allocation has the turntable's length and its box contains the lower bounds.
fn check_two_step(
    e2e: &EndToEnd,
    inputs: &EndToEndInputs,
    two_step: Option<&Allocation>,
) -> Result<(), E2eError> {
    if let Some(a) = two_step {
        tt_core::length(
            "two-step allocation",
            e2e.n_errors(),
            a.upper_bounds_rad().len(),
        )?;
        check_box(e2e, inputs, "two-step", a.upper_bounds_rad())?;
    }
    Ok(())
}

/// A named box must contain its lower bounds (a named error).
fn check_box(
    e2e: &EndToEnd,
    inputs: &EndToEndInputs,
    name: &str,
    ub: &[f64],
) -> Result<(), E2eError> {
    e2e.box_of(ub, &inputs.lower_bounds_rad)
        .map(|_| ())
        .map_err(|e| match e {
            E2eError::Bounds(mc_verify::McError::LowerAboveUpper { component, lb, ub }) => {
                E2eError::LowerAboveBox {
                    name: name.to_string(),
                    component,
                    lb,
                    ub,
                }
            }
            other => other,
        })
}

/// Worst case and distribution of one named box under `sim`.
fn box_answer(
    sim: &EndToEnd,
    linear: &Linearization,
    lower_bounds_rad: &[f64],
    name: &str,
    ub: &[f64],
    settings: &McSettings,
) -> Result<BoxAnswer, E2eError> {
    Ok(BoxAnswer {
        name: name.to_string(),
        upper_bounds_rad: ub.to_vec(),
        objective: sim.objective(ub),
        worst_case: sim.worst_case(linear, ub)?,
        distribution: sim.monte_carlo().rate_distribution(
            linear,
            &sim.box_of(ub, lower_bounds_rad)?,
            settings,
        )?,
    })
}

/// The allocations of every reading of [`answer()`] that do not need the two-step box: see
/// [`AnswerAllocations`].
///
/// # Errors
/// As [`answer()`] for the inputs, the allocations and their Monte Carlo.
pub fn answer_allocations(
    e2e: &EndToEnd,
    inputs: &EndToEndInputs,
) -> Result<AnswerAllocations, E2eError> {
    check_inputs(e2e, inputs)?;
    allocations_checked(e2e, inputs)
}

/// [`answer_allocations`] after the checks. The readings, and within a reading the
/// certification, the yield-based allocation and the direct box, are independent: they run in
/// parallel, each with its own seeded settings (the same numbers for any thread count), and
/// the first error in the serial order is returned.
fn allocations_checked(
    e2e: &EndToEnd,
    inputs: &EndToEndInputs,
) -> Result<AnswerAllocations, E2eError> {
    let settings = McSettings::new(inputs.samples, inputs.seed);
    let design = McSettings::new(inputs.samples, inputs.seed.wrapping_add(1));
    let recheck = McSettings::new(inputs.samples, inputs.seed.wrapping_add(2));
    let lb = inputs.lower_bounds_rad.as_slice();
    let one = |reading: Reading| -> Result<ReadingAllocations, E2eError> {
        let sim = if reading == e2e.reading() {
            e2e.clone()
        } else {
            e2e.with_reading(reading)?
        };
        let linear = sim.linearization();
        let spec_rows = match &inputs.specifications {
            Some(ctx) => sim.budget().specification_rows(ctx)?,
            None => Vec::new(),
        };
        let direct = sim.allocate_direct_specified(&linear, lb, &spec_rows)?;
        // the certification (no Monte Carlo) beside the Monte Carlo runs; those run one at a
        // time (each already uses every thread), so the memory of their chunk waves is that of
        // one run whatever the sample count
        let (certified, (yielded, direct_box)) = rayon::join(
            || -> Result<_, E2eError> {
                let (certified, note) = crate::allocate::certified_or_note_specified(
                    &sim, &linear, lb, &direct, &spec_rows,
                )?;
                let certified = match certified {
                    Some(d) => {
                        let wc = sim.worst_case(&linear, &d.upper_bounds_rad)?;
                        Some((d, wc))
                    }
                    None => None,
                };
                Ok((certified, note))
            },
            || {
                let yielded =
                    (|| -> Result<(YieldAllocation, Result<BoxAnswer, E2eError>, _), E2eError> {
                        let y = sim.allocate_yield_specified(
                            &direct.upper_bounds_rad,
                            lb,
                            inputs.yield_fraction,
                            &design,
                            &crate::YieldParams::default(),
                            &spec_rows,
                        )?;
                        let b = box_answer(
                            &sim,
                            &linear,
                            lb,
                            "yield-based",
                            &y.upper_bounds_rad,
                            &recheck,
                        );
                        let c = (!spec_rows.is_empty())
                            .then(|| {
                                SpecCheck::new(&sim, &spec_rows)
                                    .count(&sim.box_of(&y.upper_bounds_rad, lb)?, &recheck)
                            })
                            .transpose();
                        Ok((y, b, c))
                    })();
                let direct_box = box_answer(
                    &sim,
                    &linear,
                    lb,
                    "direct",
                    &direct.upper_bounds_rad,
                    &settings,
                );
                (yielded, direct_box)
            },
        );
        // the first error in the serial order: certification, yield allocation, direct box,
        // yield box
        let (direct_certified, direct_certified_note) = certified?;
        let (yield_based, yield_box, yield_recheck) = yielded?;
        let direct_box = direct_box?;
        let yield_box = yield_box?;
        let yield_recheck = yield_recheck?;
        Ok(ReadingAllocations {
            sim,
            linear,
            direct,
            direct_box,
            direct_certified,
            direct_certified_note,
            yield_based,
            yield_box,
            yield_recheck,
        })
    };
    // the readings one after the other: each runs Monte Carlos (see above)
    let found: Vec<Result<ReadingAllocations, E2eError>> =
        readings_of(e2e).into_iter().map(one).collect();
    Ok(AnswerAllocations {
        inputs: inputs.clone(),
        readings: found.into_iter().collect::<Result<Vec<_>, _>>()?,
    })
}

impl AnswerAllocations {
    /// The answer with the two-step allocation (for the same turntable, requirement and lower
    /// bounds as the inputs): the same answer as [`answer_with_two_step`].
    ///
    /// # Errors
    /// As [`answer_with_two_step`] for the two-step allocation and the named boxes.
    pub fn answer(self, two_step: Option<Allocation>) -> Result<BuyersAnswer, E2eError> {
        let Self { inputs, readings } = self;
        check_two_step(&readings[0].sim, &inputs, two_step.as_ref())?;
        let mut named: Vec<(String, Vec<f64>)> = Vec::new();
        if let Some(a) = &two_step {
            named.push(("two-step".into(), a.upper_bounds_rad().to_vec()));
        }
        named.extend(inputs.extra_boxes.iter().cloned());
        let settings = McSettings::new(inputs.samples, inputs.seed);
        let lb = inputs.lower_bounds_rad.as_slice();
        // the readings one after the other: their boxes are Monte Carlo runs, each already on
        // every thread (and one at a time keeps the memory of one run)
        let found: Vec<Result<ReadingAnswer, E2eError>> = readings
            .into_iter()
            .map(|a| {
                let boxes = named
                    .iter()
                    .map(|(name, ub)| box_answer(&a.sim, &a.linear, lb, name, ub, &settings))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(ReadingAnswer {
                    reading: a.sim.reading(),
                    boxes,
                    direct: a.direct,
                    direct_box: a.direct_box,
                    direct_certified: a.direct_certified,
                    direct_certified_note: a.direct_certified_note,
                    yield_based: a.yield_based,
                    yield_box: a.yield_box,
                    yield_recheck: a.yield_recheck,
                })
            })
            .collect();
        Ok(BuyersAnswer {
            inputs,
            two_step,
            readings: found.into_iter().collect::<Result<Vec<_>, _>>()?,
        })
    }
}
