//! `cargo xtask allocate [--json]`: the turntable error allocation (paper §4.2-4.3, problems
//! 31-34, Table 4) for the paper's inputs, beside Table 4 and the equal-effects allocation.
//!
//! Inputs live in [`AllocateInputs`], filled from the study file (`--study FILE`, default the
//! paper's: eq 26, $I = 0.027^\circ$ for all three angles as printed in eq 16, zero lower
//! bounds because the paper gives none) and the flags `--constraint-form` and
//! `--safety-margin`.
//!
//! `--json` prints one object with at least
//! `{"requirement_deg": {"psi","theta","gamma"}, "allocation_arcmin": {"dphi_y1", "dphi_z2",
//! "dalpha_x1", "dalpha_z1", "dalpha_x2", "dalpha_y2", "deps_x", "deps_y"}, "objective": J,
//! "paper_table4_arcmin": {...same keys...}, "paper_table4_objective": J}`; objectives are
//! $J = J_\psi + J_\theta + J_\gamma$ with the bounds in arcmin (unit arcmin$^{-2}$) and the
//! paper's weights. Further keys: shares of each requirement, worst poses, active constraints,
//! Lemma 1 on the full pose range, the equal-effects allocation, and the exact-chain check.

use crate::InputError;
use crate::study::Study;
use alloc_opt::{
    AllocError, AllocationProblem, Allocator, Certificate, ConstraintForm, EqualEffects,
    PAPER_REQUIREMENT_DEG, PAPER_TABLE4_ARCMIN, Requirement, SensitivityWeighted, Weights,
    exact_chain_check, paper_table4_rad,
};
use anyhow::Result;
use clap::Parser;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value, json};
use tt_kinematics::units::{RAD_PER_ARCMIN, arcmin_to_rad, deg_to_rad, rad_to_deg};
use tt_kinematics::{CHI_LEN, ErrorComponent, LinearModel, OrientationAxis};

/// Arguments of `allocate`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`, the paper's inputs).
    #[arg(long)]
    pub study: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// `paper` (the quarter pose ranges of problems 31 and 33) or `full-range` (eq 30 on
    /// [0, 2 pi]).
    #[arg(long, default_value = "paper")]
    pub constraint_form: String,
    /// Relative safety margin m: allocate for (1 - m) I (room for the exact chain's
    /// second-order terms).
    #[arg(long, default_value_t = 0.0)]
    pub safety_margin: f64,
}

/// Everything the allocation depends on, in the units of study files; defaults are the
/// paper's example.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AllocateInputs {
    /// Requirement $I_\psi$ in degrees (eq 16: 0.027).
    pub requirement_psi_deg: f64,
    /// Requirement $I_\theta$ in degrees (eq 16: 0.027).
    pub requirement_theta_deg: f64,
    /// Requirement $I_\gamma$ in degrees (eq 16: 0.027).
    pub requirement_gamma_deg: f64,
    /// Lower bounds $\mathrm{LB}_i$ (eq 29) in arcmin, order of eq 25 (default 0: the paper
    /// gives none).
    pub lower_bounds_arcmin: [f64; CHI_LEN],
    /// `paper` (quarter ranges of 31/33, default) or `full-range` (eq 30 on $[0, 2\pi]$).
    pub constraint_form: String,
    /// Relative safety margin: allocate for $(1 - m) I$ (default 0).
    pub safety_margin: f64,
}

impl Default for AllocateInputs {
    fn default() -> Self {
        Self {
            requirement_psi_deg: PAPER_REQUIREMENT_DEG,
            requirement_theta_deg: PAPER_REQUIREMENT_DEG,
            requirement_gamma_deg: PAPER_REQUIREMENT_DEG,
            lower_bounds_arcmin: [0.0; CHI_LEN],
            constraint_form: "paper".to_string(),
            safety_margin: 0.0,
        }
    }
}

/// Map an allocation error caused by the inputs to an [`InputError`] (exit 2).
fn input_error(e: AllocError) -> anyhow::Error {
    match &e {
        AllocError::NonFinite { field, .. }
        | AllocError::NotPositive { field, .. }
        | AllocError::Negative { field, .. } => {
            InputError::new(field.clone(), e.to_string()).into()
        }
        AllocError::InfeasibleLowerBounds { .. } | AllocError::Unbounded { .. } => {
            InputError::new("lower_bounds_arcmin", e.to_string()).into()
        }
        _ => e.into(),
    }
}

impl AllocateInputs {
    /// The study's requirement (eq 16 as written in it) and lower bounds, with the given
    /// constraint form and safety margin.
    pub fn from_study(study: &Study, constraint_form: &str, safety_margin: f64) -> Self {
        let r = &study.file.requirement;
        Self {
            requirement_psi_deg: r.psi_deg,
            requirement_theta_deg: r.theta_deg,
            requirement_gamma_deg: r.gamma_deg,
            lower_bounds_arcmin: study.file.allocation.lower_bounds_arcmin.to_array(),
            constraint_form: constraint_form.to_string(),
            safety_margin,
        }
    }

