//! `cargo xtask estimable [--study FILE] [--tolerances FILE] [--json]`: which table errors the
//! calibration can estimate itself (issue 22 item 4).
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

use anyhow::Result;
use calib_lsq::joint::JOINT_RANK_RTOL;
use clap::Parser;
use e2e_verify::DirectAllocation;
use std::path::PathBuf;
use tt_core::human::{num, sig};
pub(crate) use tt_lab::estimable::{Estimable, JOINT_ITERATIONS, model_words, to_json};

/// Arguments of `estimable`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// `--study` (default: the paper's).
    #[command(flatten)]
    pub study: crate::args::StudyFile,
    /// A vendor's tolerances whose worst turntable is calibrated both ways (default: the
    /// direct allocation's box under the user's reading).
    #[arg(long)]
    pub tolerances: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

fn allocation_line(names: &[&str], d: &DirectAllocation) -> String {
    if d.no_bound_needed() {
        return "no bound needed for any error (first order)".into();
    }
    format!(
        "J = {} arcmin^-2; bounds (arcmin): {}",
        sig(d.objective_arcmin(), 5),
        crate::text::angle_alloc::bounds_text(names, d)
    )
}

/// The answer as text lines (also the report's section body, which escapes it).
#[must_use]
pub(crate) fn to_text(a: &Estimable) -> String {
    let names = a.e2e.turntable().rotation_error_names();
    let est = &a.est;
    let reference = est.reference();
    let params = est.names().len();
    let mut t = String::new();
    t.push_str("joint least squares of the sensor coefficients and the table errors (outputs at the actual orientation: the user's reading)\n");
    let what = match model_words(a) {
        Some(m) => {
            t.push_str(&format!("error model: {m}\n"));
            format!("{params} coefficients of {} table errors", names.len())
        }
        None => format!("{params} table errors"),
    };
    t.push_str(&format!(
        "rank of the joint Jacobian: {} of {} ({} sensor coefficients + {what}; table part {} of {params})\n",
        est.rank(),
        est.columns(),
        est.coefficients(),
        est.table_rank(),
    ));
    let sv: Vec<String> = est
        .singular_values()
        .iter()
        .map(|v| sig(if reference > 0.0 { v / reference } else { 0.0 }, 3))
        .collect();
    t.push_str(&format!(
        "singular values of the table part, relative to the largest raw effect (zero at or below {}): {}\n",
        sig(JOINT_RANK_RTOL, 1),
        sv.join(", ")
    ));
    let e = est.estimable_combinations();
    t.push_str(&format!("estimable with the coefficients ({}):\n", e.len()));
    for c in &e {
        t.push_str(&format!("  {c}\n"));
    }
    let n = est.invisible_combinations();
    t.push_str(&format!(
        "not estimable ({}; their effect lies in the sensor's columns, the calibration absorbs it):\n",
        n.len()
    ));
    for c in &n {
        t.push_str(&format!("  {c}\n"));
    }
    let status: Vec<String> = est
        .names()
        .iter()
        .zip(est.identifiability())
        .map(|(n, s)| format!("{n} {}", s.name()))
        .collect();
    let model = if a.model.is_some() {
        "the study's angle-dependent model, "
    } else {
        ""
    };
    t.push_str(&format!(
        "each {} (alone: estimable by itself; combined: only in a combination; invisible: not at all): {}\n",
        if a.model.is_some() { "coefficient" } else { "error" },
        status.join(", ")
    ));
    t.push_str(&format!(
        "direct allocation (user's reading, {model}first order), ordinary calibration: {}\n",
        allocation_line(&names, &a.ordinary)
    ));
    t.push_str(&format!(
        "with the estimable combinations estimated: {}\n",
        allocation_line(&names, &a.joint)
    ));
    let what = match a.at_box.source {
        "tolerances" => "the sheet's",
        _ => "the ordinary direct allocation's",
    };
    t.push_str(&format!(
        "at {what} worst turntable ({model}exact chain, noiseless sensor; joint: Gauss-Newton, {JOINT_ITERATIONS} steps):\n"
    ));
    for (oc, (p, j)) in a.e2e.calibration().outputs().iter().zip(&a.at_box.rates) {
        let o = oc.output();
        t.push_str(&format!(
            "  {}: ordinary {} {u}, joint {} {u} (accuracy {} {u})\n",
            o.name,
            sig(*p, 4),
            sig(*j, 3),
            num(o.accuracy),
            u = o.unit
        ));
    }
    t
}

/// Run `estimable`.
///
/// # Errors
/// An [`InputError`] (exit 2) for a bad study or sheet; others exit 1.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = args.study.load()?;
    let options = tt_lab::estimable::Options {
        tolerances: args.tolerances.clone(),
    };
    let a = tt_lab::estimable::estimable(&s, &options).map_err(crate::input::lab)?;
    if args.json {
        crate::json::print(&to_json(&s, &a))
    } else {
        let mut t = format!("study {}\n{}", s.path, to_text(&a));
        if s.noise.iter().any(Option::is_some) {
            t.push_str("note: the sensor's noise is not counted here: a joint estimator's estimates carry it, the more the weaker the combination's singular value\n");
        }
        crate::out::print(&t)
    }
}
