//! Rate steps in the vendor check and the allocation (issue 23): the bounds a vendor's sheet gives the errors only
//! rotation exposes (translations in `[tolerances_mm]`, a turning joint's rate accuracy and
//! ripple in `[tolerances_ppm]`), and `check-turntable`'s answer with both boxes.
//!
//! A study with rate steps has, besides the angular errors, the extra errors of
//! [`e2e_verify::rate`]; the orientation requirement of eq 15-16 is a static concept (one
//! orientation error at every test position), so commands that use it say so and use the
//! direct allocation.

use crate::InputError;
use crate::Result;
use crate::json::{ArcminBounds, arcmin_bounds};
pub use crate::vendor::angle::NoisePart;
use e2e_verify::{
    EndToEnd, ExtraError, ExtraOutputWorstCase, McSettings, NoRoom, RateAllocation, RateTolerance,
    ToleranceSheet, YieldCount,
};
use study::Study;
use tt_core::human::num;

/// The line every command prints for a study with rate steps.
pub use crate::loaded::STATIC_REQUIREMENT_NOTE;

/// The note `end-to-end` and `calibration-error` print for a study with rate steps (JSON
/// `requirement_note`): the requirement is static, and the errors only rotation exposes are
/// held at zero.
#[must_use]
pub fn rate_steps_note(e2e: &EndToEnd) -> String {
    format!(
        "{STATIC_REQUIREMENT_NOTE}; the errors only rotation exposes ({}) are held at zero in the allocations above (an ideal rate table); the direct allocation with the rate tolerances (JSON `rate_allocation`) allocates them with the angles, and `check-turntable` bounds them by a vendor's sheet",
        e2e.extra_names().join(", ")
    )
}

/// The bound of every extra error from the sheet (m, relative), in the order of
/// [`EndToEnd::extra_errors`].
///
/// # Errors
/// An [`InputError`] naming the sheet's key when the study has rate steps and the sheet
/// bounds a translation or a turning joint's rate accuracy or ripple not at all.
pub(crate) fn extra_bounds(e2e: &EndToEnd, sheet: &ToleranceSheet) -> Result<Vec<f64>, InputError> {
    let t = e2e.turntable();
    e2e.extra_errors()
        .iter()
        .map(|x| {
            let (value, key) = match *x {
                ExtraError::Translation(i) => (
                    sheet.translations_m()[i],
                    format!("tolerances_mm.{}", t.translation_errors()[i].name),
                ),
                ExtraError::RateAccuracy(j) => (
                    sheet.rate_accuracy()[j],
                    format!("tolerances_ppm.{}_rate_accuracy", t.joints()[j].name),
                ),
                ExtraError::RippleCos(j) | ExtraError::RippleSin(j) => (
                    sheet.rate_ripple()[j],
                    format!("tolerances_ppm.{}_rate_ripple", t.joints()[j].name),
                ),
            };
            value.ok_or_else(|| {
                InputError::new(
                    format!("{}: key `{key}`", sheet.source()),
                    "the study has rate steps: at a rate step this error acts, so the sheet must bound it",
                )
            })
        })
        .collect()
}

/// A value of a translation (m) or a relative rate error in the sheet's unit: mm or ppm.
#[must_use]
fn sheet_units(is_translation: bool, v: f64) -> (f64, &'static str) {
    if is_translation {
        (v * 1e3, "mm")
    } else {
        (v * 1e6, "ppm")
    }
}

/// A bound or share of an extra error in the sheet's unit: mm or ppm.
#[must_use]
pub fn in_sheet_units(x: &ExtraError, v: f64) -> (f64, &'static str) {
    sheet_units(x.is_translation(), v)
}

