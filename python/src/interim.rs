//! The study-level questions the Python functions answer, until the study-level library
//! (`tt-lab`, issue 33 section 1) answers each of them: one function per question, each
//! returning the answer as the command line's `--json` prints it (the same keys, a subset
//! where noted). The study, its requirement, its simulator and the errors are `tt-lab`'s
//! already; when `tt-lab` answers a question (`allocate`, `end_to_end`, `check_turntable`),
//! its function here becomes that call and its answer's serialisation, and the Python layer
//! (`lib.rs`) does not change.
//!
//! Nothing here decides anything: every number is a library call's; this module resolves the
//! study's inputs the way the command line does (`ttalloc/src/allocate.rs`,
//! `end_to_end.rs`, `check_turntable.rs`) and names the keys.

use alloc_opt::{
    AllocationProblem, Allocator, Certificate, EqualEffects, SensitivityWeighted, Weights,
};
use e2e_verify::{EndToEnd, EndToEndInputs, McSettings};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use study::{RequirementSource, Study};
use tt_core::OrientationAxis;
use tt_core::units::{RAD_PER_ARCMIN, rad_to_arcmin, rad_to_deg};
use tt_kinematics::LinearModel;
use tt_lab::error::{InputError, LabError, library, library_at};
use tt_lab::loaded::{requirement_problem, simulator};

fn per_angle<T: Into<Value>>(f: impl Fn(OrientationAxis) -> T) -> Value {
    let mut m = serde_json::Map::new();
    for a in OrientationAxis::ALL {
        m.insert(a.name().to_string(), f(a).into());
    }
    Value::Object(m)
}

fn deg3(r: &[Option<f64>; 3]) -> Value {
    per_angle(|a| r[a.index()].map(f64::to_degrees))
}

/// Bounds in arcmin keyed by error name, `null` for an unbounded error (the CLI's
/// `ArcminBounds`).
fn arcmin_bounds(names: &[&str], ub_rad: &[f64]) -> Value {
    let m: BTreeMap<String, Option<f64>> = names
        .iter()
        .zip(ub_rad)
        .map(|(n, u)| ((*n).to_string(), u.is_finite().then(|| rad_to_arcmin(*u))))
        .collect();
    json!(m)
}

/// `requirement --json` (eq 15-16): `study`, `reading`, `reading_formula`, `delta_r`,
/// `schedule_positions`, `orientation_requirement_deg`, `outputs`, `unconstrained_outputs`,
/// `note`, `given_requirement_deg`, `disagreement`.
pub fn requirement(s: &Study) -> Result<Value, LabError> {
    let resolved = tt_lab::loaded::requirement(s)?;
    let p = requirement_problem(s);
    let r = p.requirement();
    let outputs: Vec<Value> = p
        .calibration
        .outputs()
        .iter()
        .map(|o| {
            let b = r
                .as_ref()
                .ok()
                .and_then(|r| r.boxes().iter().find(|b| b.output() == o.output().name));
            json!({
                "name": o.output().name,
                "unit": o.output().unit,
                "accuracy": o.output().accuracy,
                "sensitive_angles": b.map(|b| (0..3)
                    .filter(|&j| b.half_rad()[j].is_some())
                    .map(|j| OrientationAxis::ALL[j].name())
                    .collect::<Vec<_>>()),
                "half_sides_deg": b.map(|b| deg3(&b.half_rad())),
            })
        })
        .collect();
    Ok(json!({
        "study": s.path,
        "reading": p.reading.to_string(),
        "reading_formula": p.reading.formula().to_string(),
        "delta_r": p.delta_r_kind.name(),
        "schedule_positions": p.calibration.schedule().len(),
        "orientation_requirement_deg": r.as_ref().ok().map(|r| deg3(&r.requirement().to_array())),
        "outputs": outputs,
        "unconstrained_outputs": r.as_ref().map(|r| r.unconstrained_outputs().to_vec()).unwrap_or_default(),
        "note": r.as_ref().err().map(ToString::to_string),
        "given_requirement_deg": match s.requirement {
            RequirementSource::Given { rad } => Some(deg3(&rad.map(Some))),
            RequirementSource::Computed => None,
        },
        "disagreement": resolved.disagreement,
    }))
}