    /// The library problem and allocator, naming the offending key on bad input.
    ///
    /// # Errors
    /// [`InputError`] naming the key.
    pub fn problem(&self) -> Result<(AllocationProblem, SensitivityWeighted)> {
        let deg = |key: &str, v: f64| -> Result<f64> {
            if v.is_finite() {
                Ok(deg_to_rad(v))
            } else {
                Err(InputError::new(key, format!("must be finite, got {v}")).into())
            }
        };
        let requirement = Requirement::new(
            deg("requirement_psi_deg", self.requirement_psi_deg)?,
            deg("requirement_theta_deg", self.requirement_theta_deg)?,
            deg("requirement_gamma_deg", self.requirement_gamma_deg)?,
        )
        .map_err(input_error)?;
        let problem = AllocationProblem::new(
            LinearModel::paper_eq26(),
            requirement,
            self.lower_bounds_arcmin.map(arcmin_to_rad),
        )
        .map_err(input_error)?
        .with_safety_margin(self.safety_margin)
        .map_err(input_error)?;
        let form = match self.constraint_form.as_str() {
            "paper" => ConstraintForm::PaperQuarterRanges,
            "full-range" => ConstraintForm::FullRange,
            other => {
                return Err(InputError::new(
                    "constraint_form",
                    format!("expected `paper` or `full-range`, got `{other}`"),
                )
                .into());
            }
        };
        Ok((
            problem,
            SensitivityWeighted {
                form,
                ..SensitivityWeighted::paper()
            },
        ))
    }
}

fn components(values: &[f64; CHI_LEN]) -> Value {
    let mut m = Map::new();
    for c in ErrorComponent::ALL {
        m.insert(c.name().to_string(), json!(values[c.index()]));
    }
    Value::Object(m)
}

fn per_axis(f: impl Fn(OrientationAxis) -> Value) -> Value {
    let mut m = Map::new();
    for a in OrientationAxis::ALL {
        m.insert(a.name().to_string(), f(a));
    }
    Value::Object(m)
}

fn shares(cert: &Certificate) -> Value {
    per_axis(|a| json!(cert.get(a).share))
}

