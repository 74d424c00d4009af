//! The allocation of a study's tolerances ([`allocate_study`], the command line's
//! `allocate`): the two-step turntable error allocation (paper §4.2-4.3, problems
//! 31-34) for the study's turntable and requirement, beside the equal-effects allocation (and
//! the paper's Table 4 when the study's turntable is the paper's).
//!
//! `--json` prints one object with at least `requirement_deg {psi, theta, gamma}`,
//! `allocation_arcmin` (keyed by error name; null for an error no constrained angle depends
//! on), `objective` ($J = J_\psi + J_\theta + J_\gamma$ with the bounds in arcmin, unit
//! arcmin$^{-2}$, the paper's weights) and `certificate` (per angle: worst case found, rigorous
//! upper bound, worst pose, share, Lemma 1), plus the equal-effects allocation, the exact-chain
//! check, `groups` (errors that act only together, with the bound of their combination under
//! each allocation) and, for the paper's table, `paper_table4_arcmin` and
//! `paper_table4_objective`.
//!
//! For a study with rate steps the two-step allocation is not made (the orientation
//! requirement is a static concept): the text says so and gives the direct allocation with
//! the rate tolerances (JSON `rate_allocation`, beside `two_step_allocation` saying why the
//! two-step keys are absent) as the answer.

use crate::InputError;
use crate::Result;
use crate::json::{ArcminBounds, GroupJson, PerAngle, arcmin_bounds};
use crate::loaded as st;
use alloc_opt::{
    Allocation, AllocationProblem, Allocator, Certificate, ConstraintForm, EqualEffects,
    SensitivityWeighted, exact_chain_check,
};
use e2e_verify::EndToEnd;
use std::collections::BTreeMap;
use study::Study;
use tt_core::units::rad_to_deg;
use tt_kinematics::LinearModel;

pub mod angle;
pub mod spec;

pub use crate::vendor::rate::{RateAllocated, allocation as rate_allocation};

/// One angle's Lemma 1 certificate, degrees.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AxisCertificateJson {
    /// The requirement, degrees (`null`: none).
    pub requirement_deg: Option<f64>,
    /// The largest worst case found, degrees.
    pub worst_case_deg: f64,
    /// A rigorous upper bound on it, degrees.
    pub upper_bound_deg: f64,
    /// Whether the worst case is exact (at most one free joint).
    pub exact_search: bool,
    /// A pose where it is reached, keyed by joint, degrees.
    pub worst_pose_deg: BTreeMap<String, f64>,
    /// `worst_case / requirement` (`null` without a requirement).
    pub share: Option<f64>,
    /// Whether the requirement is active.
    pub requirement_active: bool,
    /// Whether Lemma 1 holds for this angle.
    pub lemma1: bool,
}

fn certificate_json(s: &Study, c: &Certificate) -> PerAngle<AxisCertificateJson> {
    let joints = s.turntable.joint_names();
    PerAngle::new(|a| {
        let x = c.get(a);
        AxisCertificateJson {
            requirement_deg: x.requirement_rad().map(rad_to_deg),
            worst_case_deg: rad_to_deg(x.worst_case_rad()),
            upper_bound_deg: rad_to_deg(x.upper_bound_rad()),
            exact_search: x.exact(),
            worst_pose_deg: joints
                .iter()
                .zip(x.worst_pose_rad())
                .map(|(j, v)| ((*j).to_string(), rad_to_deg(*v)))
                .collect(),
            share: x.share(),
            requirement_active: x.requirement_active(),
            lemma1: x.satisfied(),
        }
    })
}

/// The allocations of a study.
#[derive(Debug, Clone)]
pub struct Allocations {
    /// The problem.
    pub problem: AllocationProblem,
    /// The sensitivity-weighted (paper's method) allocation.
    pub ours: Allocation,
    /// The equal-effects allocation.
    pub equal: Allocation,
    /// Table 4 with its certificate and objective (arcmin^-2), for the paper's table.
    pub table4: Option<(Vec<f64>, Certificate, f64)>,
}