/// `check-turntable`'s answer with rate steps: the worst case over the angular box and the
/// extra errors' box, each extra error's part, and the yield over both boxes.
#[derive(Debug, Clone)]
pub struct RateCheck {
    /// The extra errors' bounds (m, relative).
    pub bounds: Vec<f64>,
    /// Per output.
    pub outputs: Vec<ExtraOutputWorstCase>,
    /// Turntables of both boxes drawn (with the seed) and meeting every accuracy.
    pub count: YieldCount,
    /// The largest error drawn, per output.
    pub max_drawn: Vec<f64>,
    /// The study's noise part of every output (its covariance over the study's timing, the
    /// rate steps' windows included), counted by the verdict; `None` without noise or timing.
    pub noise: Option<NoisePart>,
}

impl RateCheck {
    /// The table's part of output `o` over both boxes: the larger of its linearised worst case
    /// and the exact chain at its worst vertex (output's unit).
    #[must_use]
    pub fn table_part(o: &ExtraOutputWorstCase) -> f64 {
        o.linear_bound().max(o.exact_at_vertex())
    }

    /// The noise part of output `k` (`k_sigma` sigma; 0 without noise), output's unit.
    #[must_use]
    pub(crate) fn noise_part(&self, k: usize) -> f64 {
        self.noise.as_ref().map_or(0.0, |n| n.margin(k))
    }

    /// Whether output `o`'s table part plus its noise part is within `accuracy`.
    #[must_use]
    pub fn output_meets(&self, o: &ExtraOutputWorstCase, accuracy: f64) -> bool {
        Self::table_part(o) + self.noise_part(o.output()) <= accuracy
    }

    /// Whether every output's worst case (linear and exact) plus its noise part (with the
    /// study's noise) is within its accuracy: every modelled source counted.
    #[must_use]
    pub fn meets_every_accuracy(&self, e2e: &EndToEnd) -> bool {
        self.outputs
            .iter()
            .zip(e2e.accuracies())
            .all(|(o, a)| self.output_meets(o, a))
    }

    /// Whether the table's part alone (both boxes, noise held at zero) is within every
    /// accuracy.
    #[must_use]
    pub fn table_meets_every_accuracy(&self, e2e: &EndToEnd) -> bool {
        self.outputs
            .iter()
            .zip(e2e.accuracies())
            .all(|(o, a)| Self::table_part(o) <= a)
    }

    /// The rule of the verdict, in words (every source it counts).
    #[must_use]
    pub fn rule(&self) -> String {
        let table = "the worst case over the angular box and the rate errors' and translations' box (linearised and on the exact chain at its worst vertex)";
        match &self.noise {
            Some(n) => format!(
                "{table} plus {} sigma of the noise (static positions and rate steps' windows) against the accuracy",
                num(n.k_sigma)
            ),
            None => format!("{table} against the accuracy (the study gives no noise)"),
        }
    }
}

/// The study's noise part of every output at `k_sigma` (the covariance over the study's
/// timing, rate steps' windows included), `None` without noise or timing.
///
/// # Errors
/// As [`crate::end_to_end::noise_budget`].
pub(crate) fn noise_part(s: &Study, e2e: &EndToEnd, k_sigma: f64) -> Result<Option<NoisePart>> {
    Ok(crate::end_to_end::noise_budget(s, e2e)?.map(|b| NoisePart {
        sigma: b.sigma(),
        k_sigma,
    }))
}

/// Compute the [`RateCheck`] of `e2e` (a study with rate steps) for the sheet.
///
/// # Errors
/// As [`extra_bounds`]; a library error located in the study or the sheet.
pub fn check(
    s: &Study,
    e2e: &EndToEnd,
    sheet: &ToleranceSheet,
    settings: &McSettings,
) -> Result<RateCheck> {
    let noise = noise_part(s, e2e, e2e_verify::DEFAULT_K_SIGMA)?;
    check_with_noise(s, e2e, sheet, settings, noise)
}

