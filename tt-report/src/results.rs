//! `results.json`: every number of the report at full precision, as typed view structs
//! (`#[derive(Serialize)]`) built from [`Computed`]; each field's doc comment gives its unit.
//! Keys come out in alphabetical order ([`serde_json::Value`]'s map, as every command's
//! `--json`, [`tt_lab::json`]).

use crate::compute::{Computed, ScheduleFacts, TwoStep};
use crate::paper;
use e2e_verify::paper::registry::ClaimEvaluation;
use serde::{Serialize, Serializer};
use serde_json::Value;
use std::cell::Cell;
use std::collections::BTreeMap;
use tt_core::units::{objective_to_arcmin, rad_to_arcmin, rad_to_deg};
use tt_lab::end_to_end::UnconstrainedJson;
use tt_lab::json::{GroupJson, PerAngle};

thread_local! {
    /// Set when a NaN was put into `results.json` (an internal error: nothing is written).
    pub(super) static NAN_SEEN: Cell<bool> = const { Cell::new(false) };
}

/// A number of `results.json`: `null` for an infinite value (an infinite bound: no bound); a
/// NaN is written as `null` and recorded ([`NAN_SEEN`]), which fails the run.
#[derive(Debug, Clone, Copy)]
struct Num(f64);

impl Serialize for Num {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.0.is_nan() {
            NAN_SEEN.with(|c| c.set(true));
            s.serialize_none()
        } else if self.0.is_finite() {
            s.serialize_f64(self.0)
        } else {
            s.serialize_none()
        }
    }
}

fn f(v: f64) -> Num {
    Num(v)
}

/// A triple per orientation angle in degrees from radians (`null` where none).
fn deg3(r: &[Option<f64>; 3]) -> PerAngle<Option<Num>> {
    PerAngle::new(|a| r[a.index()].map(|v| f(rad_to_deg(v))))
}

/// Bounds in arcminutes keyed by error name (`null`: no bound).
fn arcmin_map(names: &[&str], ub_rad: &[f64]) -> BTreeMap<String, Num> {
    names
        .iter()
        .zip(ub_rad)
        .map(|(n, u)| ((*n).to_string(), f(rad_to_arcmin(*u))))
        .collect()
}

/// The requirement under one reading.
#[derive(Debug, Serialize)]
struct ReadingRequirementJson {
    /// The reading of eq 13.
    reading: String,
    /// Its requirement, degrees (`null` when it failed, `note`).
    requirement_deg: Option<PerAngle<Option<Num>>>,
    /// Why there is none, else `null`.
    note: Option<String>,
}

/// The orientation requirement.
#[derive(Debug, Serialize)]
struct RequirementJson<'a> {
    /// Whether the study gives it.
    given: bool,
    /// The requirement used, degrees (`null`: none).
    used_deg: Option<PerAngle<Option<Num>>>,
    /// The computed requirement, degrees (`null` when it failed, `computed_note`).
    computed_deg: Option<PerAngle<Option<Num>>>,
    /// Why there is no computed requirement, else `null`.
    computed_note: Option<String>,
    /// The outputs that constrain no angle.
    unconstrained_outputs: Vec<String>,
    /// How the given and the computed requirement disagree, else `null`.
    disagreement: Option<&'a str>,
    /// Under every reading.
    readings: Vec<ReadingRequirementJson>,
}

/// One output's regression.
#[derive(Debug, Serialize)]
struct CalibrationJson<'a> {
    /// The output's name.
    output: &'a str,
    /// Its coefficients' names.
    coefficients: &'a [String],
    /// The regression's rank.
    rank: usize,
    /// Its condition number.
    condition_number: Num,
}

/// One angle of the two-step allocation's certificate, degrees.
#[derive(Debug, Serialize)]
struct CertificateJson<'a> {
    /// `psi`, `theta` or `gamma`.
    angle: &'a str,
    /// The worst case found, degrees.
    worst_case_deg: Num,
    /// Its proven bound, degrees.
    proven_bound_deg: Num,
    /// The share of the requirement used (`null`: no requirement).
    share: Option<Num>,
    /// Whether Lemma 1 holds.
    lemma1: bool,
}

