//! Which table errors the calibration can estimate itself ([`estimable`], the command line's
//! `estimable`; issue 22 item 4).
//!
//! A joint least squares of the sensor coefficients and the turntable's angular errors from
//! the same schedule data, with the outputs simulated at the actual orientation (the user's
//! reading of eq 13, whatever the study's reading: under the paper's the outputs carry no
//! trace of the table). It prints the rank of the joint Jacobian (SVD, relative tolerance
//! [`calib_lsq::joint::JOINT_RANK_RTOL`] of the largest raw effect, rows weighted by
//! 1/accuracy), the estimable and the invisible combinations in the errors' names, each
//! error's status, the direct allocation (user's reading, first order) before and after the
//! estimable combinations are estimated, and at the worst turntable of a box (the sheet given
//! by `--tolerances`, else that direct allocation's box) every output's rate error with the
//! ordinary calibration and with the joint estimator (Gauss-Newton on the exact chain from
//! noiseless outputs).
//!
//! When the study's errors vary with a shaft angle (`turntable.factors[i].varies`), every
//! answer is of the study's model, as `end-to-end` allocates it: the joint parameters are the
//! coefficients of each error's expansion (`dphi_y1.c0`, `dphi_y1.a1`, `dphi_y1.b1`, ...), the
//! allocations bound each error over the whole revolution and the box's worst turntable is the
//! model's worst coefficients; the text names the model.
//!
//! JSON: `reading`, `model` (`{error: "constant" | "harmonics [1, 2] of phi1" | ...}`),
//! `parameters` (`errors` or `coefficients`: what `errors` and the combinations name), `rank`, `columns`, `coefficients`, `table_rank`, `rank_rtol`,
//! `singular_values_relative`, `estimable` and `invisible` (`[{"combination", "terms":
//! {error: coefficient}}]`), `errors` (`[{"name", "status"}]`, status `alone`, `combined` or
//! `invisible`), `allocation` (`ordinary` and `joint`: `objective_arcmin` (`null` when no
//! bound is needed), `upper_bounds_arcmin` (`null` = no bound needed), `no_bound_needed`),
//! `box` (`source`: `tolerances` or `direct-allocation`; `outputs`: `[{"name", "unit",
//! "accuracy", "ordinary", "joint"}]`).

use crate::InputError;
use crate::Result;
use crate::json::{ArcminBounds, arcmin_bounds};
use calib_lsq::Reading;
use calib_lsq::joint::{Combination, JOINT_RANK_RTOL, JointEstimability};
use e2e_verify::{DirectAllocation, EndToEnd};
use std::collections::BTreeMap;
use study::Study;
use tt_kinematics::{ErrorVariation, Expansion};

/// Gauss-Newton steps of the joint estimator at the box's worst turntable (it converges
/// quadratically: 1e-4 rad to rounding in about four).
pub const JOINT_ITERATIONS: usize = 10;

/// Every output's rate error at a box's worst turntable (the ordinary calibration's worst
/// vertex of that output), ordinary and joint.
#[derive(Debug, Clone)]
pub struct BoxRates {
    /// `tolerances` or `direct-allocation`.
    pub source: &'static str,
    /// Per output: (ordinary, joint), output unit.
    pub rates: Vec<(f64, f64)>,
}

/// The joint-estimation answer of a study.
#[derive(Debug, Clone)]
pub struct Estimable {
    /// The user's-reading simulator.
    pub e2e: EndToEnd,
    /// The study's model of errors that vary with a shaft angle (`turntable.factors[i].varies`),
    /// `None` when every error is constant: the joint parameters are then its coefficients
    /// and every allocation and worst case is of that model.
    pub model: Option<Vec<ErrorVariation>>,
    /// The estimability (parameters: the errors, or the model's coefficients).
    pub est: JointEstimability,
    /// The direct allocation, ordinary calibration.
    pub ordinary: DirectAllocation,
    /// The direct allocation when the estimable combinations are estimated.
    pub joint: DirectAllocation,
    /// The rate errors at a box's worst turntable.
    pub at_box: BoxRates,
}

