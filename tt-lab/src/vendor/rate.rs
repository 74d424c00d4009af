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
use e2e_verify::{
    EndToEnd, ExtraError, ExtraOutputWorstCase, McSettings, RateAllocation, RateTolerance,
    ToleranceSheet,
};
use study::Study;

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
pub fn extra_bounds(e2e: &EndToEnd, sheet: &ToleranceSheet) -> Result<Vec<f64>, InputError> {
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
    /// Turntables of both boxes meeting every accuracy, of `samples`.
    pub meets: u64,
    /// Turntables drawn.
    pub samples: u64,
    /// The largest error drawn, per output.
    pub max_drawn: Vec<f64>,
}

impl RateCheck {
    /// Whether every output's worst case (linear and exact) is within its accuracy.
    #[must_use]
    pub fn meets_every_accuracy(&self, e2e: &EndToEnd) -> bool {
        self.outputs
            .iter()
            .zip(e2e.accuracies())
            .all(|(o, a)| o.linear_bound() <= a && o.exact_at_vertex() <= a)
    }
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
    let bounds = extra_bounds(e2e, sheet)?;
    let outputs = e2e
        .worst_case_with_extra(
            &e2e.linearization(),
            &e2e.extra_linearization(),
            sheet.upper_bounds_rad(),
            &bounds,
        )
        .map_err(|e| crate::error::library_at(e, s, sheet.source()))?;
    let (meets, max_drawn) = e2e
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
        meets,
        samples: settings.samples,
        max_drawn,
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
    /// The certified allocation ([`EndToEnd::allocate_direct_rate_certified`]), or why there
    /// is none.
    pub certified: std::result::Result<e2e_verify::CertifiedRateAllocation, String>,
    /// Turntables of both allocated boxes meeting every accuracy, of `samples`.
    pub meets: u64,
    /// Turntables drawn.
    pub samples: u64,
    /// The largest error drawn, per output.
    pub max_drawn: Vec<f64>,
}

/// The direct allocation of the angles and the rate tolerances together for a study with
/// rate steps, and its Monte Carlo over both boxes (`None` for a static study).
///
/// # Errors
/// A library error located in the study.
pub fn allocation(
    s: &Study,
    e2e: &EndToEnd,
    settings: &McSettings,
) -> Result<Option<RateAllocated>> {
    if !e2e.has_rate_steps() {
        return Ok(None);
    }
    let a = e2e
        .allocate_direct_rate(
            &e2e.linearization(),
            &e2e.extra_linearization(),
            &s.lower_bounds_rad,
        )
        .map_err(|e| crate::error::library(e, s))?;
    let extra = e2e.extra_bounds_of(a.tolerance_bounds());
    let (meets, max_drawn) = e2e
        .meeting_count_with_extra(a.angles_rad(), &s.lower_bounds_rad, &extra, settings)
        .map_err(|e| crate::error::library(e, s))?;
    let certified = match e2e.allocate_direct_rate_certified(
        &e2e.linearization(),
        &e2e.extra_linearization(),
        &s.lower_bounds_rad,
    ) {
        Ok(c) => Ok(c),
        Err(
            e @ (e2e_verify::E2eError::NoSecondOrderBound { .. }
            | e2e_verify::E2eError::NoConvergence { .. }),
        ) => Err(e.to_string()),
        Err(e) => return Err(crate::error::library(e, s)),
    };
    Ok(Some(RateAllocated {
        allocation: a,
        certified,
        meets,
        samples: settings.samples,
        max_drawn,
    }))
}

/// A rate error or translation bounded by the sheet (`extra_errors[]`), in the sheet's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExtraErrorJson {
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
pub struct ExtraPartJson {
    /// The error's name.
    pub error: String,
    /// Its part, output's unit.
    pub part: f64,
}

/// One output's worst case over both boxes, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateOutputJson<'a> {
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
    pub extra_parts: Vec<ExtraPartJson>,
    /// The worst schedule entry (index).
    pub entry: usize,
    /// The exact chain at the worst vertex, output's unit.
    pub exact_at_vertex: f64,
    /// Whether both are within the accuracy.
    pub meets: bool,
}

/// The check with the errors only rotation exposes (`rate_steps[]`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateCheckJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// The sheet's rate errors and translations.
    pub extra_errors: Vec<ExtraErrorJson>,
    /// Every output's worst case.
    pub outputs: Vec<RateOutputJson<'a>>,
    /// Monte Carlo yield over both boxes, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// Largest error of each output over the draws, output's unit.
    pub max_drawn: &'a [f64],
    /// `meets` or `does not meet`.
    pub verdict: &'static str,
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
                    meets: o.linear_bound() <= acc[o.output()]
                        && o.exact_at_vertex() <= acc[o.output()],
                })
                .collect(),
            yield_fraction: c.meets as f64 / c.samples as f64,
            yield_interval_95: e2e_verify::wilson_interval_95(c.meets, c.samples),
            samples: c.samples,
            max_drawn: &c.max_drawn,
            verdict: if c.meets_every_accuracy(e2e) {
                "meets"
            } else {
                "does not meet"
            },
        }
    }
}

/// A rate tolerance allocated (`tolerances[]`), in the sheet's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ToleranceJson {
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
pub struct CertifiedOutputJson<'a> {
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
pub struct CertifiedRateJson<'a> {
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
    fn new(e2e: &'a EndToEnd, c: &e2e_verify::CertifiedRateAllocation) -> Self {
        let names = e2e.turntable().rotation_error_names();
        let acc = e2e.accuracies();
        Self {
            objective_arcmin: c.combined().objective_arcmin(),
            bounds_arcmin: arcmin_bounds(&names, c.angles_rad()),
            tolerances: e2e
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
                    linear_bound: c.linear_bounds()[k],
                    second_order_bound: c.second_order_bounds()[k],
                    certified_bound: c.certified_bound(k),
                })
                .collect(),
            rounds: c.rounds(),
        }
    }
}

/// One output of the allocation with the rate tolerances, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AllocatedOutputJson<'a> {
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
    pub tolerances: Vec<ToleranceJson>,
    /// Every output's worst case.
    pub outputs: Vec<AllocatedOutputJson<'a>>,
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
    pub certified: Option<CertifiedRateJson<'a>>,
    /// Why there is no certified allocation, else `null`.
    pub certified_note: Option<&'a str>,
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
            tolerances: e2e
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
                .collect(),
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
            yield_fraction: r.meets as f64 / r.samples as f64,
            yield_interval_95: e2e_verify::wilson_interval_95(r.meets, r.samples),
            samples: r.samples,
            max_drawn: &r.max_drawn,
            direct_note: e2e_verify::rate::NOT_CERTIFIED_AT_RATE_STEPS,
            certified: r
                .certified
                .as_ref()
                .ok()
                .map(|c| CertifiedRateJson::new(e2e, c)),
            certified_note: r.certified.as_ref().err().map(String::as_str),
        }
    }
}