/// The two-step allocation's Monte Carlo.
#[derive(Debug, Serialize)]
struct TwoStepMonteCarloJson {
    /// Turntables drawn.
    samples: u64,
    /// The largest |error| per angle (psi, theta, gamma), degrees.
    max_abs_deg: [Num; 3],
    /// The histograms' proven half range per angle, degrees.
    proven_bound_deg: [Num; 3],
    /// Fraction inside the requirement, in [0, 1].
    within_requirement_fraction: Num,
}

/// The two-step allocation.
#[derive(Debug, Serialize)]
struct TwoStepJson<'a> {
    /// Its requirement, degrees.
    requirement_deg: PerAngle<Option<Num>>,
    /// Its bounds, arcmin.
    bounds_arcmin: BTreeMap<String, Num>,
    /// J, arcmin^-2.
    objective_arcmin: Num,
    /// Lemma 1's certificate per angle.
    certificate: Vec<CertificateJson<'a>>,
    /// The exact chain's excess over the requirement per angle, rad (`null`: none).
    exact_chain_excess_rad: Vec<Option<Num>>,
    /// Its Monte Carlo.
    monte_carlo: TwoStepMonteCarloJson,
}

/// The equal-effects allocation.
#[derive(Debug, Serialize)]
struct EqualEffectsJson {
    /// Its bounds, arcmin.
    bounds_arcmin: BTreeMap<String, Num>,
    /// J, arcmin^-2.
    objective_arcmin: Num,
}

/// A box with the noise part (study's reading).
#[derive(Debug, Serialize)]
struct NoiseBoxJson<'a> {
    /// The box's name.
    name: &'a str,
    /// Its verdict counting the noise.
    verdict: &'static str,
    /// Every output's table part, output's unit.
    table_part: Vec<Num>,
    /// Every output's combined answer, output's unit.
    combined: Vec<Num>,
    /// The yield over turntables and noise, in [0, 1].
    combined_yield: Num,
}

/// A point of the time/table trade-off.
#[derive(Debug, Serialize)]
struct TradeoffPointJson {
    /// Dwell per position, s.
    dwell_s: Num,
    /// Total test time, s.
    total_s: Num,
    /// J, arcmin^-2 (`null`: no table suffices).
    objective_arcmin: Option<Num>,
}

/// The noise part (study's reading).
#[derive(Debug, Serialize)]
struct NoiseJson<'a> {
    /// The confidence multiplier.
    k_sigma: Num,
    /// Every output's noise sigma, output's unit.
    noise_sigma: Vec<Num>,
    /// Every box with the noise part.
    boxes: Vec<NoiseBoxJson<'a>>,
    /// J of the direct allocation with the noise part kept free, arcmin^-2 (`null`: no table
    /// suffices).
    direct_with_noise_objective_arcmin: Option<Num>,
    /// The shortest dwell at which some table suffices, s.
    min_dwell_s: Option<Num>,
    /// The trade-off's knee, s.
    knee_dwell_s: Option<Num>,
    /// What the trade-off scanned (the study's dwells scaled alike).
    dwell_scan: tt_lab::end_to_end::Scanned,
    /// The trade-off.
    tradeoff: Vec<TradeoffPointJson>,
}

/// One output's worst case over a box, output's unit.
#[derive(Debug, Serialize)]
struct WorstCaseJson<'a> {
    /// The output's name.
    output: &'a str,
    /// The exact chain at the worst vertex.
    exact_at_vertex: Num,
    /// The linearised worst case.
    linear: Num,
    /// The certified bound (`null` when not computed).
    certified: Option<Num>,
    /// The computation's precision.
    precision: Num,
}