/// Compute the answer for a study (`ub_rad`: a sheet's bounds, if given).
///
/// # Errors
/// An [`InputError`] naming the study for what its data make impossible (infeasible lower
/// bounds); a library failure otherwise.
pub fn compute(s: &Study, ub_rad: Option<&[f64]>) -> Result<Estimable> {
    if s.has_rate_steps() {
        return Err(InputError::new(
            format!("{}: key `calibration.rate_steps`", s.path),
            format!(
                "the study has {} rate step{}, and the joint estimation of table errors takes static positions only: ask it of a copy of the study without `[[calibration.rate_steps]]`",
                s.rate_steps.len(),
                if s.rate_steps.len() == 1 { "" } else { "s" }
            ),
        )
        .into());
    }
    let e2e = crate::loaded::simulator(s)?
        .with_reading(Reading::USER)
        .map_err(|e| crate::error::library(e, s))?;
    if s.has_angle_dependent_errors() {
        return compute_angle(s, e2e, ub_rad);
    }
    let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
    let est = e2e.estimable().estimability().map_err(lib)?;
    let ordinary = e2e
        .allocate_direct(&e2e.linearization(), &s.lower_bounds_rad)
        .map_err(lib)?;
    let lj = e2e.estimable().linearization_joint(&est).map_err(lib)?;
    let joint = e2e.allocate_direct(&lj, &s.lower_bounds_rad).map_err(lib)?;
    let ub = box_of(ub_rad, &ordinary);
    let wc = e2e.worst_case(&e2e.linearization(), &ub.1).map_err(lib)?;
    let rates = wc
        .outputs()
        .iter()
        .map(|o| {
            let plain = e2e.delta_omega(o.worst_chi_rad())?[o.output()];
            let joint =
                e2e.estimable()
                    .joint_delta_omega(o.worst_chi_rad(), &est, JOINT_ITERATIONS)?[o.output()];
            Ok((plain, joint))
        })
        .collect::<Result<Vec<_>, e2e_verify::E2eError>>()
        .map_err(lib)?;
    finish(e2e, None, est, ordinary, joint, ub.0, rates)
}

/// The box whose worst turntable is calibrated both ways: the sheet's, else the ordinary
/// direct allocation's.
fn box_of(ub_rad: Option<&[f64]>, ordinary: &DirectAllocation) -> (&'static str, Vec<f64>) {
    match ub_rad {
        Some(u) => ("tolerances", u.to_vec()),
        None => ("direct-allocation", ordinary.upper_bounds_rad().to_vec()),
    }
}

fn finish(
    e2e: EndToEnd,
    model: Option<Vec<ErrorVariation>>,
    est: JointEstimability,
    ordinary: DirectAllocation,
    joint: DirectAllocation,
    source: &'static str,
    rates: Vec<(f64, f64)>,
) -> Result<Estimable> {
    for (p, j) in &rates {
        if !(p.is_finite() && j.is_finite()) {
            return Err(crate::LabError::Library(
                "the joint estimator gave a non-finite rate error".into(),
            ));
        }
    }
    Ok(Estimable {
        e2e,
        model,
        est,
        ordinary,
        joint,
        at_box: BoxRates { source, rates },
    })
}

/// [`compute`] under the study's angle-dependent model: the joint parameters are the
/// coefficients of its expansion (each error's constant and harmonic coefficients, or its
/// value at each angle of the schedule), the allocations are of that model (each error bounded
/// over the whole revolution, as `end-to-end` allocates it) and the box's worst turntable is
/// the model's worst coefficients.
fn compute_angle(s: &Study, e2e: EndToEnd, ub_rad: Option<&[f64]>) -> Result<Estimable> {
    let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
    let ex = Expansion::new(e2e.turntable(), &s.variations, e2e.poses())
        .map_err(|e| crate::error::library(e, s))?;
    let est = e2e.estimable().estimability_expanded(&ex).map_err(lib)?;
    let al = e2e.angle().angle_linearization(&ex).map_err(lib)?;
    let lb = &s.lower_bounds_rad;
    let ordinary = e2e.allocate_direct(&al.reduced, lb).map_err(lib)?;
    let lj = e2e
        .estimable()
        .linearization_joint_expanded(&ex, &est)
        .map_err(lib)?;
    let joint = e2e.allocate_direct(&lj.reduced, lb).map_err(lib)?;
    let ub = box_of(ub_rad, &ordinary);
    let wc = e2e
        .angle()
        .angle_worst_case(&ex, &al, &e2e.linearization(), &ub.1)
        .map_err(lib)?;
    let rates = wc
        .iter()
        .map(|o| {
            let joint = e2e.estimable().joint_delta_omega_expanded(
                &ex,
                o.worst_coefficients(),
                &est,
                JOINT_ITERATIONS,
            )?[o.output()];
            Ok((o.exact_at_vertex(), joint))
        })
        .collect::<Result<Vec<_>, e2e_verify::E2eError>>()
        .map_err(lib)?;
    finish(
        e2e,
        Some(s.variations.clone()),
        est,
        ordinary,
        joint,
        ub.0,
        rates,
    )
}