/// Allocate for a study.
///
/// # Errors
/// An [`InputError`] naming the key or flag, or a solver error.
pub fn allocate(s: &Study, form: ConstraintForm, safety_margin: f64) -> Result<Allocations> {
    let req = st::requirement(s)?.used.ok_or_else(|| {
        InputError::new(
            format!("{}: key `requirement`", s.path),
            "the study has no orientation requirement: no output constrains a constant orientation error (see `requirement`); give one in [requirement] or use `end-to-end`, which allocates against the outputs' accuracies directly",
        )
    })?;
    let problem = AllocationProblem::new(
        LinearModel::new(&s.turntable),
        req,
        s.lower_bounds_rad.clone(),
    )
    .map_err(|e| crate::error::library(e, s))?
    .with_safety_margin(safety_margin)
    .map_err(|e| crate::error::library(e, s))?;
    let allocator = SensitivityWeighted {
        form,
        ..SensitivityWeighted::paper()
    };
    let ours = allocator
        .allocate(&problem)
        .map_err(|e| crate::error::library(e, s))?;
    let equal = EqualEffects
        .allocate(&problem)
        .map_err(|e| crate::error::library(e, s))?;
    let table4 = paper_table4(s, &problem)?;
    Ok(Allocations {
        problem,
        ours,
        equal,
        table4,
    })
}

/// The paper's Table 4 with its certificate and objective (arcmin^-2) when the study's table
/// is the paper's (the `paper` feature).
#[cfg(feature = "paper")]
fn paper_table4(
    s: &Study,
    problem: &AllocationProblem,
) -> Result<Option<(Vec<f64>, Certificate, f64)>> {
    Ok(if s.turntable == tt_kinematics::paper::table3() {
        let t = alloc_opt::paper::table4_rad();
        let cert = Certificate::compute(
            problem.model(),
            problem.limits(),
            problem.lower_bounds_rad(),
            &t,
        )
        .map_err(|e| crate::error::library(e, s))?;
        let j = alloc_opt::Weights::inverse_average_sensitivity(problem.model()).objective(&t)
            * tt_core::units::RAD_PER_ARCMIN
            * tt_core::units::RAD_PER_ARCMIN;
        Some((t, cert, j))
    } else {
        None
    })
}

/// Without the paper compiled in, no table is the paper's.
#[cfg(not(feature = "paper"))]
fn paper_table4(
    _s: &Study,
    _problem: &AllocationProblem,
) -> Result<Option<(Vec<f64>, Certificate, f64)>> {
    Ok(None)
}

/// `allocate --json`: the two-step allocation with its certificate.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AllocateJson<'a> {
    /// The study's path.
    pub study: &'a str,
    /// The orientation requirement per angle, degrees (`null`: none).
    pub requirement_deg: PerAngle<Option<f64>>,
    /// The errors' lower bounds, arcmin.
    pub lower_bounds_arcmin: ArcminBounds,
    /// `paper` or `full-range`.
    pub constraint_form: &'static str,
    /// The safety margin, in [0, 1).
    pub safety_margin: f64,
    /// The sensitivity-weighted allocation's bounds, arcmin.
    pub allocation_arcmin: ArcminBounds,
    /// The errors no angle constrains.
    pub unconstrained: Vec<&'a str>,
    /// J of the allocation, arcmin^-2 (`objective_unit`).
    pub objective: f64,
    /// J's unit and definition, in words.
    pub objective_unit: &'static str,
    /// Lemma 1's certificate per angle.
    pub(crate) certificate: PerAngle<AxisCertificateJson>,
    /// Whether Lemma 1 holds over the full range.
    pub lemma1_full_range: bool,
    /// The equal-effects allocation's bounds, arcmin.
    pub equal_effects_arcmin: ArcminBounds,
    /// Its J, arcmin^-2.
    pub equal_effects_objective: f64,
    /// The exact chain's worst case per angle, degrees.
    pub exact_chain_worst_deg: PerAngle<f64>,
    /// By how much the exact chain exceeds the requirement per angle, rad (`null`: no
    /// requirement).
    pub exact_chain_excess_rad: PerAngle<Option<f64>>,
    /// Why the requirement is not the study's, else `null`.
    pub requirement_note: Option<String>,
    /// Errors that act only together, with their combination's bound under each allocation.
    pub groups: Vec<GroupJson>,
    /// For the paper's table: Table 4's bounds, arcmin; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub paper_table4_arcmin: Option<ArcminBounds>,
    /// For the paper's table: Table 4's J, arcmin^-2; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub paper_table4_objective: Option<f64>,
    /// For the paper's table: Table 4's certificate; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub(crate) paper_table4_certificate: Option<PerAngle<AxisCertificateJson>>,
    /// `angle_dependent`, `disc_allocation` and `rate_allocation` (each absent when it does
    /// not apply).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub extras: crate::json::ExtrasJson<'a>,
}