/// One box's answer.
#[derive(Debug, Serialize)]
struct BoxJson<'a> {
    /// The box's name.
    name: &'a str,
    /// Whether it meets every accuracy ([`e2e_verify::BoxMeets::name`]).
    meets: &'static str,
    /// The same in words.
    meets_text: String,
    /// By how much it misses (`null` when it meets).
    meets_excess: Option<Num>,
    /// J, arcmin^-2.
    objective_arcmin: Num,
    /// Its bounds, arcmin.
    bounds_arcmin: BTreeMap<String, Num>,
    /// Every output's worst case.
    worst_case: Vec<WorstCaseJson<'a>>,
    /// Monte Carlo yield, in [0, 1].
    #[serde(rename = "yield")]
    yield_fraction: Num,
    /// Its 95% interval.
    yield_interval_95: [Num; 2],
}

/// The certified direct allocation.
#[derive(Debug, Serialize)]
struct DirectCertifiedJson {
    /// J, arcmin^-2.
    objective_arcmin: Num,
    /// Its bounds, arcmin.
    bounds_arcmin: BTreeMap<String, Num>,
}

/// End to end under one reading.
#[derive(Debug, Serialize)]
struct EndToEndJson<'a> {
    /// The reading of eq 13.
    reading: String,
    /// Every box.
    boxes: Vec<BoxJson<'a>>,
    /// The direct allocation's box.
    direct: BoxJson<'a>,
    /// The errors no output constrains and whether any error needs a bound.
    #[serde(flatten)]
    unconstrained: UnconstrainedJson<'a>,
    /// The yield-based allocation's box.
    yield_based: BoxJson<'a>,
    /// Its target yield.
    yield_target: Num,
    /// Its verdict against the target.
    yield_verdict: &'static str,
    /// The certified direct allocation (`null`: none, `direct_certified_note`).
    direct_certified: Option<DirectCertifiedJson>,
    /// Why there is none, else `null`.
    direct_certified_note: Option<&'a str>,
}

/// One output of the vendor's check, output's unit.
#[derive(Debug, Serialize)]
struct VendorOutputJson<'a> {
    /// The output's name.
    output: &'a str,
    /// Its verdict.
    verdict: &'static str,
    /// The exact chain at the worst vertex.
    worst_case: Num,
    /// Its accuracy.
    accuracy: Num,
    /// The computation's precision.
    precision: Num,
}

/// The vendor's sheet checked.
#[derive(Debug, Serialize)]
struct VendorJson<'a> {
    /// The sheet's path.
    tolerances: &'a str,
    /// The verdict.
    verdict: &'static str,
    /// Monte Carlo yield, in [0, 1].
    #[serde(rename = "yield")]
    yield_fraction: Num,
    /// Every output.
    outputs: Vec<VendorOutputJson<'a>>,
    /// With rate steps: the check with the errors only rotation exposes (`null` otherwise).
    rate_steps: Option<tt_lab::vendor::rate::RateCheckJson<'a>>,
}

/// A schedule beside the study's (`--designed`).
#[derive(Debug, Serialize)]
struct DesignedJson<'a> {
    /// The study's path.
    study: &'a str,
    /// Its positions.
    positions: usize,
    /// J of its direct allocation, arcmin^-2.
    direct_objective_arcmin: Num,
    /// Every output's condition number.
    condition_numbers: Vec<Num>,
    /// Its requirement, degrees (`null` when it failed).
    requirement_deg: Option<PerAngle<Option<Num>>>,
}

/// One of the paper's claims, checked.
#[derive(Debug, Serialize)]
struct ClaimJson {
    /// Its id.
    id: &'static str,
    /// The paper's section.
    section: &'static str,
    /// The claim.
    statement: &'static str,
    /// The function that checks it.
    function: &'static str,
    /// The test that checks it.
    test: String,
    /// The command that runs the test.
    test_command: String,
    /// Whether it holds under the paper's reading.
    holds_paper_reading: bool,
    /// The evidence.
    evidence_paper_reading: String,
    /// Under the user's reading (`null`: not reading-dependent).
    holds_user_reading: Option<bool>,
    /// The evidence.
    evidence_user_reading: Option<String>,
}

