//! `cargo xtask allocate [--study FILE] [--json] [--constraint-form paper|full-range]
//! [--safety-margin M]`: the two-step turntable error allocation (paper §4.2-4.3, problems
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
use crate::json::{ArcminBounds, GroupJson, PerAngle, arcmin_bounds};
use crate::loaded as st;
use alloc_opt::{
    Allocation, AllocationProblem, Allocator, Certificate, ConstraintForm, EqualEffects,
    SensitivityWeighted, Weights, exact_chain_check,
};
use anyhow::Result;
use clap::{Parser, ValueEnum};
use serde::Serialize;
use std::collections::BTreeMap;
use study::Study;
use study::fmt::num;
use tt_core::units::{RAD_PER_ARCMIN, rad_to_arcmin, rad_to_deg};
use tt_kinematics::{LinearModel, OrientationAxis};

/// The constraint of the per-angle problems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormChoice {
    /// As printed: the quarter pose ranges of problems 31 and 33 (tables with one free joint).
    Paper,
    /// Eq 30 itself over every pose (any table; the same optimum for the paper's).
    FullRange,
}

/// Arguments of `allocate`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub study: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// The constraint form of the per-angle problems.
    #[arg(long, value_enum, default_value_t = FormChoice::FullRange)]
    pub constraint_form: FormChoice,
    /// Relative safety margin m in [0, 1): allocate for (1 - m) I (room for the exact chain's
    /// second-order terms).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0, value_parser = parse_margin)]
    pub safety_margin: f64,
    /// A vendor sheet whose magnitudes (`[axes.<joint>]` wobble, orthogonality) pair the
    /// errors: adds the direct and certified allocation with one tolerance per pair, as a
    /// disc and as a square (JSON `disc_allocation`).
    #[arg(long)]
    pub tolerances: Option<std::path::PathBuf>,
}

fn parse_margin(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if (0.0..1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("`{s}`: the safety margin must lie in [0, 1)"))
    }
}

/// One angle's Lemma 1 certificate, degrees.
#[derive(Debug, Serialize)]
pub struct AxisCertificateJson {
    /// The requirement, degrees (`null`: none).
    requirement_deg: Option<f64>,
    /// The largest worst case found, degrees.
    worst_case_deg: f64,
    /// A rigorous upper bound on it, degrees.
    upper_bound_deg: f64,
    /// Whether the worst case is exact (at most one free joint).
    exact_search: bool,
    /// A pose where it is reached, keyed by joint, degrees.
    worst_pose_deg: BTreeMap<String, f64>,
    /// `worst_case / requirement` (`null` without a requirement).
    share: Option<f64>,
    /// Whether the requirement is active.
    requirement_active: bool,
    /// Whether Lemma 1 holds for this angle.
    lemma1: bool,
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
pub fn allocate(s: &Study, form: FormChoice, safety_margin: f64) -> Result<Allocations> {
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
    .map_err(|e| crate::input::library(e, s))?
    .with_safety_margin(safety_margin)
    .map_err(|e| crate::input::library(e, s))?;
    let allocator = SensitivityWeighted {
        form: match form {
            FormChoice::Paper => ConstraintForm::PaperQuarterRanges,
            FormChoice::FullRange => ConstraintForm::FullRange,
        },
        ..SensitivityWeighted::paper()
    };
    let ours = allocator
        .allocate(&problem)
        .map_err(|e| crate::input::library(e, s))?;
    let equal = EqualEffects
        .allocate(&problem)
        .map_err(|e| crate::input::library(e, s))?;
    let table4 = if s.turntable == tt_kinematics::paper::table3() {
        let t = alloc_opt::paper::table4_rad();
        let cert = Certificate::compute(
            problem.model(),
            problem.limits(),
            problem.lower_bounds_rad(),
            &t,
        )
        .map_err(|e| crate::input::library(e, s))?;
        let j = Weights::inverse_average_sensitivity(problem.model()).objective(&t)
            * RAD_PER_ARCMIN
            * RAD_PER_ARCMIN;
        Some((t, cert, j))
    } else {
        None
    };
    Ok(Allocations {
        problem,
        ours,
        equal,
        table4,
    })
}

/// `allocate --json`: the two-step allocation with its certificate.
#[derive(Debug, Serialize)]
pub struct AllocateJson<'a> {
    /// The study's path.
    study: &'a str,
    /// The orientation requirement per angle, degrees (`null`: none).
    requirement_deg: PerAngle<Option<f64>>,
    /// The errors' lower bounds, arcmin.
    lower_bounds_arcmin: ArcminBounds,
    /// `paper` or `full-range`.
    constraint_form: &'static str,
    /// The safety margin, in [0, 1).
    safety_margin: f64,
    /// The sensitivity-weighted allocation's bounds, arcmin.
    allocation_arcmin: ArcminBounds,
    /// The errors no angle constrains.
    unconstrained: Vec<&'a str>,
    /// J of the allocation, arcmin^-2 (`objective_unit`).
    objective: f64,
    /// J's unit and definition, in words.
    objective_unit: &'static str,
    /// Lemma 1's certificate per angle.
    certificate: PerAngle<AxisCertificateJson>,
    /// Whether Lemma 1 holds over the full range.
    lemma1_full_range: bool,
    /// The equal-effects allocation's bounds, arcmin.
    equal_effects_arcmin: ArcminBounds,
    /// Its J, arcmin^-2.
    equal_effects_objective: f64,
    /// The exact chain's worst case per angle, degrees.
    exact_chain_worst_deg: PerAngle<f64>,
    /// By how much the exact chain exceeds the requirement per angle, rad (`null`: no
    /// requirement).
    exact_chain_excess_rad: PerAngle<Option<f64>>,
    /// Why the requirement is not the study's, else `null`.
    requirement_note: Option<String>,
    /// Errors that act only together, with their combination's bound under each allocation.
    groups: Vec<GroupJson>,
    /// For the paper's table: Table 4's bounds, arcmin; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    paper_table4_arcmin: Option<ArcminBounds>,
    /// For the paper's table: Table 4's J, arcmin^-2; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    paper_table4_objective: Option<f64>,
    /// For the paper's table: Table 4's certificate; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    paper_table4_certificate: Option<PerAngle<AxisCertificateJson>>,
    /// `angle_dependent`, `disc_allocation` and `rate_allocation` (each absent when it does
    /// not apply).
    #[serde(flatten)]
    extras: crate::json::ExtrasJson<'a>,
}