/// [`check`] with the noise part `noise` counted by the verdict (`None`: the table alone).
///
/// # Errors
/// As [`check`].
pub(crate) fn check_with_noise(
    s: &Study,
    e2e: &EndToEnd,
    sheet: &ToleranceSheet,
    settings: &McSettings,
    noise: Option<NoisePart>,
) -> Result<RateCheck> {
    let bounds = extra_bounds(e2e, sheet)?;
    let outputs = e2e
        .rates()
        .worst_case_with_extra(
            &e2e.linearization(),
            &e2e.rates().extra_linearization(),
            sheet.upper_bounds_rad(),
            &bounds,
        )
        .map_err(|e| crate::error::library_at(e, s, sheet.source()))?;
    let (meets, max_drawn) = e2e
        .rates()
        .meeting_count_with_extra(
            sheet.upper_bounds_rad(),
            sheet.lower_bounds_rad(),
            &bounds,
            settings,
        )
        .map_err(|e| crate::error::library_at(e, s, sheet.source()))?;
    Ok(RateCheck {
        bounds,
        outputs,
        count: YieldCount::new(settings.samples, settings.seed, meets, Vec::new()),
        max_drawn,
        noise,
    })
}

/// A rate tolerance's bound in the sheet's unit: mm or ppm.
#[must_use]
pub fn tolerance_in_sheet_units(t: &RateTolerance, v: f64) -> (f64, &'static str) {
    sheet_units(t.is_translation(), v)
}

/// The direct allocation of the angles and the rate tolerances together, with the Monte Carlo
/// over both of its boxes (exact chain at random points: evidence beside the worst-vertex
/// check, not a certificate) and the certified allocation.
#[derive(Debug, Clone)]
pub struct RateAllocated {
    /// The allocation.
    pub allocation: RateAllocation,
    /// The certified allocation ([`e2e_verify::RateQuestions::allocate_direct_rate_certified`]), or why there
    /// is none.
    pub certified: std::result::Result<RateAllocation, String>,
    /// Turntables of both allocated boxes drawn (with the seed) and meeting every accuracy.
    pub count: YieldCount,
    /// The largest error drawn, per output.
    pub max_drawn: Vec<f64>,
    /// With the study's noise: the same allocation with the noise part kept free.
    pub with_noise: Option<RateWithNoise>,
}

/// The direct allocation with the rate tolerances and the noise part kept free (issue 35):
/// every output's rows over both boxes held to its accuracy less `k_sigma` sigma, so the
/// angles and the rate tolerances share what the noise leaves.
#[derive(Debug, Clone)]
pub struct RateWithNoise {
    /// The noise part counted.
    pub noise: NoisePart,
    /// The allocation, or the outputs whose noise part (with the lower bounds' table part)
    /// leaves no room: no table suffices at this dwell.
    pub allocation: std::result::Result<RateAllocation, Vec<NoRoom>>,
    /// The certified allocation with the noise part kept free, or why there is none
    /// (`None` when no table suffices).
    pub certified: Option<std::result::Result<RateAllocation, String>>,
}

/// The certified allocation, or why there is none (a reading without a derived bound, no
/// convergence); other errors are the library's.
fn certified_or_why<T>(
    s: &Study,
    r: std::result::Result<T, e2e_verify::E2eError>,
) -> Result<std::result::Result<T, String>> {
    match r {
        Ok(c) => Ok(Ok(c)),
        Err(
            e @ (e2e_verify::E2eError::NoSecondOrderBound { .. }
            | e2e_verify::E2eError::NoConvergence { .. }),
        ) => Ok(Err(e.to_string())),
        Err(e) => Err(crate::error::library(e, s)),
    }
}

/// The direct allocation of the angles and the rate tolerances together for a study with
/// rate steps, and its Monte Carlo over both boxes (`None` for a static study); with the
/// study's noise, also the allocation keeping its noise part (`DEFAULT_K_SIGMA` sigma) free.
///
/// # Errors
/// A library error located in the study.
pub fn allocation(
    s: &Study,
    e2e: &EndToEnd,
    settings: &McSettings,
) -> Result<Option<RateAllocated>> {
    allocation_with_k(s, e2e, settings, e2e_verify::DEFAULT_K_SIGMA)
}

