//! The allocation when the study's errors vary with the shaft angle (issue 22 item 1 in
//! `end-to-end`, `allocate` and `report`): the direct and the certified allocation of the
//! angle-dependent model (each error bounded over the whole revolution), beside the constant
//! model's direct allocation with the same readings.
//!
//! The angle model's first-order matrix is e2e-verify's reduced linearisation
//! ([`e2e_verify::angle::AngleLinearization::reduced`]: each error's dual norm in place of
//! $\lvert M_{rj}\rvert$), which the direct and the certified allocation take unchanged; the
//! second-order bound stays rigorous (it bounds each position's rotation). A study without
//! `varies` gets nothing from here (its answers are today's).
//!
//! With measured errors (`[[compensation.measured]]`) every reading also gets the allocation
//! after compensation: the measured errors held at their uncertainty, the unmeasured ones
//! allocated what remains ([`e2e_verify::AngleQuestions::allocate_direct_compensated`]).
//!
//! JSON (`angle_dependent`): `model` (`{error: "constant" | "harmonics [1, 2] of phi1" | "any
//! of phi1"}`), `readings` (`[{"reading", "constant_direct_objective_arcmin", "direct":
//! {"objective_arcmin", "upper_bounds_arcmin"}, "certified": {...} | null, "certified_note",
//! "unmeasured_before_objective_arcmin", "compensated": {...} | {"no_room"} | null}]`).

use crate::Result;
use calib_lsq::Reading;
use e2e_verify::{DirectAllocation, EndToEnd};
use std::collections::BTreeMap;
use study::Study;
use tt_kinematics::ErrorVariation;

/// One reading's allocations under the angle-dependent model.
#[derive(Debug, Clone)]
pub struct ReadingAngleAllocation {
    /// The reading.
    pub reading: Reading,
    /// The constant model's direct allocation (same reading, same lower bounds).
    pub constant_direct: DirectAllocation,
    /// The direct allocation under the angle model.
    pub direct: DirectAllocation,
    /// The certified direct allocation under the angle model, or why there is none.
    pub certified: std::result::Result<DirectAllocation, String>,
    /// With the study's measured errors compensated (`[[compensation.measured]]`): the direct
    /// allocation of the unmeasured errors with the measured ones held at their uncertainty
    /// (same model), or why the measured errors alone leave no room; `None` without
    /// measurements.
    pub compensated: Option<std::result::Result<DirectAllocation, String>>,
    /// The objective of the unmeasured errors' bounds before compensation (arcmin^-2; the
    /// direct allocation's bounds of those errors), to compare with `compensated`'s.
    pub unmeasured_before_arcmin: Option<f64>,
}

/// The angle-dependent allocations of a study (the study's reading, then the user's).
#[derive(Debug, Clone)]
pub struct AngleAllocations {
    /// Each error's model (order of chi).
    pub variations: Vec<ErrorVariation>,
    /// Whether the study declares an error that varies with a shaft angle (else only the
    /// compensation is shown).
    pub varies: bool,
    /// Per reading.
    pub readings: Vec<ReadingAngleAllocation>,
}

/// The allocations under the study's angle-dependent model and with its measured errors
/// compensated, `None` when the study declares neither an error that varies with a shaft angle
/// nor a measurement.
///
/// # Errors
/// A library error located in the study.
pub fn compute(s: &Study, e2e: &EndToEnd) -> Result<Option<AngleAllocations>> {
    let varies = s.has_angle_dependent_errors();
    let measured: Vec<Option<f64>> = s
        .measured
        .iter()
        .map(|m| m.as_ref().map(|m| m.uncertainty_rad))
        .collect();
    if !varies && measured.iter().all(Option::is_none) {
        return Ok(None);
    }
    let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != Reading::USER {
        sims.push(e2e.with_reading(Reading::USER).map_err(lib)?);
    }
    let mut readings = Vec::with_capacity(sims.len());
    for sim in &sims {
        let ex = crate::vendor::angle::expansion(s, sim, &s.variations)?;
        let al = sim.angle().angle_linearization(&ex).map_err(lib)?;
        let lb = &s.lower_bounds_rad;
        let constant_direct = sim.allocate_direct(&sim.linearization(), lb).map_err(lib)?;
        let direct = sim.allocate_direct(&al.reduced, lb).map_err(lib)?;
        let certified = if direct.no_bound_needed() {
            Err("no bound is needed".to_string())
        } else {
            match sim.allocate_direct_certified(&al.reduced, lb) {
                Ok(d) => Ok(d),
                Err(
                    e @ (e2e_verify::E2eError::NoSecondOrderBound { .. }
                    | e2e_verify::E2eError::NoConvergence { .. }
                    | e2e_verify::E2eError::MarginExceedsAccuracy { .. }),
                ) => Err(e.to_string()),
                Err(e) => return Err(lib(e)),
            }
        };
        let compensated = if measured.iter().all(Option::is_none) {
            None
        } else {
            Some(
                sim.angle()
                    .allocate_direct_compensated(&al.reduced, lb, &measured)
                    .map_err(lib)?
                    .map_err(|blocked| {
                        format!(
                            "the measured errors' uncertainty alone leaves no room for output{} {}",
                            if blocked.len() > 1 { "s" } else { "" },
                            blocked
                                .iter()
                                .map(|b| sim.calibration().outputs()[b.output()]
                                    .output()
                                    .name
                                    .clone())
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    }),
            )
        };
        let unmeasured_before_arcmin = compensated.is_some().then(|| {
            let ub: Vec<f64> = direct
                .upper_bounds_rad()
                .iter()
                .zip(&measured)
                .map(|(u, m)| if m.is_some() { f64::INFINITY } else { *u })
                .collect();
            tt_core::units::objective_to_arcmin(sim.objective(&ub))
        });
        readings.push(ReadingAngleAllocation {
            unmeasured_before_arcmin,
            reading: sim.reading(),
            constant_direct,
            direct,
            certified,
            compensated,
        });
    }
    Ok(Some(AngleAllocations {
        varies,
        variations: s.variations.clone(),
        readings,
    }))
}

/// J (arcmin^-2) of `d`, `None` when no error needs a bound.
pub fn objective(d: &DirectAllocation) -> Option<f64> {
    (!d.no_bound_needed()).then(|| d.objective_arcmin())
}

/// A model in words: `constant`, `harmonics [1, 2] of phi1`, `any of phi1`.
#[must_use]
pub fn model_name(v: &ErrorVariation) -> String {
    match v {
        ErrorVariation::Constant => "constant".into(),
        ErrorVariation::Harmonics { joint, orders } => format!("harmonics {orders:?} of {joint}"),
        ErrorVariation::Any { joint } => format!("any of {joint}"),
    }
}

/// The allocation after compensation: the allocation, or why there is no room.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub(crate) enum CompensatedJson<'a> {
    /// The unmeasured errors' allocation.
    Allocated(crate::vendor::angle::AllocationJson),
    /// The measured errors' uncertainty leaves no room.
    NoRoom {
        /// Why, in words.
        no_room: &'a str,
    },
}