/// A paper's printed value beside ours.
#[derive(Debug, Serialize)]
struct ComparisonJson<'a> {
    /// The quantity.
    quantity: &'a str,
    /// The paper's value, `unit`.
    paper: Num,
    /// Ours, `unit`.
    ours: Num,
    /// The unit.
    unit: &'static str,
    /// Why they differ (or agree).
    reason: &'a str,
}

/// `estimable`: the answer, or why there is none.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum EstimableJson<'a> {
    /// The answer.
    Answer(Box<tt_lab::estimable::EstimableJson<'a>>),
    /// None.
    Note {
        /// Why.
        note: &'static str,
    },
}

/// `results.json`.
#[derive(Debug, Serialize)]
struct ResultsJson<'a> {
    /// The study's path.
    study: &'a str,
    /// The study's name.
    study_name: &'a str,
    /// Seed of the Monte Carlo streams.
    seed: u64,
    /// Monte Carlo turntables per box.
    samples: u64,
    /// Time of the computation, s.
    seconds: Num,
    /// The study's reading of eq 13.
    reading: String,
    /// The orientation requirement.
    requirement: RequirementJson<'a>,
    /// Every output's regression.
    calibration: Vec<CalibrationJson<'a>>,
    /// Errors that act only together.
    groups: Vec<GroupJson>,
    /// Every error's average sensitivity per angle (dimensionless).
    average_sensitivity: BTreeMap<String, PerAngle<Num>>,
    /// The two-step allocation; absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    two_step: Option<TwoStepJson<'a>>,
    /// The equal-effects allocation; absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    equal_effects: Option<EqualEffectsJson>,
    /// With noise: the noise part; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    noise: Option<NoiseJson<'a>>,
    /// End to end per reading.
    end_to_end: Vec<EndToEndJson<'a>>,
    /// With a vendor's sheet: its check; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    vendor: Option<VendorJson<'a>>,
    /// With `--designed`: both schedules; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    designed: Option<Vec<DesignedJson<'a>>>,
    /// The paper's report: its claims; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    claims: Option<Vec<ClaimJson>>,
    /// The paper's report: the claims' summary line; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    claims_summary: Option<String>,
    /// The paper's report: its printed values beside ours; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    paper_versus_ours: Option<Vec<ComparisonJson<'a>>>,
    /// With rate steps: the allocation with the rate tolerances; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_allocation: Option<tt_lab::vendor::rate::RateAllocationJson<'a>>,
    /// With errors that vary with the shaft angle: the allocations under its model; absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    angle_dependent: Option<tt_lab::allocation::angle::AngleDependentJson<'a>>,
    /// The table errors the calibration estimates itself, or why not.
    estimable: EstimableJson<'a>,
    /// With `[[specifications]]`: the verdict and GUM budget of each over the direct
    /// allocation's box under the study's reading (as `end-to-end --json`'s `decision`);
    /// absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    specifications: Option<SpecificationsJson>,
    /// With `--recording`: the processed run, as `calibrate --json` prints it (the recording,
    /// segments, warnings, per output the measured noise, every coefficient with its
    /// uncertainties and the plan's predicted one, the residuals; the verdicts); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    processed_run: Option<tt_lab::calibrate::CalibrationJson<'a>>,
}

/// The verdict against the study's specifications and the tolerances it was evaluated at.
#[derive(Debug, Serialize)]
struct SpecificationsJson {
    /// The tolerances the budgets take (the direct allocation's box, study's reading), rad per
    /// error (`null`: no bound).
    tolerances_rad: BTreeMap<String, Num>,
    /// The verdict, rule and budgets.
    #[serde(flatten)]
    verdict: tt_lab::vendor::spec::SpecVerdictJson,
}