/// [`allocation`] with the noise part at `k_sigma` sigma.
///
/// # Errors
/// As [`allocation`].
pub(crate) fn allocation_with_k(
    s: &Study,
    e2e: &EndToEnd,
    settings: &McSettings,
    k_sigma: f64,
) -> Result<Option<RateAllocated>> {
    if !e2e.has_rate_steps() {
        return Ok(None);
    }
    let a = e2e
        .rates()
        .allocate_direct_rate(
            &e2e.linearization(),
            &e2e.rates().extra_linearization(),
            &s.lower_bounds_rad,
        )
        .map_err(|e| crate::error::library(e, s))?;
    let extra = e2e.rates().extra_bounds_of(a.tolerance_bounds());
    let (meets, max_drawn) = e2e
        .rates()
        .meeting_count_with_extra(a.angles_rad(), &s.lower_bounds_rad, &extra, settings)
        .map_err(|e| crate::error::library(e, s))?;
    let certified = certified_or_why(
        s,
        e2e.rates().allocate_direct_rate_certified(
            &e2e.linearization(),
            &e2e.rates().extra_linearization(),
            &s.lower_bounds_rad,
        ),
    )?;
    let with_noise = match crate::end_to_end::noise_budget(s, e2e)? {
        Some(budget) => Some(with_noise(s, e2e, &budget, k_sigma)?),
        None => None,
    };
    Ok(Some(RateAllocated {
        allocation: a,
        certified,
        count: YieldCount::new(settings.samples, settings.seed, meets, Vec::new()),
        max_drawn,
        with_noise,
    }))
}

/// The allocation with the rate tolerances keeping `budget`'s noise part free, and its
/// certified form.
fn with_noise(
    s: &Study,
    e2e: &EndToEnd,
    budget: &e2e_verify::NoiseBudget,
    k_sigma: f64,
) -> Result<RateWithNoise> {
    let lib = |e| crate::error::library(e, s);
    let (lin, extra) = (e2e.linearization(), e2e.rates().extra_linearization());
    let allocation = e2e
        .rates()
        .allocate_direct_rate_with_noise(&lin, &extra, &s.lower_bounds_rad, budget, k_sigma, None)
        .map_err(lib)?;
    let certified = match &allocation {
        Ok(_) => Some(
            certified_or_why(
                s,
                e2e.rates().allocate_direct_rate_with_noise(
                    &lin,
                    &extra,
                    &s.lower_bounds_rad,
                    budget,
                    k_sigma,
                    Some(&e2e_verify::CertifyParams::default()),
                )
                .and_then(|c| {
                    c.map_err(|_| e2e_verify::E2eError::NoConvergence {
                        what: "certified direct allocation with rate tolerances and noise (the noise leaves no room)",
                        iterations: 0,
                        change: 0.0,
                    })
                }),
            )?,
        ),
        Err(_) => None,
    };
    Ok(RateWithNoise {
        noise: NoisePart {
            sigma: budget.sigma(),
            k_sigma,
        },
        allocation,
        certified,
    })
}

/// A rate error or translation bounded by the sheet (`extra_errors[]`), in the sheet's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ExtraErrorJson {
    /// The error's name.
    pub name: String,
    /// Its bound, `unit`.
    pub bound: f64,
    /// `mm` or `ppm`.
    pub unit: &'static str,
}

/// One error's part of an output's worst case, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ExtraPartJson {
    /// The error's name.
    pub error: String,
    /// Its part, output's unit.
    pub part: f64,
}