/// The view printed by `--json`.
///
/// # Errors
/// As [`allocate`] and the exact-chain check.
pub fn allocate_json<'a>(
    s: &'a Study,
    a: &'a Allocations,
    form: ConstraintForm,
    safety_margin: f64,
) -> Result<AllocateJson<'a>> {
    let names = s.turntable.rotation_error_names();
    let exact = exact_chain_check(&a.problem, &a.ours).map_err(|e| crate::error::library(e, s))?;
    let req = a.problem.requirement();
    Ok(AllocateJson {
        study: &s.path,
        requirement_deg: PerAngle::new(|x| req.get(x).map(rad_to_deg)),
        lower_bounds_arcmin: arcmin_bounds(&names, a.problem.lower_bounds_rad()),
        constraint_form: match form {
            ConstraintForm::PaperQuarterRanges => "paper",
            ConstraintForm::FullRange => "full-range",
        },
        safety_margin,
        allocation_arcmin: arcmin_bounds(&names, a.ours.upper_bounds_rad()),
        unconstrained: a.ours.unconstrained_names(),
        objective: a.ours.objective_arcmin(),
        objective_unit: "arcmin^-2 (J_psi + J_theta + J_gamma, W = 1/average sensitivity)",
        certificate: certificate_json(s, a.ours.certificate()),
        lemma1_full_range: a.ours.certificate().lemma1_holds(),
        equal_effects_arcmin: arcmin_bounds(&names, a.equal.upper_bounds_rad()),
        equal_effects_objective: a.equal.objective_arcmin(),
        exact_chain_worst_deg: PerAngle::new(|x| rad_to_deg(exact[x.index()].exact_worst_rad())),
        exact_chain_excess_rad: PerAngle::new(|x| exact[x.index()].excess_rad()),
        requirement_note: st::requirement(s)?.disagreement,
        groups: GroupJson::all(&s.turntable, &group_boxes(a)),
        paper_table4_arcmin: a.table4.as_ref().map(|(t, _, _)| arcmin_bounds(&names, t)),
        paper_table4_objective: a.table4.as_ref().map(|(_, _, j)| *j),
        paper_table4_certificate: a
            .table4
            .as_ref()
            .map(|(_, cert, _)| certificate_json(s, cert)),
        extras: crate::json::ExtrasJson::default(),
    })
}

/// The allocations' bounds by label, for the groups of errors that act only together.
pub fn group_boxes(a: &Allocations) -> Vec<(&'static str, &[f64])> {
    let mut b: Vec<(&'static str, &[f64])> = vec![
        ("ours", a.ours.upper_bounds_rad()),
        ("equal effects", a.equal.upper_bounds_rad()),
    ];
    if let Some((t, _, _)) = &a.table4 {
        b.push(("Table 4", t));
    }
    b
}

