//! The vendor check ([`check`], the command line's `check-turntable`): "the vendor's sheet
//! says these tolerances: will my calibration meet its accuracy, and which error dominates?"
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
use crate::Result;
use crate::json::{ArcminBounds, CombinedYieldJson, GroupJson, Split, arcmin_bounds};
use calib_lsq::Reading;
use e2e_verify::{
    CombinedOutput, EndToEnd, McSettings, ToleranceSheet, TurntableCheck, Verdict, YieldCount,
};

pub mod angle;
pub mod rate;
pub mod spec;

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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ContributionJson<'a> {
    /// The error's name, or its group's combination.
    pub error: String,
    /// The errors of the group (one when the error acts alone).
    pub errors: Vec<&'a str>,
    /// Its share of the linearised worst case, in [0, 1].
    pub worst_case_share: f64,
    /// Its share of the variance over the box, in [0, 1].
    pub variance_share: f64,
}

/// One output's check (`outputs[]`), output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CheckOutputJson<'a> {
    /// The output's name.
    pub name: &'a str,
    /// Its unit (the study's).
    pub unit: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// Its verdict (with the noise part: counting both).
    pub verdict: &'static str,
    /// With the noise part: the table's verdict alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
    /// The linearised worst case over the sheet's box, output's unit.
    pub worst_case_linear: f64,
    /// The exact chain at the worst vertex, output's unit.
    pub worst_case_exact_at_vertex: f64,
    /// The second-order bound (`null` when not computed), output's unit.
    pub second_order_bound: Option<f64>,
    /// The certified bound (`null` when not computed), output's unit.
    pub certified_bound: Option<f64>,
    /// The worst test position (index into the schedule).
    pub worst_position: usize,
    /// The computation's precision, output's unit.
    pub precision: f64,
    /// Fraction of the Monte Carlo turntables meeting this output's accuracy, in [0, 1].
    pub meeting_fraction: f64,
    /// Largest error over the Monte Carlo turntables, output's unit.
    pub monte_carlo_max: f64,
    /// Each error's (or group's) contribution.
    pub contributions: Vec<ContributionJson<'a>>,
    /// With the noise part: the split between the table and the noise; absent otherwise.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub split: Option<Split>,
}

/// One reading's check; with the noise part, every output gets the split, `verdict` counts
/// the noise and `table_verdict` is the table's alone.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ReadingCheckJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// The verdict (with the noise part: counting both).
    pub verdict: &'static str,
    /// With the noise part: the table's verdict alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
    /// Monte Carlo yield over the sheet's box, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Every output's check.
    pub outputs: Vec<CheckOutputJson<'a>>,
    /// With the noise part: its confidence multiplier (`null` without outputs); absent
    /// otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub k_sigma: Option<Option<f64>>,
    /// With the noise part: the yield over turntables and noise; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub combined_yield: Option<CombinedYieldJson>,
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
                                error: k
                                    .group()
                                    .combination(&e2e.turntable().rotation_error_names()),
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CheckJson<'a> {
    /// The study's reading's check (its keys at the top level).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) study_reading: ReadingCheckJson<'a>,
    /// The sheet's path.
    pub tolerances: &'a str,
    /// The sheet's angular tolerances, arcmin.
    pub tolerances_arcmin: ArcminBounds,
    /// Errors that act only together.
    pub groups: Vec<GroupJson>,
    /// The user's reading's check, `null` when it is the study's.
    pub(crate) user_reading: Option<ReadingCheckJson<'a>>,
    /// Without rate steps: the check when the errors vary with the shaft angle; absent with
    /// rate steps.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub(crate) angle_dependent: Option<crate::vendor::angle::AngleCheckJson<'a>>,
    /// Without rate steps: the check of the compensated table (`null` without measured
    /// errors); absent with rate steps.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub(crate) compensated: Option<Option<crate::vendor::angle::CompensatedJson<'a>>>,
    /// With rate steps: what the angular check holds at zero; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub rate_steps_note: Option<&'static str>,
    /// With rate steps: per reading, the check with the errors only rotation exposes bounded
    /// by the sheet; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub rate_steps: Option<Vec<crate::vendor::rate::RateCheckJson<'a>>>,
    /// The decision rule and the verdict against the study's specifications per quantity
    /// (the GUM budget of each over the sheet's tolerances); the accuracy rule without.
    pub decision: Option<crate::vendor::spec::SpecVerdictJson>,
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