/// One output's worst case over both boxes, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct RateOutputJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// The linearised worst case over both boxes, output's unit.
    pub linear_bound: f64,
    /// The angular errors' part, output's unit.
    pub angular_part: f64,
    /// The rate errors' and translations' part, output's unit.
    pub extra_part: f64,
    /// Each such error's part.
    pub(crate) extra_parts: Vec<ExtraPartJson>,
    /// The worst schedule entry (index).
    pub entry: usize,
    /// The exact chain at the worst vertex, output's unit.
    pub exact_at_vertex: f64,
    /// Whether both are within the accuracy (with the study's noise: both plus the noise
    /// part).
    pub meets: bool,
    /// With the study's noise: the noise part counted; absent otherwise.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub noise: Option<RateNoiseSplitJson>,
}

/// One output's noise part in the rate check, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct RateNoiseSplitJson {
    /// The table's part: the larger of `linear_bound` and `exact_at_vertex`.
    pub table_part: f64,
    /// One standard deviation of the noise, output's unit.
    pub noise_sigma: f64,
    /// The confidence multiplier.
    pub k_sigma: f64,
    /// `k_sigma * noise_sigma`.
    pub noise_part: f64,
    /// `table_part + noise_part`.
    pub combined: f64,
    /// Whether the table's part alone is within the accuracy.
    pub table_meets: bool,
}

/// The check with the errors only rotation exposes (`rate_steps[]`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateCheckJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// The sheet's rate errors and translations.
    pub(crate) extra_errors: Vec<ExtraErrorJson>,
    /// Every output's worst case.
    pub(crate) outputs: Vec<RateOutputJson<'a>>,
    /// Monte Carlo yield over both boxes, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// Largest error of each output over the draws, output's unit.
    pub max_drawn: &'a [f64],
    /// `meets` or `does not meet` (with the study's noise: table and noise counted).
    pub verdict: &'static str,
    /// With the study's noise: the table's verdict alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
    /// With the study's noise: the verdict's rule, every source it counts; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub rule: Option<String>,
}

/// `meets` or `does not meet`.
fn meets_name(meets: bool) -> &'static str {
    if meets { "meets" } else { "does not meet" }
}

impl<'a> RateCheckJson<'a> {
    /// The view of the check `c` of `e2e`.
    #[must_use]
    pub fn new(e2e: &'a EndToEnd, c: &'a RateCheck) -> Self {
        let names = e2e.extra_names();
        let acc = e2e.accuracies();
        Self {
            reading: e2e.reading().to_string(),
            extra_errors: e2e
                .extra_errors()
                .iter()
                .zip(&names)
                .zip(&c.bounds)
                .map(|((x, n), b)| {
                    let (bound, unit) = in_sheet_units(x, *b);
                    ExtraErrorJson {
                        name: n.clone(),
                        bound,
                        unit,
                    }
                })
                .collect(),
            outputs: c
                .outputs
                .iter()
                .map(|o| RateOutputJson {
                    output: &e2e.calibration().outputs()[o.output()].output().name,
                    accuracy: acc[o.output()],
                    linear_bound: o.linear_bound(),
                    angular_part: o.angular_part(),
                    extra_part: o.extra_part(),
                    extra_parts: names
                        .iter()
                        .zip(o.extra_parts())
                        .map(|(n, v)| ExtraPartJson {
                            error: n.clone(),
                            part: *v,
                        })
                        .collect(),
                    entry: o.position(),
                    exact_at_vertex: o.exact_at_vertex(),
                    meets: c.output_meets(o, acc[o.output()]),
                    noise: c.noise.as_ref().map(|n| {
                        let table_part = RateCheck::table_part(o);
                        RateNoiseSplitJson {
                            table_part,
                            noise_sigma: n.sigma[o.output()],
                            k_sigma: n.k_sigma,
                            noise_part: n.margin(o.output()),
                            combined: table_part + n.margin(o.output()),
                            table_meets: table_part <= acc[o.output()],
                        }
                    }),
                })
                .collect(),
            yield_fraction: c.count.fraction(),
            yield_interval_95: c.count.interval_95(),
            samples: c.count.samples(),
            max_drawn: &c.max_drawn,
            verdict: meets_name(c.meets_every_accuracy(e2e)),
            table_verdict: c
                .noise
                .as_ref()
                .map(|_| meets_name(c.table_meets_every_accuracy(e2e))),
            rule: c.noise.as_ref().map(|_| c.rule()),
        }
    }
}

