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

use crate::json::ExtrasJson;
use alloc_opt::ConstraintForm;
use anyhow::Result;
use clap::{Parser, ValueEnum};
use study::Study;
use tt_core::human::num;
use tt_core::units::{rad_to_arcmin, rad_to_deg};
use tt_kinematics::OrientationAxis;
use tt_lab::allocation::{AllocateJson, Allocations, RateStudyJson, StudyAllocation, group_boxes};

/// The constraint of the per-angle problems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum FormChoice {
    /// As printed: the quarter pose ranges of problems 31 and 33 (tables with one free joint).
    Paper,
    /// Eq 30 itself over every pose (any table; the same optimum for the paper's).
    FullRange,
}

/// Arguments of `allocate`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// `--study` (default: the paper's) and `--json`.
    #[command(flatten)]
    pub input: crate::args::StudyJson,
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
            tt_core::human::sig(rad_to_arcmin(u), 4)
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
    t.push_str(&crate::text::groups::text(
        &s.turntable,
        &group_boxes(a),
        "",
    ));
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

/// Run the command.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = args.input.study.load()?;
    let form = match args.constraint_form {
        FormChoice::Paper => ConstraintForm::PaperQuarterRanges,
        FormChoice::FullRange => ConstraintForm::FullRange,
    };
    let options = tt_lab::allocation::Options {
        form,
        safety_margin: args.safety_margin,
        tolerances: args.tolerances.clone(),
    };
    let r = tt_lab::allocation::allocate_study(&s, &options).map_err(crate::input::lab)?;
    let Some(a) = r.two_step() else {
        return print_rate_study(args, &s, &r);
    };
    let mut v = tt_lab::allocation::allocate_json(&s, a, form, args.safety_margin)
        .map_err(crate::input::lab)?;
    if args.input.json {
        v.extras.angle_dependent = r
            .angle()
            .map(|(e2e, an)| tt_lab::allocation::angle::AngleDependentJson::new(e2e, an));
        v.extras.disc_allocation = r
            .sheet()
            .map(|(path, al)| tt_lab::vendor::angle::SheetAllocationsJson::new(path, al));
        return crate::json::print(&v);
    }
    let mut t = text(&s, a, &v);
    if let Some((e2e, an)) = r.angle() {
        t.push_str(&crate::text::angle_alloc::to_text(e2e, an));
    }
    if let Some((path, al)) = r.sheet() {
        t.push_str(&crate::text::angle::sheet_allocations_text(path, al));
    }
    crate::out::print(&t)
}

/// `allocate` on a study with rate steps: the two-step allocation is not made (the
/// orientation requirement is a static concept); the answer is the direct allocation with the
/// rate tolerances.
fn print_rate_study(args: &Args, s: &Study, r: &StudyAllocation) -> Result<()> {
    let not_made = format!("not made: {}", tt_lab::loaded::STATIC_REQUIREMENT_NOTE);
    let sheet = r.sheet();
    let (e2e, rate) = match r.rate() {
        Some((e2e, rate)) => (e2e, rate.as_ref()),
        None => return Ok(()),
    };
    if args.input.json {
        let extras = ExtrasJson {
            disc_allocation: sheet
                .map(|(path, al)| tt_lab::vendor::angle::SheetAllocationsJson::new(path, al)),
            rate_allocation: rate.map(|x| tt_lab::vendor::rate::RateAllocationJson::new(e2e, x)),
            ..ExtrasJson::default()
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
    if let Some((path, al)) = sheet {
        t.push_str(&crate::text::angle::sheet_allocations_text(path, al));
    }
    if let Some(x) = rate {
        t.push_str(&crate::text::rate::allocation_text(e2e, x));
    }
    crate::out::print(&t)
}