fn certificate(s: &Study, c: &Certificate) -> Value {
    let joints = s.turntable.joint_names();
    per_angle(|a| {
        let x = c.get(a);
        let pose: BTreeMap<String, f64> = joints
            .iter()
            .zip(x.worst_pose_rad())
            .map(|(j, v)| ((*j).to_string(), rad_to_deg(*v)))
            .collect();
        json!({
            "requirement_deg": x.requirement_rad().map(rad_to_deg),
            "worst_case_deg": rad_to_deg(x.worst_case_rad()),
            "upper_bound_deg": rad_to_deg(x.upper_bound_rad()),
            "exact_search": x.exact(),
            "worst_pose_deg": pose,
            "share": x.share(),
            "requirement_active": x.requirement_active(),
            "lemma1": x.satisfied(),
        })
    })
}

/// `allocate --json` (the two-step allocation, full-range constraint): `study`,
/// `requirement_deg`, `lower_bounds_arcmin`, `constraint_form`, `safety_margin`,
/// `allocation_arcmin`, `unconstrained`, `objective`, `certificate`, `lemma1_full_range`,
/// `equal_effects_arcmin`, `equal_effects_objective`, and for the paper's table
/// `paper_table4_arcmin`, `paper_table4_objective` (the exact-chain check, the groups and the
/// angle-dependent extras are not bound yet).
pub fn allocate(s: &Study, safety_margin: f64) -> Result<Value, LabError> {
    if s.has_rate_steps() {
        return Err(InputError::new(
            format!("{}: key `calibration.rate_steps`", s.path),
            format!(
                "{}: use end_to_end()",
                tt_lab::loaded::STATIC_REQUIREMENT_NOTE
            ),
        )
        .into());
    }
    let req = tt_lab::loaded::requirement(s)?.used.ok_or_else(|| {
        InputError::new(
            format!("{}: key `requirement`", s.path),
            "the study has no orientation requirement: no output constrains a constant orientation error (see requirement()); give one in [requirement] or use end_to_end(), which allocates against the outputs' accuracies directly",
        )
    })?;
    let lib = |e| library(e, s);
    let problem = AllocationProblem::new(
        LinearModel::new(&s.turntable),
        req,
        s.lower_bounds_rad.clone(),
    )
    .map_err(lib)?
    .with_safety_margin(safety_margin)
    .map_err(lib)?;
    let ours = SensitivityWeighted::paper()
        .allocate(&problem)
        .map_err(lib)?;
    let equal = EqualEffects.allocate(&problem).map_err(lib)?;
    let names = s.turntable.rotation_error_names();
    let mut v = json!({
        "study": s.path,
        "requirement_deg": per_angle(|a| req.get(a).map(rad_to_deg)),
        "lower_bounds_arcmin": arcmin_bounds(&names, problem.lower_bounds_rad()),
        "constraint_form": "full-range",
        "safety_margin": safety_margin,
        "allocation_arcmin": arcmin_bounds(&names, ours.upper_bounds_rad()),
        "unconstrained": ours.unconstrained_names(),
        "objective": ours.objective_arcmin(),
        "objective_unit": "arcmin^-2 (J_psi + J_theta + J_gamma, W = 1/average sensitivity)",
        "certificate": certificate(s, ours.certificate()),
        "lemma1_full_range": ours.certificate().lemma1_holds(),
        "equal_effects_arcmin": arcmin_bounds(&names, equal.upper_bounds_rad()),
        "equal_effects_objective": equal.objective_arcmin(),
    });
    if s.turntable == tt_kinematics::paper::table3() {
        let t = alloc_opt::paper::table4_rad();
        let j = Weights::inverse_average_sensitivity(problem.model()).objective(&t)
            * RAD_PER_ARCMIN
            * RAD_PER_ARCMIN;
        v["paper_table4_arcmin"] = arcmin_bounds(&names, &t);
        v["paper_table4_objective"] = json!(j);
    }
    Ok(v)
}