/// `allocate --json` for a study with rate steps: the two-step allocation is not made, so
/// only what is: the direct allocation with the rate tolerances (and a sheet's pairs).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateStudyJson<'a> {
    /// The study's path.
    pub study: &'a str,
    /// Why the two-step allocation is not made.
    pub two_step_allocation: String,
    /// `disc_allocation` and `rate_allocation` (each absent when it does not apply).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub extras: crate::json::ExtrasJson<'a>,
}

/// The options of [`allocate_study`]: the constraint form of the per-angle problems, the
/// relative safety margin m in [0, 1) (allocate for (1 - m) I) and a vendor sheet whose
/// magnitudes pair the errors (the disc allocation).
#[derive(Debug, Clone)]
pub struct Options {
    /// The constraint of the per-angle problems (default: eq 30 over every pose).
    pub form: ConstraintForm,
    /// Relative safety margin in [0, 1).
    pub safety_margin: f64,
    /// A vendor sheet whose magnitudes pair the errors.
    pub tolerances: Option<std::path::PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            form: ConstraintForm::FullRange,
            safety_margin: 0.0,
            tolerances: None,
        }
    }
}

/// The allocations of a study ([`allocate_study`]): the two-step allocation (a static study),
/// the angle-dependent model's direct allocations, a sheet's pairs, and the direct allocation
/// with the rate tolerances (a study with rate steps, where the two-step allocation is not
/// made).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct StudyAllocation {
    two_step: Option<Allocations>,
    angle: Option<(EndToEnd, angle::AngleAllocations)>,
    sheet: Option<angle::SheetAllocations>,
    rate: Option<(EndToEnd, Option<RateAllocated>)>,
}

impl StudyAllocation {
    /// The two-step allocation (`None` for a study with rate steps: the orientation
    /// requirement is static).
    #[must_use]
    pub fn two_step(&self) -> Option<&Allocations> {
        self.two_step.as_ref()
    }
    /// The angle-dependent model's allocations with the study's simulator.
    #[must_use]
    pub fn angle(&self) -> Option<&(EndToEnd, angle::AngleAllocations)> {
        self.angle.as_ref()
    }
    /// A sheet's pairs allocated as discs and squares.
    #[must_use]
    pub fn sheet(&self) -> Option<&angle::SheetAllocations> {
        self.sheet.as_ref()
    }
    /// For a study with rate steps: its simulator and the direct allocation with the rate
    /// tolerances.
    #[must_use]
    pub fn rate(&self) -> Option<&(EndToEnd, Option<RateAllocated>)> {
        self.rate.as_ref()
    }
}

/// The allocation of a study's tolerances: two-step (eq 30-34) for a static study, with the
/// angle-dependent model's and a sheet's pairs; for a study with rate steps, the direct
/// allocation with the rate tolerances.
///
/// # Errors
/// An [`InputError`] naming the key or the sheet; a solver error.
pub fn allocate_study(s: &Study, o: &Options) -> Result<StudyAllocation> {
    if s.has_rate_steps() {
        let sheet = angle::sheet(s, o.tolerances.as_deref())?;
        let e2e = crate::loaded::simulator(s)?;
        let settings = e2e_verify::McSettings::new(s.monte_carlo.samples, s.monte_carlo.seed);
        let rate = rate_allocation(s, &e2e, &settings)?;
        return Ok(StudyAllocation {
            two_step: None,
            angle: None,
            sheet,
            rate: Some((e2e, rate)),
        });
    }
    let a = allocate(s, o.form, o.safety_margin)?;
    // errors that vary with the shaft angle: the direct allocations of the angle model
    let angle = if s.has_angle_dependent_errors() || s.measured.iter().any(Option::is_some) {
        let e2e = crate::loaded::simulator(s)?;
        angle::compute(s, &e2e)?.map(|an| (e2e, an))
    } else {
        None
    };
    let sheet = angle::sheet(s, o.tolerances.as_deref())?;
    Ok(StudyAllocation {
        two_step: Some(a),
        angle,
        sheet,
        rate: None,
    })
}