/// The view printed by `--json`.
///
/// # Errors
/// As [`allocate`] and the exact-chain check.
pub fn allocate_json<'a>(
    s: &'a Study,
    a: &'a Allocations,
    form: FormChoice,
    safety_margin: f64,
) -> Result<AllocateJson<'a>> {
    let names = s.turntable.rotation_error_names();
    let exact = exact_chain_check(&a.problem, &a.ours).map_err(|e| crate::input::library(e, s))?;
    let req = a.problem.requirement();
    Ok(AllocateJson {
        study: &s.path,
        requirement_deg: PerAngle::new(|x| req.get(x).map(rad_to_deg)),
        lower_bounds_arcmin: arcmin_bounds(&names, a.problem.lower_bounds_rad()),
        constraint_form: match form {
            FormChoice::Paper => "paper",
            FormChoice::FullRange => "full-range",
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
fn group_boxes(a: &Allocations) -> Vec<(&'static str, &[f64])> {
    let mut b: Vec<(&'static str, &[f64])> = vec![
        ("ours", a.ours.upper_bounds_rad()),
        ("equal effects", a.equal.upper_bounds_rad()),
    ];
    if let Some((t, _, _)) = &a.table4 {
        b.push(("Table 4", t));
    }
    b
}

fn text(s: &Study, a: &Allocations, v: &AllocateJson<'_>) -> String {
    let names = s.turntable.rotation_error_names();
    let req = a.problem.requirement();
    let mut t = format!(
        "two-step allocation, study {} ({}); requirement psi {}, theta {}, gamma {} deg\n",
        s.name,
        s.path,
        req.get(OrientationAxis::Psi)
            .map_or("none".into(), |r| num(rad_to_deg(r))),
        req.get(OrientationAxis::Theta)
            .map_or("none".into(), |r| num(rad_to_deg(r))),
        req.get(OrientationAxis::Gamma)
            .map_or("none".into(), |r| num(rad_to_deg(r))),
    );
    let width = names.iter().map(|n| n.len()).max().unwrap_or(5).max(5);
    let mut header = format!(
        "{:<width$} {:>12} {:>14}",
        "error", "ours (')", "equal eff. (')"
    );
    if a.table4.is_some() {
        header.push_str(&format!(" {:>12}", "Table 4 (')"));
    }
    t.push_str(&header);
    t.push('\n');
    let cell = |u: f64| {
        if u.is_finite() {
            study::fmt::sig(rad_to_arcmin(u), 4)
        } else {
            "none".into()
        }
    };
    for (i, n) in names.iter().enumerate() {
        let mut row = format!(
            "{:<width$} {:>12} {:>14}",
            n,
            cell(a.ours.upper_bounds_rad()[i]),
            cell(a.equal.upper_bounds_rad()[i])
        );
        if let Some((tb, _, _)) = &a.table4 {
            row.push_str(&format!(" {:>12}", cell(tb[i])));
        }
        t.push_str(&row);
        t.push('\n');
    }
    let mut j = format!(
        "{:<width$} {:>12} {:>14}",
        "J",
        num(a.ours.objective_arcmin()),
        num(a.equal.objective_arcmin())
    );
    if let Some((_, _, tj)) = &a.table4 {
        j.push_str(&format!(" {:>12}", num(*tj)));
    }
    t.push_str(&j);
    t.push_str("   (arcmin^-2)\n");
    t.push_str(&crate::groups::text(&s.turntable, &group_boxes(a), ""));
    for x in OrientationAxis::ALL {
        let c = a.ours.certificate().get(x);
        t.push_str(&format!(
            "{:<6} worst case {} deg (bound {}), share {}, Lemma 1 {}\n",
            x.name(),
            num(rad_to_deg(c.worst_case_rad())),
            num(rad_to_deg(c.upper_bound_rad())),
            c.share()
                .map_or("-".into(), |v| format!("{:.4}%", 100.0 * v)),
            if c.satisfied() { "holds" } else { "fails" }
        ));
    }
    let ex = |x: OrientationAxis| {
        v.exact_chain_excess_rad
            .get(x)
            .filter(|e| e.is_finite())
            .map_or("-".into(), num)
    };
    let excess: Vec<String> = OrientationAxis::ALL
        .iter()
        .map(|&a| format!("{} {}", a.name(), ex(a)))
        .collect();
    t.push_str(&format!(
        "exact chain over I (rad): {}\n",
        excess.join(", ")
    ));
    if let Some(n) = &v.requirement_note {
        t.push_str(n);
        t.push('\n');
    }
    t
}

/// `allocate --json` for a study with rate steps: the two-step allocation is not made, so
/// only what is: the direct allocation with the rate tolerances (and a sheet's pairs).
#[derive(Debug, Serialize)]
struct RateStudyJson<'a> {
    /// The study's path.
    study: &'a str,
    /// Why the two-step allocation is not made.
    two_step_allocation: String,
    /// `disc_allocation` and `rate_allocation` (each absent when it does not apply).
    #[serde(flatten)]
    extras: crate::json::ExtrasJson<'a>,
}

/// `allocate` on a study with rate steps: the two-step allocation is not made (the
/// orientation requirement is a static concept); the answer is the direct allocation with the
/// rate tolerances.
fn run_rate_study(args: &Args, s: &Study) -> Result<()> {
    let sheet = crate::angle_alloc::sheet(s, args.tolerances.as_deref())?;
    let e2e = crate::end_to_end::simulator(s)?;
    let settings = e2e_verify::McSettings::new(s.monte_carlo.samples, s.monte_carlo.seed);
    let rate = crate::rate::allocation(s, &e2e, &settings)?;
    let not_made = format!("not made: {}", crate::rate::STATIC_REQUIREMENT_NOTE);
    if args.json {
        let extras = crate::json::ExtrasJson {
            disc_allocation: sheet
                .as_ref()
                .map(|(path, al)| crate::angle::SheetAllocationsJson::new(path, al)),
            rate_allocation: rate
                .as_ref()
                .map(|r| crate::rate::RateAllocationJson::new(&e2e, r)),
            ..crate::json::ExtrasJson::default()
        };
        return crate::json::print(&RateStudyJson {
            study: &s.path,
            two_step_allocation: not_made,
            extras,
        });
    }
    let mut t = format!(
        "two-step allocation, study {} ({}): {not_made}\n",
        s.name, s.path
    );
    if let Some((path, al)) = &sheet {
        t.push_str(&crate::angle::sheet_allocations_text(path, al));
    }
    if let Some(r) = &rate {
        t.push_str(&crate::rate::allocation_text(&e2e, r));
    }
    crate::out::print(&t)
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let s = st::load(args.study.as_deref())?;
    if s.has_rate_steps() {
        return run_rate_study(args, &s);
    }
    let a = allocate(&s, args.constraint_form, args.safety_margin)?;
    // errors that vary with the shaft angle: the direct allocations of the angle model
    let angle = if s.has_angle_dependent_errors() || s.measured.iter().any(Option::is_some) {
        let e2e = crate::end_to_end::simulator(&s)?;
        crate::angle_alloc::compute(&s, &e2e)?.map(|an| (e2e, an))
    } else {
        None
    };
    let extra = angle
        .as_ref()
        .map(|(e2e, an)| crate::angle_alloc::to_text(e2e, an));
    let sheet = crate::angle_alloc::sheet(&s, args.tolerances.as_deref())?;
    let mut v = allocate_json(&s, &a, args.constraint_form, args.safety_margin)?;
    if args.json {
        v.extras.angle_dependent = angle
            .as_ref()
            .map(|(e2e, an)| crate::angle_alloc::AngleDependentJson::new(e2e, an));
        v.extras.disc_allocation = sheet
            .as_ref()
            .map(|(path, al)| crate::angle::SheetAllocationsJson::new(path, al));
        return crate::json::print(&v);
    }
    let mut t = text(&s, &a, &v);
    if let Some(x) = extra {
        t.push_str(&x);
    }
    if let Some((path, al)) = &sheet {
        t.push_str(&crate::angle::sheet_allocations_text(path, al));
    }
    crate::out::print(&t)
}