fn objective_arcmin(j_rad: f64) -> f64 {
    j_rad * RAD_PER_ARCMIN * RAD_PER_ARCMIN
}

fn box_json(e2e: &EndToEnd, b: &e2e_verify::BoxAnswer) -> Value {
    let d = b.distribution();
    let meets = b.worst_case().meets(&e2e.accuracies());
    let worst: Vec<Value> = b
        .worst_case()
        .outputs()
        .iter()
        .map(|w| {
            json!({
                "output": e2e.calibration().outputs()[w.output()].output().name,
                "exact_at_vertex": w.exact_at_vertex(),
                "linear": w.linear_bound(),
                "second_order_bound": w.second_order_bound(),
                "position": w.position(),
            })
        })
        .collect();
    json!({
        "name": b.name(),
        "meets": meets.name(),
        "meets_text": meets.to_string(),
        "objective": objective_arcmin(b.objective()),
        "bounds_arcmin": arcmin_bounds(&e2e.turntable().rotation_error_names(), b.upper_bounds_rad()),
        "worst_case": worst,
        "yield": d.count().fraction(),
        "yield_interval_95": d.count().interval_95(),
        "meeting": d.count().meeting(),
        "samples": d.count().samples(),
        "seed": d.count().seed(),
        "max": d.max(),
    })
}

/// `end-to-end --json` (the direct allocation answer): `study`, `two_step_objective`, and
/// `readings[]` (the study's reading, then the user's) with `reading`, `boxes[]` (the
/// two-step box, Table 4 for the paper's table: `name`, `meets`, `objective`,
/// `bounds_arcmin`, `worst_case[]`, `yield`...), `direct` (`objective`, `bounds_arcmin`,
/// `unconstrained`, `box`), `yield_based` (`objective`, `target`, `bounds_arcmin`,
/// `remeasured`). Not bound yet: the noise part, the trade-off, angle-dependent and rate
/// extras, the decision.
pub fn end_to_end(
    s: &Study,
    samples: Option<u64>,
    seed: Option<u64>,
    yield_fraction: Option<f64>,
) -> Result<Value, LabError> {
    let e2e = simulator(s)?;
    let used = if s.has_rate_steps() {
        None
    } else {
        tt_lab::loaded::requirement(s)?.used
    };
    let mut inputs = EndToEndInputs::new(
        s.lower_bounds_rad.clone(),
        used,
        seed.unwrap_or(s.monte_carlo.seed),
    );
    inputs.samples = samples.unwrap_or(s.monte_carlo.samples);
    if let Some(y) = yield_fraction {
        inputs.yield_fraction = y;
    }
    if s.turntable == tt_kinematics::paper::table3() {
        inputs
            .extra_boxes
            .push(("Table 4".into(), alloc_opt::paper::table4_rad()));
    }
    let a = e2e_verify::answer(&e2e, &inputs).map_err(|e| library(e, s))?;
    let names = e2e.turntable().rotation_error_names();
    let readings: Vec<Value> = a
        .readings()
        .iter()
        .map(|r| {
            let sim = e2e.with_reading(r.reading()).unwrap_or_else(|_| e2e.clone());
            json!({
                "reading": r.reading().to_string(),
                "boxes": r.boxes().iter().map(|b| box_json(&sim, b)).collect::<Vec<_>>(),
                "direct": {
                    "objective": r.direct().objective_arcmin(),
                    "bounds_arcmin": arcmin_bounds(&names, r.direct().upper_bounds_rad()),
                    "unconstrained": r.direct().unconstrained().iter().map(|&j| names[j]).collect::<Vec<_>>(),
                    "no_bound_needed": r.direct().no_bound_needed(),
                    "box": box_json(&sim, r.direct_box()),
                },
                "direct_certified_note": r.direct_certified_note(),
                "yield_based": {
                    "objective": r.yield_based().objective_arcmin(),
                    "target": r.yield_based().target(),
                    "bounds_arcmin": arcmin_bounds(&names, r.yield_based().upper_bounds_rad()),
                    "verdict": r.yield_verdict().name(),
                    "remeasured": box_json(&sim, r.yield_box()),
                },
            })
        })
        .collect();
    Ok(json!({
        "study": s.path,
        "two_step_objective": a.two_step().map(|t| t.objective_arcmin()),
        "readings": readings,
    }))
}