/// A combination of errors, in words and by term.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CombinationJson {
    /// In words (`0.71 dphi_y1 - 0.71 deps_y`).
    pub combination: String,
    /// Each error's coefficient (dimensionless).
    pub terms: BTreeMap<String, f64>,
}

impl From<&Combination> for CombinationJson {
    fn from(c: &Combination) -> Self {
        Self {
            combination: c.to_string(),
            terms: c.terms.iter().cloned().collect(),
        }
    }
}

/// A direct allocation (first order).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AllocationJson {
    /// J, arcmin^-2; `null` when no error needs a bound.
    pub objective_arcmin: Option<f64>,
    /// Its bounds, arcmin.
    pub upper_bounds_arcmin: ArcminBounds,
    /// Whether no error needs a bound.
    pub no_bound_needed: bool,
}

impl AllocationJson {
    fn new(names: &[&str], d: &DirectAllocation) -> Self {
        Self {
            objective_arcmin: (!d.no_bound_needed()).then(|| d.objective_arcmin()),
            upper_bounds_arcmin: arcmin_bounds(names, d.upper_bounds_rad()),
            no_bound_needed: d.no_bound_needed(),
        }
    }
}

/// The direct allocation with the ordinary calibration and with the estimable combinations
/// estimated.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AllocationsJson {
    /// With the ordinary calibration.
    pub ordinary: AllocationJson,
    /// With the joint estimator.
    pub joint: AllocationJson,
}

/// One error's status.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ErrorStatusJson<'a> {
    /// The error's name.
    pub name: &'a str,
    /// `alone`, `combined` or `invisible`.
    pub status: &'static str,
}

/// One output's rate error at the box's worst turntable, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct BoxOutputJson<'a> {
    /// The output's name.
    pub name: &'a str,
    /// Its unit (the study's).
    pub unit: &'a str,
    /// Its accuracy, output's unit.
    pub accuracy: f64,
    /// With the ordinary calibration, output's unit.
    pub ordinary: f64,
    /// With the joint estimator, output's unit.
    pub joint: f64,
}

/// The worst turntable's rate errors.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct BoxJson<'a> {
    /// `tolerances` or `direct-allocation`: whose box.
    pub source: &'static str,
    /// Every output's rate error.
    pub outputs: Vec<BoxOutputJson<'a>>,
}

/// `estimable --json` (see the [module](self)).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct EstimableJson<'a> {
    /// The study's path.
    pub study: &'a str,
    /// The reading (the user's: outputs at the actual orientation).
    pub reading: String,
    /// Each error's model in words (`constant`, `harmonics [1, 2] of phi1`, `any of phi1`):
    /// the study's; every answer below is of that model.
    pub model: BTreeMap<String, String>,
    /// `errors` (every error constant: one parameter per error) or `coefficients` (the
    /// study's angle-dependent model: the parameters are its coefficients, named
    /// `error.c0`, `error.a1`, `error.b1`, ...).
    pub parameters: &'static str,
    /// The joint Jacobian's rank.
    pub rank: usize,
    /// Its columns (coefficients and table errors).
    pub columns: usize,
    /// The sensor coefficients.
    pub coefficients: usize,
    /// The rank the table's errors add.
    pub table_rank: usize,
    /// The relative tolerance of the rank.
    pub rank_rtol: f64,
    /// The singular values relative to the largest raw effect.
    pub singular_values_relative: Vec<f64>,
    /// The estimable combinations.
    pub(crate) estimable: Vec<CombinationJson>,
    /// The invisible combinations.
    pub(crate) invisible: Vec<CombinationJson>,
    /// Every parameter's status (each error's, or each coefficient's of the study's
    /// angle-dependent model).
    pub(crate) errors: Vec<ErrorStatusJson<'a>>,
    /// The direct allocations.
    pub(crate) allocation: AllocationsJson,
    /// The worst turntable's rate errors.
    #[cfg_attr(feature = "serde", serde(rename = "box"))]
    pub(crate) at_box: BoxJson<'a>,
}