/// One reading of `angle_dependent`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AngleReadingJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// J of the constant model's direct allocation, arcmin^-2 (`null`: no bound needed).
    pub constant_direct_objective_arcmin: Option<f64>,
    /// The direct allocation under the study's model.
    pub direct: crate::vendor::angle::AllocationJson,
    /// The certified allocation under it, `null` when there is none (`certified_note`).
    pub certified: Option<crate::vendor::angle::AllocationJson>,
    /// Why there is no certified allocation, else `null`.
    pub certified_note: Option<&'a str>,
    /// With measured errors: J of the unmeasured errors before compensation, arcmin^-2.
    pub unmeasured_before_objective_arcmin: Option<f64>,
    /// With measured errors: the allocation after compensation, else `null`.
    pub compensated: Option<CompensatedJson<'a>>,
}

/// The JSON value of `angle_dependent` (see the [module](self)).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AngleDependentJson<'a> {
    /// Each error's model in words (`constant`, `harmonics [1, 2] of phi1`, `any of phi1`).
    pub model: BTreeMap<String, String>,
    /// Per reading.
    pub(crate) readings: Vec<AngleReadingJson<'a>>,
}

impl<'a> AngleDependentJson<'a> {
    /// The view of `a` for the table of `e2e`.
    #[must_use]
    pub fn new(e2e: &EndToEnd, a: &'a AngleAllocations) -> Self {
        let names = e2e.turntable().rotation_error_names();
        Self {
            model: names
                .iter()
                .zip(&a.variations)
                .map(|(n, v)| ((*n).to_string(), model_name(v)))
                .collect(),
            readings: a
                .readings
                .iter()
                .map(|r| AngleReadingJson {
                    reading: r.reading.to_string(),
                    constant_direct_objective_arcmin: objective(&r.constant_direct),
                    direct: crate::vendor::angle::AllocationJson::new(&names, &r.direct),
                    certified: r
                        .certified
                        .as_ref()
                        .ok()
                        .map(|d| crate::vendor::angle::AllocationJson::new(&names, d)),
                    certified_note: r.certified.as_ref().err().map(String::as_str),
                    unmeasured_before_objective_arcmin: r.unmeasured_before_arcmin,
                    compensated: r.compensated.as_ref().map(|c| match c {
                        Ok(d) => CompensatedJson::Allocated(
                            crate::vendor::angle::AllocationJson::new(&names, d),
                        ),
                        Err(why) => CompensatedJson::NoRoom { no_room: why },
                    }),
                })
                .collect(),
        }
    }
}

/// A sheet's path as given and its allocations per reading ([`sheet`]).
pub(crate) type SheetAllocations = (
    String,
    Vec<(EndToEnd, crate::vendor::angle::DiscAllocation)>,
);

/// The allocations with one tolerance per pair of the vendor sheet at `path` (`--tolerances`
/// of `allocate` and `end-to-end`, [`crate::vendor::angle::sheet_allocations`]), with the path as
/// given; `None` without a sheet.
///
/// # Errors
/// [`crate::InputError`] for a bad sheet (exit 2 naming the key); a library error located in
/// the study.
pub fn sheet(s: &Study, path: Option<&std::path::Path>) -> Result<Option<SheetAllocations>> {
    let Some(path) = path else {
        return Ok(None);
    };
    let sheet = s.load_sheet(path).map_err(crate::InputError::from)?;
    let e2e = crate::loaded::simulator(s)?;
    let al = crate::vendor::angle::sheet_allocations(s, &e2e, &sheet)?;
    Ok(Some((sheet.source().to_string(), al)))
}