/// One box's answer.
fn box_json<'a>(
    b: &'a e2e_verify::BoxAnswer,
    names: &[&str],
    outs: &[&'a str],
    accuracies: &[f64],
) -> BoxJson<'a> {
    let (lo, hi) = b.distribution().count().interval_95();
    let meets = b.worst_case().meets(accuracies);
    BoxJson {
        name: b.name(),
        meets: meets.name(),
        meets_text: meets.to_string(),
        meets_excess: meets.excess().map(f),
        objective_arcmin: f(objective_to_arcmin(b.objective())),
        bounds_arcmin: arcmin_map(names, b.upper_bounds_rad()),
        worst_case: b
            .worst_case()
            .outputs()
            .iter()
            .map(|w| WorstCaseJson {
                output: outs[w.output()],
                exact_at_vertex: f(w.exact_at_vertex()),
                linear: f(w.linear_bound()),
                certified: w.certified_bound().map(f),
                precision: f(w.precision()),
            })
            .collect(),
        yield_fraction: f(b.distribution().count().fraction()),
        yield_interval_95: [f(lo), f(hi)],
    }
}

impl<'a> RequirementJson<'a> {
    /// The requirement of `c`: given or computed, under every reading.
    fn new(c: &'a Computed) -> Self {
        let computed = c.requirement.computed.as_ref();
        Self {
            given: c.requirement.given,
            used_deg: c.requirement.used.map(|r| deg3(&r.to_array())),
            computed_deg: computed.ok().map(|r| deg3(&r.requirement().to_array())),
            computed_note: computed.err().map(ToString::to_string),
            unconstrained_outputs: computed
                .map(|r| r.unconstrained_outputs().to_vec())
                .unwrap_or_default(),
            disagreement: c.requirement.disagreement.as_deref(),
            readings: c
                .readings
                .iter()
                .map(|(r, q)| ReadingRequirementJson {
                    reading: r.to_string(),
                    requirement_deg: q.as_ref().ok().map(|q| deg3(&q.requirement().to_array())),
                    note: q.as_ref().err().map(ToString::to_string),
                })
                .collect(),
        }
    }
}

impl<'a> TwoStepJson<'a> {
    /// The two-step allocation `t` with its certificate and Monte Carlo; `names`: the errors.
    fn new(t: &'a TwoStep, names: &[&str]) -> Self {
        Self {
            requirement_deg: deg3(&t.problem.requirement().to_array()),
            bounds_arcmin: arcmin_map(names, t.ours.upper_bounds_rad()),
            objective_arcmin: f(t.ours.objective_arcmin()),
            certificate: t
                .ours
                .certificate()
                .axes()
                .iter()
                .map(|a| CertificateJson {
                    angle: a.name(),
                    worst_case_deg: f(rad_to_deg(a.worst_case_rad())),
                    proven_bound_deg: f(rad_to_deg(a.upper_bound_rad())),
                    share: a.share().map(f),
                    lemma1: a.satisfied(),
                })
                .collect(),
            exact_chain_excess_rad: t.exact.iter().map(|e| e.excess_rad().map(f)).collect(),
            monte_carlo: TwoStepMonteCarloJson {
                samples: t.result.count().samples(),
                max_abs_deg: t.result.max_abs_rad().map(|v| f(rad_to_deg(v))),
                proven_bound_deg: t.monte_carlo.half_range_rad().map(|v| f(rad_to_deg(v))),
                within_requirement_fraction: f(t.result.count().fraction()),
            },
        }
    }
}