/// `check-turntable --json` (the vendor check): the study's reading's check at the top level
/// (`reading`, `verdict`, `yield`, `yield_interval_95`, `samples`, `seed`, `outputs[]` with
/// `name`, `unit`, `accuracy`, `verdict`, `worst_case_linear`,
/// `worst_case_exact_at_vertex`, `second_order_bound`, `certified_bound`, `worst_position`,
/// `precision`, `meeting_fraction`, `monte_carlo_max`, `contributions[]`), `tolerances`,
/// `tolerances_arcmin` and `user_reading` (the same for the user's reading, `null` when it
/// is the study's), `decision` (the specifications' budgets and verdict). Not bound yet: the
/// noise split, the angle-dependent, compensated and rate-step sections.
pub fn check_turntable(
    s: &Study,
    tolerances: &std::path::Path,
    samples: Option<u64>,
    seed: Option<u64>,
) -> Result<Value, LabError> {
    let sheet = s.load_sheet(tolerances).map_err(InputError::from)?;
    let e2e = simulator(s)?;
    let settings = McSettings::new(
        samples.unwrap_or(s.monte_carlo.samples),
        seed.unwrap_or(s.monte_carlo.seed),
    );
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != calib_lsq::Reading::USER {
        sims.push(
            e2e.with_reading(calib_lsq::Reading::USER)
                .map_err(|e| library(e, s))?,
        );
    }
    let names = e2e.turntable().rotation_error_names();
    let mut checks = Vec::new();
    for sim in &sims {
        let c = sim
            .check_sheet(&sheet, &settings)
            .map_err(|e| library_at(e, s, sheet.source()))?;
        let d = c.distribution();
        let outputs: Vec<Value> = c
            .outputs()
            .iter()
            .map(|o| {
                let out = sim.calibration().outputs()[o.output()].output();
                let w = o.worst_case();
                let contributions: Vec<Value> = o
                    .contributions()
                    .iter()
                    .map(|k| {
                        json!({
                            "error": k.group().combination(&names),
                            "errors": k.group().names(&names),
                            "worst_case_share": k.worst_share(),
                            "variance_share": k.variance_share(),
                        })
                    })
                    .collect();
                json!({
                    "name": out.name,
                    "unit": out.unit,
                    "accuracy": o.accuracy(),
                    "verdict": o.verdict().name(),
                    "worst_case_linear": w.linear_bound(),
                    "worst_case_exact_at_vertex": w.exact_at_vertex(),
                    "second_order_bound": w.second_order_bound(),
                    "certified_bound": w.certified_bound(),
                    "worst_position": w.position(),
                    "precision": w.precision(),
                    "meeting_fraction": d.count().meeting_per_output()[o.output()] as f64 / d.count().samples() as f64,
                    "monte_carlo_max": d.worst()[o.output()].value(),
                    "contributions": contributions,
                })
            })
            .collect();
        checks.push(json!({
            "reading": sim.reading().to_string(),
            "verdict": c.verdict().name(),
            "yield": d.count().fraction(),
            "yield_interval_95": d.count().interval_95(),
            "samples": d.count().samples(),
            "seed": d.count().seed(),
            "outputs": outputs,
        }));
        if checks.len() == 1 {
            checks[0]["tolerances_arcmin"] = arcmin_bounds(&names, c.upper_bounds_rad());
        }
    }
    let user = checks.get(1).cloned();
    let mut v = checks.swap_remove(0);
    v["tolerances"] = json!(sheet.source());
    v["user_reading"] = json!(user);
    v["decision"] = decision(s, &e2e, sheet.upper_bounds_rad())?;
    Ok(v)
}