/// The checks with the noise part, one per check (empty when the study gives no noise or no
/// timing): every output's combined answer, the verdict counting both and the yield over
/// turntables in the sheet's box and noise.
///
/// # Errors
/// As [`e2e_verify::NoiseQuestions::noise_budget`] and [`e2e_verify::NoiseQuestions::combined_yield`].
pub fn noisy_checks(
    s: &study::Study,
    e2e: &EndToEnd,
    checks: &[(EndToEnd, TurntableCheck)],
    sheet: &ToleranceSheet,
    settings: &McSettings,
    k_sigma: f64,
) -> Result<Vec<NoisyCheck>> {
    let Some(budget) = crate::end_to_end::noise_budget(s, e2e)? else {
        return Ok(Vec::new());
    };
    let sigma = budget.sigma();
    let bounds = e2e
        .box_of(sheet.upper_bounds_rad(), sheet.lower_bounds_rad())
        .map_err(|e| crate::error::library(e, s))?;
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
                .noise()
                .combined_yield(&bounds, &budget, settings)
                .map_err(|e| crate::error::library(e, s))?;
            Ok(NoisyCheck {
                verdict: e2e_verify::noise::weakest(outputs.iter().map(|o| o.verdict())),
                outputs,
                combined_yield,
            })
        })
        .collect()
}

/// The options of [`check`]: the Monte Carlo size and seed (default: the study's) and the
/// noise part's confidence multiplier.
#[derive(Debug, Clone)]
pub struct Options {
    /// Monte Carlo turntables (`None`: the study's `monte_carlo.samples`).
    pub samples: Option<u64>,
    /// Seed of the random streams (`None`: the study's).
    pub seed: Option<u64>,
    /// Confidence multiplier of the noise part (combined = table + k sigma).
    pub k_sigma: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            samples: None,
            seed: None,
            k_sigma: e2e_verify::DEFAULT_K_SIGMA,
        }
    }
}

/// The note of a vendor check of a study with rate steps (JSON `rate_steps_note`).
pub const RATE_STEPS_NOTE: &str = "the study has rate steps: the angular errors' check above holds the rate errors and translations at zero; the check below bounds them by the sheet; errors that vary with a shaft angle are modelled at static positions only (not checked here)";

/// A vendor's sheet checked against a study ([`check`]): per reading the table's check, the
/// noise part, then either the angle-dependent and compensated parts (a static study) or the
/// rate part (a study with rate steps), and the verdict against the specifications.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct VendorCheck {
    sheet: ToleranceSheet,
    checks: Vec<(EndToEnd, TurntableCheck)>,
    noisy: Vec<NoisyCheck>,
    angle: Option<angle::AngleCheck>,
    compensated: Option<angle::Compensated>,
    counted: Vec<Verdict>,
    rate: Option<Vec<rate::RateCheck>>,
    decision: Option<e2e_verify::budget::PlanVerdict>,
}

impl VendorCheck {
    /// The sheet as loaded (a measured table inside it).
    #[must_use]
    pub fn sheet(&self) -> &ToleranceSheet {
        &self.sheet
    }
    /// Per reading (the study's first, then the user's when it differs): its simulator and
    /// the table's check.
    #[must_use]
    pub fn checks(&self) -> &[(EndToEnd, TurntableCheck)] {
        &self.checks
    }
    /// Per reading, the noise part (empty without noise or timing).
    #[must_use]
    pub fn noisy(&self) -> &[NoisyCheck] {
        &self.noisy
    }
    /// The angle-dependent part (a static study).
    #[must_use]
    pub fn angle(&self) -> Option<&angle::AngleCheck> {
        self.angle.as_ref()
    }
    /// The compensated part (a sheet with measured errors; a static study).
    #[must_use]
    pub fn compensated(&self) -> Option<&angle::Compensated> {
        self.compensated.as_ref()
    }
    /// Per reading, the verdict that counts the noise part (the table's without noise).
    #[must_use]
    pub fn counted(&self) -> &[Verdict] {
        &self.counted
    }
    /// The rate part, per reading (a study with rate steps).
    #[must_use]
    pub fn rate(&self) -> Option<&[rate::RateCheck]> {
        self.rate.as_deref()
    }
    /// The verdict against the study's specifications over the sheet's box.
    #[must_use]
    pub fn decision(&self) -> Option<&e2e_verify::budget::PlanVerdict> {
        self.decision.as_ref()
    }
}