impl<'a> NoiseJson<'a> {
    /// The noise part `n` under the study's reading and the time/table trade-off.
    fn new(n: &'a tt_lab::end_to_end::NoisyAnswer) -> Self {
        let t = &n.tradeoff;
        let r0 = &n.readings[0];
        Self {
            k_sigma: f(t.k_sigma()),
            noise_sigma: r0.sigma().iter().map(|v| f(*v)).collect(),
            boxes: r0
                .boxes()
                .iter()
                .map(|b| NoiseBoxJson {
                    name: b.name(),
                    verdict: b.verdict().name(),
                    table_part: b.outputs().iter().map(|o| f(o.table_part())).collect(),
                    combined: b.outputs().iter().map(|o| f(o.combined())).collect(),
                    combined_yield: f(b.combined_yield().fraction()),
                })
                .collect(),
            direct_with_noise_objective_arcmin: match &r0.direct() {
                e2e_verify::NoisyDirect::Allocated { allocation, .. } => {
                    Some(f(allocation.objective_arcmin()))
                }
                e2e_verify::NoisyDirect::NoTableSuffices { .. } => None,
            },
            min_dwell_s: t.min_dwell_s().map(f),
            knee_dwell_s: t.knee_dwell_s().map(f),
            dwell_scan: n.scanned.clone(),
            tradeoff: t
                .points()
                .iter()
                .map(|p| TradeoffPointJson {
                    dwell_s: f(p.dwell_s()),
                    total_s: f(p.total_s()),
                    objective_arcmin: p.objective().map(|j| f(objective_to_arcmin(j))),
                })
                .collect(),
        }
    }
}