/// A rate tolerance allocated (`tolerances[]`), in the sheet's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ToleranceJson {
    /// The tolerance's name.
    pub name: String,
    /// Its bound, `unit`; `null` when unbounded.
    pub bound: Option<f64>,
    /// `mm` or `ppm`.
    pub unit: &'static str,
    /// Its weight in J, SI unit per rad (absent in the certified allocation).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub weight_si_per_rad: Option<f64>,
}

/// One output of the certified allocation with the rate tolerances, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CertifiedOutputJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// The linearised worst case, output's unit.
    pub linear_bound: f64,
    /// The second-order bound, output's unit.
    pub second_order_bound: f64,
    /// The certified bound, output's unit.
    pub certified_bound: f64,
}

/// The certified allocation with the rate tolerances (`rate_allocation.certified`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CertifiedRateJson<'a> {
    /// J, arcmin^-2.
    pub objective_arcmin: f64,
    /// The angular bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// The rate tolerances.
    pub tolerances: Vec<ToleranceJson>,
    /// Every output's bounds.
    pub outputs: Vec<CertifiedOutputJson<'a>>,
    /// Rounds of the certification.
    pub rounds: usize,
}

impl<'a> CertifiedRateJson<'a> {
    /// The view of `c`, `None` when it has no certificate.
    fn new(e2e: &'a EndToEnd, c: &RateAllocation) -> Option<Self> {
        let cert = c.certificate()?;
        let names = e2e.turntable().rotation_error_names();
        let acc = e2e.accuracies();
        Some(Self {
            objective_arcmin: c.combined().objective_arcmin(),
            bounds_arcmin: arcmin_bounds(&names, c.angles_rad()),
            tolerances: e2e
                .rates()
                .rate_tolerance_names()
                .into_iter()
                .zip(c.tolerances())
                .zip(c.tolerance_bounds())
                .map(|((name, t), b)| {
                    let (v, unit) = tolerance_in_sheet_units(t, *b);
                    ToleranceJson {
                        name,
                        bound: b.is_finite().then_some(v),
                        unit,
                        weight_si_per_rad: None,
                    }
                })
                .collect(),
            outputs: (0..acc.len())
                .map(|k| CertifiedOutputJson {
                    output: &e2e.calibration().outputs()[k].output().name,
                    accuracy: acc[k],
                    linear_bound: cert.linear_bounds()[k],
                    second_order_bound: cert.second_order_bounds()[k],
                    certified_bound: cert.certified_bound(k),
                })
                .collect(),
            rounds: cert.rounds(),
        })
    }
}

/// One output of the allocation with the rate tolerances, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AllocatedOutputJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// The linearised worst case, output's unit.
    pub linear_bound: f64,
    /// The exact chain at the worst vertex, output's unit.
    pub exact_at_vertex: f64,
    /// The worst schedule entry (index).
    pub entry: usize,
    /// `accuracy - exact_at_vertex`, output's unit.
    pub margin: f64,
    /// The room kept for the second-order terms, output's unit.
    pub second_order_room: f64,
}