/// The JSON object printed by `--json`.
///
/// # Errors
/// [`InputError`] for bad inputs; solver failures otherwise.
pub fn allocate_json(inputs: &AllocateInputs) -> Result<Value> {
    let (problem, allocator) = inputs.problem()?;
    let ours = allocator.allocate(&problem).map_err(input_error)?;
    let equal = EqualEffects.allocate(&problem).map_err(input_error)?;
    let table = paper_table4_rad();
    let table_cert = Certificate::compute(
        problem.model(),
        &problem.requirement(),
        &problem.lower_bounds_rad(),
        &table,
    );
    let weights = Weights::inverse_average_sensitivity(problem.model());
    let table_objective = weights.objective(&table) * RAD_PER_ARCMIN * RAD_PER_ARCMIN;
    let exact = exact_chain_check(&ours)?;
    let req = problem.requirement();
    let active_lb: Vec<&str> = {
        let mut v: Vec<&str> = ours
            .certificate
            .axes
            .iter()
            .flat_map(|a| a.active_lower_bounds.iter().map(|c| c.name()))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    Ok(json!({
        "requirement_deg": per_axis(|a| json!(rad_to_deg(req.get(a)))),
        "lower_bounds_arcmin": components(&inputs.lower_bounds_arcmin),
        "constraint_form": inputs.constraint_form,
        "safety_margin": inputs.safety_margin,
        "allocation_arcmin": components(&ours.upper_bounds_arcmin()),
        "objective": ours.objective_arcmin(),
        "objective_unit": "arcmin^-2 (J_psi + J_theta + J_gamma, W = 1/average sensitivity)",
        "share": shares(&ours.certificate),
        "worst_phi2_deg": per_axis(|a| json!(rad_to_deg(ours.certificate.get(a).worst_phi2_rad))),
        "active_requirements": per_axis(|a| json!(ours.certificate.get(a).requirement_active)),
        "active_lower_bounds": active_lb,
        "lemma1_full_range": ours.certificate.lemma1_holds(),
        "paper_table4_arcmin": components(&PAPER_TABLE4_ARCMIN),
        "paper_table4_objective": table_objective,
        "paper_table4_share": shares(&table_cert),
        "equal_effects_arcmin": components(&equal.upper_bounds_arcmin()),
        "equal_effects_objective": equal.objective_arcmin(),
        "equal_effects_share": shares(&equal.certificate),
        "exact_chain_worst_rad": per_axis(|a| json!(exact[a.index()].exact_worst_rad)),
        "exact_chain_excess_rad": per_axis(|a| json!(exact[a.index()].excess_rad)),
    }))
}

fn text(v: &Value) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let req = &v["requirement_deg"];
    let lb: Vec<String> = ErrorComponent::ALL
        .iter()
        .map(|c| format!("{}", v["lower_bounds_arcmin"][c.name()]))
        .collect();
    let _ = writeln!(
        s,
        "requirement (deg): psi {} theta {} gamma {}; lower bounds (arcmin, eq 25 order): {}",
        req["psi"],
        req["theta"],
        req["gamma"],
        lb.join(" ")
    );
    let _ = writeln!(
        s,
        "{:<10} {:>12} {:>12} {:>14}",
        "component", "ours (')", "Table 4 (')", "equal eff. (')"
    );
    for c in ErrorComponent::ALL {
        let k = c.name();
        let f = |key: &str| v[key][k].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            s,
            "{:<10} {:>12.4} {:>12.4} {:>14.4}",
            k,
            f("allocation_arcmin"),
            f("paper_table4_arcmin"),
            f("equal_effects_arcmin")
        );
    }
    let g = |key: &str| v[key].as_f64().unwrap_or(f64::NAN);
    let _ = writeln!(
        s,
        "{:<10} {:>12.3} {:>12.3} {:>14.3}   (J, arcmin^-2)",
        "J",
        g("objective"),
        g("paper_table4_objective"),
        g("equal_effects_objective")
    );
    for a in OrientationAxis::ALL {
        let k = a.name();
        let f = |key: &str| v[key][k].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            s,
            "share {:<5}{:>11.2}% {:>11.2}% {:>13.2}%",
            k,
            100.0 * f("share"),
            100.0 * f("paper_table4_share"),
            100.0 * f("equal_effects_share")
        );
    }
    let _ = writeln!(
        s,
        "Lemma 1 on the full pose range: {}; exact-chain excess over I (rad): psi {:.3e}, theta {:.3e}, gamma {:.3e}",
        v["lemma1_full_range"],
        v["exact_chain_excess_rad"]["psi"]
            .as_f64()
            .unwrap_or(f64::NAN),
        v["exact_chain_excess_rad"]["theta"]
            .as_f64()
            .unwrap_or(f64::NAN),
        v["exact_chain_excess_rad"]["gamma"]
            .as_f64()
            .unwrap_or(f64::NAN),
    );
    s
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let study = Study::load_or_paper(args.study.as_deref())?;
    let v = allocate_json(&AllocateInputs::from_study(
        &study,
        &args.constraint_form,
        args.safety_margin,
    ))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print!("{}", text(&v));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key_of(e: &anyhow::Error) -> String {
        e.downcast_ref::<InputError>()
            .map(|i| i.location.clone())
            .unwrap_or_else(|| panic!("not an InputError: {e:#}"))
    }

    /// The paper's study file gives exactly the paper's example.
    #[test]
    fn paper_study_gives_the_default_inputs() {
        assert_eq!(
            AllocateInputs::from_study(&Study::paper().unwrap(), "paper", 0.0),
            AllocateInputs::default()
        );
    }

    /// Bad study values become InputErrors (exit 2) naming the key.
    #[test]
    fn bad_inputs_are_input_errors_naming_the_key() {
        let bad = |f: &dyn Fn(&mut AllocateInputs)| {
            let mut i = AllocateInputs::default();
            f(&mut i);
            allocate_json(&i).unwrap_err()
        };
        let e = bad(&|i| i.requirement_theta_deg = f64::NAN);
        assert_eq!(key_of(&e), "requirement_theta_deg");
        let e = bad(&|i| i.requirement_gamma_deg = -0.01);
        assert_eq!(key_of(&e), "requirement.gamma");
        let e = bad(&|i| i.lower_bounds_arcmin[4] = -0.1);
        assert_eq!(key_of(&e), "lower_bounds.dalpha_x2");
        let e = bad(&|i| i.lower_bounds_arcmin[4] = 2.0);
        assert_eq!(key_of(&e), "lower_bounds_arcmin");
        assert!(e.to_string().contains("problem gamma") && e.to_string().contains("dalpha_x2"));
        let e = bad(&|i| i.constraint_form = "quarter".into());
        assert_eq!(key_of(&e), "constraint_form");
        let e = bad(&|i| i.safety_margin = 1.5);
        assert_eq!(key_of(&e), "1 - safety_margin");
    }

    /// The defaults are the paper's example, and the full-range form gives the same bounds
    /// for eq 26.
    #[test]
    fn defaults_are_the_paper_example() {
        let d = AllocateInputs::default();
        let (p, a) = d.problem().unwrap();
        assert_eq!(p, AllocationProblem::paper_example().unwrap());
        assert_eq!(a, SensitivityWeighted::paper());
        let full = allocate_json(&AllocateInputs {
            constraint_form: "full-range".into(),
            ..d.clone()
        })
        .unwrap();
        let paper = allocate_json(&d).unwrap();
        for c in ErrorComponent::ALL {
            let (x, y) = (
                full["allocation_arcmin"][c.name()].as_f64().unwrap(),
                paper["allocation_arcmin"][c.name()].as_f64().unwrap(),
            );
            assert!((x - y).abs() <= 1e-9 * y, "{}: {x} vs {y}", c.name());
        }
    }
}