impl<'a> EndToEndJson<'a> {
    /// The answer under reading `r`; `names`: the errors, `outs`: the outputs.
    fn new(
        r: &'a e2e_verify::ReadingAnswer,
        names: &[&'a str],
        outs: &[&'a str],
        accuracies: &[f64],
    ) -> Self {
        let boxj = |b| box_json(b, names, outs, accuracies);
        Self {
            reading: r.reading().to_string(),
            boxes: r.boxes().iter().map(boxj).collect(),
            direct: boxj(r.direct_box()),
            unconstrained: UnconstrainedJson::new(r.direct(), names),
            yield_based: boxj(r.yield_box()),
            yield_target: f(r.yield_based().target()),
            yield_verdict: r.yield_verdict().name(),
            direct_certified: r.direct_certified().map(|(dc, _)| DirectCertifiedJson {
                objective_arcmin: f(dc.objective_arcmin()),
                bounds_arcmin: arcmin_map(names, dc.upper_bounds_rad()),
            }),
            direct_certified_note: r.direct_certified_note(),
        }
    }
}

impl<'a> VendorJson<'a> {
    /// The vendor check of `c` (`None` without a sheet); `outs`: the outputs.
    fn new(c: &'a Computed, outs: &[&'a str]) -> Option<Self> {
        let (tol, chk) = c.vendor.as_ref()?;
        Some(Self {
            tolerances: tol.source(),
            verdict: chk.verdict().name(),
            yield_fraction: f(chk.distribution().count().fraction()),
            outputs: chk
                .outputs()
                .iter()
                .map(|o| VendorOutputJson {
                    output: outs[o.output()],
                    verdict: o.verdict().name(),
                    worst_case: f(o.worst_case().exact_at_vertex()),
                    accuracy: f(o.accuracy()),
                    precision: f(o.worst_case().precision()),
                })
                .collect(),
            rate_steps: c
                .vendor_rate
                .as_ref()
                .map(|r| tt_lab::vendor::rate::RateCheckJson::new(&c.e2e, r)),
        })
    }
}

impl<'a> DesignedJson<'a> {
    /// One schedule's facts.
    fn new(x: &'a ScheduleFacts) -> Self {
        Self {
            study: &x.path,
            positions: x.positions,
            direct_objective_arcmin: f(x.direct_objective_arcmin),
            condition_numbers: x.conditions.iter().map(|v| f(*v)).collect(),
            requirement_deg: x
                .requirement
                .as_ref()
                .ok()
                .map(|r| deg3(&r.requirement().to_array())),
        }
    }
}

impl ClaimJson {
    /// One claim of the paper evaluated on this run.
    fn new(x: &ClaimEvaluation) -> Self {
        Self {
            id: x.info.id,
            section: x.info.section,
            statement: x.info.statement,
            function: x.info.function,
            test: x.info.test.to_string(),
            test_command: x.info.test.command(),
            holds_paper_reading: x.paper.holds,
            evidence_paper_reading: x.paper.evidence.clone(),
            holds_user_reading: x.user.as_ref().map(|u| u.holds),
            evidence_user_reading: x.user.as_ref().map(|u| u.evidence.clone()),
        }
    }
}

/// `results.json` of `c` as a value (a NaN anywhere is recorded in [`NAN_SEEN`]).
///
/// # Errors
/// None in practice (every key is a string); serde_json's error type.
pub(super) fn results_json(
    c: &Computed,
    comparisons: &[paper::Comparison],
) -> serde_json::Result<Value> {
    let s = &c.study;
    let names = s.turntable.rotation_error_names();
    let outs: Vec<&str> = s.sensor.outputs().iter().map(|o| o.name.as_str()).collect();
    let accuracies = c.e2e.accuracies();
    let r = ResultsJson {
        study: &s.path,
        study_name: &s.name,
        seed: c.options.seed,
        samples: c.options.samples,
        seconds: f(c.seconds),
        reading: s.reading.to_string(),
        requirement: RequirementJson::new(c),
        calibration: s
            .calibration
            .outputs()
            .iter()
            .map(|o| CalibrationJson {
                output: &o.output().name,
                coefficients: o.regression().names(),
                rank: o.regression().rank(),
                condition_number: f(o.regression().condition_number()),
            })
            .collect(),
        groups: GroupJson::all(&s.turntable, &[]),
        average_sensitivity: names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                (
                    (*n).to_string(),
                    PerAngle::new(|a| f(c.sensitivity[i][a.index()])),
                )
            })
            .collect(),
        two_step: c.two_step.as_ref().map(|t| TwoStepJson::new(t, &names)),
        equal_effects: c.equal.as_ref().map(|e| EqualEffectsJson {
            bounds_arcmin: arcmin_map(&names, e.upper_bounds_rad()),
            objective_arcmin: f(e.objective_arcmin()),
        }),
        noise: c.noise.as_ref().map(NoiseJson::new),
        end_to_end: c
            .answer
            .readings()
            .iter()
            .map(|r| EndToEndJson::new(r, &names, &outs, &accuracies))
            .collect(),
        vendor: VendorJson::new(c, &outs),
        designed: c
            .designed
            .as_ref()
            .map(|ds| ds.iter().map(DesignedJson::new).collect()),
        claims: c
            .paper
            .as_ref()
            .map(|p| p.claims.iter().map(ClaimJson::new).collect()),
        claims_summary: c
            .paper
            .as_ref()
            .map(|p| e2e_verify::paper::registry::summary(&p.claims)),
        paper_versus_ours: c.paper.as_ref().map(|_| {
            comparisons
                .iter()
                .map(|r| ComparisonJson {
                    quantity: &r.quantity,
                    paper: f(r.paper),
                    ours: f(r.ours),
                    unit: r.unit,
                    reason: &r.reason,
                })
                .collect()
        }),
        rate_allocation: c
            .rate_alloc
            .as_ref()
            .map(|r| tt_lab::vendor::rate::RateAllocationJson::new(&c.e2e, r)),
        angle_dependent: c
            .angle_alloc
            .as_ref()
            .map(|a| tt_lab::allocation::angle::AngleDependentJson::new(&c.e2e, a)),
        estimable: match &c.estimable {
            Some(a) => EstimableJson::Answer(Box::new(tt_lab::estimable::to_json(s, a))),
            None => EstimableJson::Note {
                note: crate::report::ESTIMABLE_STATIC_ONLY,
            },
        },
        specifications: c.decision.as_ref().map(|(ub, v)| SpecificationsJson {
            tolerances_rad: names
                .iter()
                .zip(ub)
                .map(|(n, b)| ((*n).to_string(), f(*b)))
                .collect(),
            verdict: tt_lab::vendor::spec::SpecVerdictJson::new(s, Some(v)),
        }),
        processed_run: c.options.run.as_ref().map(|r| r.answer.view(None)),
    };
    serde_json::to_value(r)
}