/// The allocation with the rate tolerances (`rate_allocation`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateAllocationJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// J, arcmin^-2.
    pub objective_arcmin: f64,
    /// The angular bounds, arcmin.
    pub bounds_arcmin: ArcminBounds,
    /// The rate tolerances.
    pub(crate) tolerances: Vec<ToleranceJson>,
    /// Every output's worst case.
    pub(crate) outputs: Vec<AllocatedOutputJson<'a>>,
    /// Rounds of the exact-chain check.
    pub exact_rounds: usize,
    /// Monte Carlo yield over both boxes, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// Largest error of each output over the draws, output's unit.
    pub max_drawn: &'a [f64],
    /// Why the direct allocation is not certified at rate steps.
    pub direct_note: &'static str,
    /// The certified allocation, `null` when there is none (`certified_note`).
    pub(crate) certified: Option<CertifiedRateJson<'a>>,
    /// Why there is no certified allocation, else `null`.
    pub certified_note: Option<&'a str>,
    /// With the study's noise: the allocation keeping the noise part free; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub(crate) with_noise: Option<RateWithNoiseJson<'a>>,
}

/// One output of the allocation with the rate tolerances and the noise part kept free,
/// output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct NoisyAllocatedOutputJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// `k_sigma` sigma of the noise kept free, output's unit.
    pub noise_part: f64,
    /// The linearised worst case of the table over both boxes, output's unit.
    pub linear_bound: f64,
    /// The exact chain at the worst vertex, output's unit.
    pub exact_at_vertex: f64,
    /// `exact_at_vertex + noise_part`, output's unit.
    pub combined: f64,
    /// `accuracy - combined`, output's unit.
    pub margin: f64,
}

/// An output the noise leaves no room (`with_noise.no_room[]`), output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct RateNoRoomJson<'a> {
    /// The output's name.
    pub output: &'a str,
    /// `k_sigma` sigma of the noise.
    pub noise_part: f64,
    /// The part the errors' lower bounds take.
    pub lower_bounds_part: f64,
}

/// The allocation with the rate tolerances and the noise part kept free
/// (`rate_allocation.with_noise`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct RateWithNoiseJson<'a> {
    /// The rule: what each output's accuracy is shared between.
    pub rule: String,
    /// The confidence multiplier.
    pub k_sigma: f64,
    /// Each output's noise sigma, output's unit.
    pub noise_sigma: &'a [f64],
    /// Whether the noise leaves no room for any table at this dwell.
    pub no_table_suffices: bool,
    /// The outputs the noise leaves no room (empty when a table suffices).
    pub no_room: Vec<RateNoRoomJson<'a>>,
    /// J, arcmin^-2 (`null` when no table suffices).
    pub objective_arcmin: Option<f64>,
    /// The angular bounds, arcmin (`null` when no table suffices).
    pub bounds_arcmin: Option<ArcminBounds>,
    /// The rate tolerances (empty when no table suffices).
    pub tolerances: Vec<ToleranceJson>,
    /// Every output's worst case with the noise part (empty when no table suffices).
    pub outputs: Vec<NoisyAllocatedOutputJson<'a>>,
    /// The certified allocation with the noise part kept free, else `null`.
    pub certified: Option<CertifiedRateJson<'a>>,
    /// Why there is no certified allocation, else `null`.
    pub certified_note: Option<&'a str>,
}

/// The rule of the allocation with the rate tolerances and the noise part kept free.
#[must_use]
pub fn with_noise_rule(k_sigma: f64) -> String {
    format!(
        "every output's worst case over both boxes (linearised, and on the exact chain at its worst vertex) plus {} sigma of the noise (static positions and rate steps' windows) within its accuracy: the angles and the rate tolerances share what the noise leaves",
        num(k_sigma)
    )
}