/// The answer's view (see the [module](self)).
#[must_use]
pub fn to_json<'a>(s: &'a Study, a: &'a Estimable) -> EstimableJson<'a> {
    let names = a.e2e.turntable().rotation_error_names();
    let reference = a.est.reference();
    EstimableJson {
        study: &s.path,
        reading: Reading::USER.to_string(),
        model: names
            .iter()
            .zip(&s.variations)
            .map(|(n, v)| ((*n).to_string(), crate::allocation::angle::model_name(v)))
            .collect(),
        parameters: if a.model.is_some() {
            "coefficients"
        } else {
            "errors"
        },
        rank: a.est.rank(),
        columns: a.est.columns(),
        coefficients: a.est.coefficients(),
        table_rank: a.est.table_rank(),
        rank_rtol: JOINT_RANK_RTOL,
        singular_values_relative: a
            .est
            .singular_values()
            .iter()
            .map(|v| if reference > 0.0 { v / reference } else { 0.0 })
            .collect(),
        estimable: a
            .est
            .estimable_combinations()
            .iter()
            .map(CombinationJson::from)
            .collect(),
        invisible: a
            .est
            .invisible_combinations()
            .iter()
            .map(CombinationJson::from)
            .collect(),
        errors: a
            .est
            .names()
            .iter()
            .zip(a.est.identifiability())
            .map(|(n, st)| ErrorStatusJson {
                name: n,
                status: st.name(),
            })
            .collect(),
        allocation: AllocationsJson {
            ordinary: AllocationJson::new(&names, &a.ordinary),
            joint: AllocationJson::new(&names, &a.joint),
        },
        at_box: BoxJson {
            source: a.at_box.source,
            outputs: a
                .e2e
                .calibration()
                .outputs()
                .iter()
                .zip(&a.at_box.rates)
                .map(|(oc, (p, j))| {
                    let o = oc.output();
                    BoxOutputJson {
                        name: &o.name,
                        unit: &o.unit,
                        accuracy: o.accuracy,
                        ordinary: *p,
                        joint: *j,
                    }
                })
                .collect(),
        },
    }
}

/// The options of [`estimable`]: a vendor's tolerances whose worst turntable is calibrated
/// both ways (default: the direct allocation's box under the user's reading).
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// A vendor sheet.
    pub tolerances: Option<std::path::PathBuf>,
}

/// Which table errors does the calibration estimate itself, and what is left to allocate?
///
/// # Errors
/// An [`InputError`] naming the sheet or the study; a library failure otherwise.
pub fn estimable(s: &Study, o: &Options) -> Result<Estimable> {
    let tol = o
        .tolerances
        .as_ref()
        .map(|p| s.load_sheet(p).map_err(InputError::from))
        .transpose()?;
    compute(
        s,
        tol.as_ref()
            .map(e2e_verify::ToleranceSheet::upper_bounds_rad),
    )
}

/// The study's error model in words when it is not every error constant: `the study's
/// angle-dependent model (dphi_y1 harmonics [1, 2] of phi1, ..., deps_x constant)`.
#[must_use]
pub fn model_words(a: &Estimable) -> Option<String> {
    let model = a.model.as_ref()?;
    let names = a.e2e.turntable().rotation_error_names();
    let each: Vec<String> = names
        .iter()
        .zip(model)
        .map(|(n, v)| format!("{n} {}", crate::allocation::angle::model_name(v)))
        .collect();
    Some(format!(
        "the study's angle-dependent model ({}; each error bounded over the whole revolution): the joint parameters are its {} coefficients (c0 the constant, a_k and b_k the order-k cosine and sine)",
        each.join(", "),
        a.est.names().len()
    ))
}