/// Will a vendor's tolerances (the sheet at `tolerances`) deliver the study's accuracies, and
/// which error dominates?
///
/// # Errors
/// An [`InputError`] for a sheet the study refuses (a measured table outside it, an unbounded
/// rate error with rate steps); a library error if a computation fails.
pub fn check(s: &study::Study, tolerances: &std::path::Path, o: &Options) -> Result<VendorCheck> {
    // a measured table outside the sheet is refused before any computation
    let sheet = s.load_sheet(tolerances).map_err(InputError::from)?;
    let e2e = crate::loaded::simulator(s)?;
    let settings = McSettings::new(
        o.samples.unwrap_or(s.monte_carlo.samples),
        o.seed.unwrap_or(s.monte_carlo.seed),
    );
    let checks = reading_checks(s, &e2e, &sheet, &settings)?;
    let noisy = noisy_checks(s, &e2e, &checks, &sheet, &settings, o.k_sigma)?;
    let counted: Vec<Verdict> = checks
        .iter()
        .enumerate()
        .map(|(i, (_, c))| noisy.get(i).map_or(c.verdict(), |n| n.verdict))
        .collect();
    let mut v = VendorCheck {
        sheet,
        checks,
        noisy,
        angle: None,
        compensated: None,
        counted,
        rate: None,
        decision: None,
    };
    let noise = v.noisy.first().map(|n| angle::NoisePart {
        sigma: n.outputs.iter().map(CombinedOutput::noise_sigma).collect(),
        k_sigma: o.k_sigma,
    });
    if e2e.has_rate_steps() {
        v.decision = spec::compute(s, &v.checks[0].0, v.sheet.upper_bounds_rad())?;
        v.rate = Some(
            v.checks
                .iter()
                .map(|(sim, _)| rate::check_with_noise(s, sim, &v.sheet, &settings, noise.clone()))
                .collect::<Result<Vec<_>>>()?,
        );
        return Ok(v);
    }
    v.angle = Some(angle::check(
        s,
        &v.checks,
        &v.sheet,
        settings.samples,
        settings.seed,
        true,
        noise.as_ref(),
    )?);
    v.compensated = angle::compensated(s, &v.checks, &v.sheet, &settings, noise.as_ref())?;
    v.decision = spec::compute(s, &e2e, v.sheet.upper_bounds_rad())?;
    Ok(v)
}

/// The table's check of the sheet under the study's reading, then the user's when it differs.
fn reading_checks(
    s: &study::Study,
    e2e: &EndToEnd,
    sheet: &ToleranceSheet,
    settings: &McSettings,
) -> Result<Vec<(EndToEnd, TurntableCheck)>> {
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != Reading::USER {
        sims.push(
            e2e.with_reading(Reading::USER)
                .map_err(|e| crate::error::library(e, s))?,
        );
    }
    sims.into_iter()
        .map(|sim| {
            let c = sim
                .vendor()
                .check_sheet(sheet, settings)
                .map_err(|e| crate::error::library(e, s))?;
            Ok((sim, c))
        })
        .collect()
}

impl<'a> CheckJson<'a> {
    /// The `check-turntable --json` view of a whole vendor check.
    #[must_use]
    pub fn of(s: &study::Study, v: &'a VendorCheck) -> Self {
        let mut j = Self::new(&v.checks, &v.sheet, &v.noisy);
        if let Some(rate) = &v.rate {
            j.rate_steps_note = Some(RATE_STEPS_NOTE);
            j.rate_steps = Some(
                v.checks
                    .iter()
                    .zip(rate)
                    .map(|((e2e, _), r)| rate::RateCheckJson::new(e2e, r))
                    .collect(),
            );
        }
        if let Some(a) = &v.angle {
            j.angle_dependent = Some(angle::AngleCheckJson::new(&v.checks, a));
            j.compensated = Some(
                v.compensated
                    .as_ref()
                    .map(|c| angle::CompensatedJson::new(&v.checks, c)),
            );
        }
        j.decision = Some(spec::SpecVerdictJson::new(s, v.decision.as_ref()));
        j
    }
}