impl<'a> RateWithNoiseJson<'a> {
    fn new(e2e: &'a EndToEnd, w: &'a RateWithNoise) -> Self {
        let acc = e2e.accuracies();
        let name = |k: usize| e2e.calibration().outputs()[k].output().name.as_str();
        let names = e2e.turntable().rotation_error_names();
        let (objective_arcmin, bounds_arcmin, tolerances, outputs, no_room) = match &w.allocation {
            Ok(a) => (
                Some(a.combined().objective_arcmin()),
                Some(arcmin_bounds(&names, a.angles_rad())),
                tolerances_json(e2e, a),
                a.worst_cases()
                    .iter()
                    .map(|c| {
                        let k = c.output();
                        let combined = c.exact_at_vertex() + w.noise.margin(k);
                        NoisyAllocatedOutputJson {
                            output: name(k),
                            accuracy: acc[k],
                            noise_part: w.noise.margin(k),
                            linear_bound: c.linear_bound(),
                            exact_at_vertex: c.exact_at_vertex(),
                            combined,
                            margin: acc[k] - combined,
                        }
                    })
                    .collect(),
                Vec::new(),
            ),
            Err(blocked) => (
                None,
                None,
                Vec::new(),
                Vec::new(),
                blocked
                    .iter()
                    .map(|b| RateNoRoomJson {
                        output: name(b.output()),
                        noise_part: b.noise_part(),
                        lower_bounds_part: b.lower_bounds_part(),
                    })
                    .collect(),
            ),
        };
        Self {
            rule: with_noise_rule(w.noise.k_sigma),
            k_sigma: w.noise.k_sigma,
            noise_sigma: &w.noise.sigma,
            no_table_suffices: w.allocation.is_err(),
            no_room,
            objective_arcmin,
            bounds_arcmin,
            tolerances,
            outputs,
            certified: w
                .certified
                .as_ref()
                .and_then(|c| c.as_ref().ok())
                .and_then(|c| CertifiedRateJson::new(e2e, c)),
            certified_note: w
                .certified
                .as_ref()
                .and_then(|c| c.as_ref().err())
                .map(String::as_str),
        }
    }
}

/// The rate tolerances of `a` with their weights, in the sheet's units.
fn tolerances_json(e2e: &EndToEnd, a: &RateAllocation) -> Vec<ToleranceJson> {
    e2e.rates()
        .rate_tolerance_names()
        .into_iter()
        .zip(a.tolerances())
        .zip(a.tolerance_bounds())
        .zip(a.weights())
        .map(|(((name, t), b), w)| {
            let (v, unit) = tolerance_in_sheet_units(t, *b);
            ToleranceJson {
                name,
                bound: b.is_finite().then_some(v),
                unit,
                weight_si_per_rad: Some(*w),
            }
        })
        .collect()
}

impl<'a> RateAllocationJson<'a> {
    /// The view of `r` for `e2e`.
    #[must_use]
    pub fn new(e2e: &'a EndToEnd, r: &'a RateAllocated) -> Self {
        let a = &r.allocation;
        let names = e2e.turntable().rotation_error_names();
        let acc = e2e.accuracies();
        Self {
            reading: e2e.reading().to_string(),
            objective_arcmin: a.combined().objective_arcmin(),
            bounds_arcmin: arcmin_bounds(&names, a.angles_rad()),
            tolerances: tolerances_json(e2e, a),
            outputs: a
                .worst_cases()
                .iter()
                .map(|w| AllocatedOutputJson {
                    output: &e2e.calibration().outputs()[w.output()].output().name,
                    accuracy: acc[w.output()],
                    linear_bound: w.linear_bound(),
                    exact_at_vertex: w.exact_at_vertex(),
                    entry: w.position(),
                    margin: acc[w.output()] - w.exact_at_vertex(),
                    second_order_room: a.combined().second_order_margins()[w.output()],
                })
                .collect(),
            exact_rounds: a.exact_rounds(),
            yield_fraction: r.count.fraction(),
            yield_interval_95: r.count.interval_95(),
            samples: r.count.samples(),
            max_drawn: &r.max_drawn,
            direct_note: e2e_verify::rate::NOT_CERTIFIED_AT_RATE_STEPS,
            certified: r
                .certified
                .as_ref()
                .ok()
                .and_then(|c| CertifiedRateJson::new(e2e, c)),
            certified_note: r.certified.as_ref().err().map(String::as_str),
            with_noise: r
                .with_noise
                .as_ref()
                .map(|w| RateWithNoiseJson::new(e2e, w)),
        }
    }
}