/// The decision against the study's specifications (issue 34) for the tolerances `ub_rad`:
/// the `decision` of `check-turntable --json` (`rule`, `meets`, `tolerance_distribution`,
/// `specifications[]` with each GUM budget: `quantity`, `unit`, `limit`, `coverage`,
/// `combined_standard_uncertainty`, `dof_eff`, `coverage_factor`, `expanded`, `ratio`,
/// `meets`, `noise_modelled`, `unbounded`, `position`, `budget[]`). Without specifications:
/// the accuracy rule, `meets` `null`, no specification.
fn decision(s: &Study, e2e: &EndToEnd, ub_rad: &[f64]) -> Result<Value, LabError> {
    use e2e_verify::budget::{ACCURACY_RULE, EvaluatedAt, PLAN_RULE};
    let law = s.uncertainty.tolerance_distribution;
    if s.specifications.is_empty() {
        return Ok(json!({
            "rule": ACCURACY_RULE,
            "meets": null,
            "tolerance_distribution": law.name(),
            "specifications": [],
        }));
    }
    let v = e2e
        .plan_verdict(
            &s.specifications,
            ub_rad,
            |n, a| law.input(n, a),
            &s.noise,
            s.timing.as_ref(),
        )
        .map_err(|e| library(e, s))?;
    let finite = |x: f64| x.is_finite().then_some(x);
    let specifications: Vec<Value> = v
        .budgets()
        .iter()
        .zip(&s.specifications)
        .map(|(b, sp)| {
            let f = sp.to_written();
            let o = b.output();
            let rows: Vec<Value> = b
                .result()
                .rows()
                .iter()
                .zip(o.sensitivities().iter().zip(o.contributions()))
                .map(|(r, (c, u))| {
                    json!({
                        "name": r.name(),
                        "distribution": r.distribution(),
                        "standard_uncertainty": r.standard_uncertainty(),
                        "sensitivity": c * f,
                        "contribution": u.abs() * f,
                        "dof": finite(r.dof()),
                    })
                })
                .collect();
            json!({
                "quantity": sp.label(&s.sensor),
                "unit": sp.unit().to_string(),
                "limit": sp.written_limit(),
                "coverage": sp.coverage(),
                "combined_standard_uncertainty": o.combined() * f,
                "dof_eff": finite(o.dof_eff()),
                "coverage_factor": o.coverage_factor(),
                "expanded": o.expanded() * f,
                "ratio": b.check().ratio(),
                "meets": v.meets(b.spec()),
                "noise_modelled": b.noise_modelled(),
                "unbounded": v.unbounded()[b.spec()],
                "position": match b.at() {
                    EvaluatedAt::Position(i) => Some(i),
                    _ => None,
                },
                "budget": rows,
            })
        })
        .collect();
    Ok(json!({
        "rule": PLAN_RULE,
        "meets": v.meets_all(),
        "tolerance_distribution": law.name(),
        "specifications": specifications,
    }))
}

/// The GUM budget and decision of every specification of the study (issue 34) over a
/// tolerance sheet's box: `check-turntable --json`'s `decision`.
pub fn specification_budgets(s: &Study, tolerances: &std::path::Path) -> Result<Value, LabError> {
    let sheet = s.load_sheet(tolerances).map_err(InputError::from)?;
    decision(s, &simulator(s)?, sheet.upper_bounds_rad())
}
