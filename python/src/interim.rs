//! The study-level questions the Python functions answer, on the library crates directly, until
//! the study-level library (`tt-lab`, issue 33 section 1) answers them: one function per
//! question, each returning the answer as the command line's `--json` prints it (the same
//! keys, a subset where noted). When `tt-lab` lands, each function here is replaced by the
//! `tt-lab` call of the same name and its answer's serialisation; the Python layer
//! (`lib.rs`) does not change.
//!
//! Nothing here decides anything: every number is a library call's; this module resolves the
//! study's inputs the way the command line does (`ttalloc/src/loaded.rs`, `allocate.rs`,
//! `end_to_end.rs`, `check_turntable.rs`) and names the keys.

use alloc_opt::{
    AllocationProblem, Allocator, Certificate, EqualEffects, Requirement, SensitivityWeighted,
    Weights,
};
use calib_lsq::RequirementProblem;
use e2e_verify::{EndToEnd, EndToEndInputs, McSettings};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use study::{RequirementSource, Study};
use tt_core::units::{RAD_PER_ARCMIN, rad_to_arcmin, rad_to_deg};
use tt_core::{ErrorClass, OrientationAxis, Pose};
use tt_kinematics::LinearModel;

/// An error of a question: the input's (a location as the command line names it, and why) or
/// the library's own failure.
#[derive(Debug)]
pub enum Failure {
    /// The input is wrong: where (a file and key, a keyword argument) and why.
    Input {
        /// Where.
        location: String,
        /// Why.
        reason: String,
    },
    /// The computation failed (not the input's fault).
    Internal(String),
}

impl From<study::StudyError> for Failure {
    fn from(e: study::StudyError) -> Self {
        Self::Input {
            location: e.location,
            reason: e.reason,
        }
    }
}

/// A library error located the command line's way: a field that is a command-line flag is
/// named by the keyword argument of the same name (`samples`, `seed`, `yield_fraction`), the
/// lower bounds by the study key, anything else by `at` (the study file, a tolerance file).
pub fn library<E: ErrorClass + std::fmt::Display>(e: E, s: &Study, at: &str) -> Failure {
    match e.input_field() {
        Some(field) => {
            let location = match field {
                "samples" | "seed" | "yield_fraction" | "safety_margin" => field.to_string(),
                f if f == "lower_bounds" || f.starts_with("lower_bounds.") => {
                    format!("{}: key `allocation.lower_bounds_arcmin`", s.path)
                }
                _ => at.to_string(),
            };
            Failure::Input {
                location,
                reason: e.to_string(),
            }
        }
        None => Failure::Internal(e.to_string()),
    }
}

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

/// The study's requirement as the command line resolves it: the given one, else the
/// computed one (`None`: no output constrains an angle).
fn used_requirement(s: &Study) -> Result<Option<Requirement>, Failure> {
    match s.requirement {
        RequirementSource::Given { rad } => Requirement::new(rad[0], rad[1], rad[2])
            .map(Some)
            .map_err(|e| library(e, s, &format!("{}: key `requirement`", s.path))),
        RequirementSource::Computed => Ok(requirement_problem(s)
            .requirement()
            .ok()
            .map(|r| r.requirement())),
    }
}

fn requirement_problem(s: &Study) -> RequirementProblem {
    RequirementProblem::new(s.calibration.clone(), s.reading, s.delta_r_kind)
}

/// `requirement --json` (eq 15-16): `study`, `reading`, `reading_formula`, `delta_r`,
/// `schedule_positions`, `orientation_requirement_deg`, `outputs`, `unconstrained_outputs`,
/// `note`, `given_requirement_deg`.
pub fn requirement(s: &Study) -> Result<Value, Failure> {
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
pub fn allocate(s: &Study, safety_margin: f64) -> Result<Value, Failure> {
    if s.has_rate_steps() {
        return Err(Failure::Input {
            location: format!("{}: key `calibration.rate_steps`", s.path),
            reason: "the two-step allocation is not made for a study with rate steps (the orientation requirement is a static concept): use end_to_end()".into(),
        });
    }
    let req = used_requirement(s)?.ok_or_else(|| Failure::Input {
        location: format!("{}: key `requirement`", s.path),
        reason: "the study has no orientation requirement: no output constrains a constant orientation error (see requirement()); give one in [requirement] or use end_to_end(), which allocates against the outputs' accuracies directly".into(),
    })?;
    let lib = |e| library(e, s, &s.path);
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

/// The end-to-end simulator of a study (its schedule's poses, its reading).
pub fn simulator(s: &Study) -> Result<EndToEnd, Failure> {
    let poses = s
        .schedule_angles_deg()
        .iter()
        .map(|p| Pose::from_deg(p).map_err(|e| library(e, s, &s.path)))
        .collect::<Result<Vec<_>, _>>()?;
    EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading)
        .map_err(|e| library(e, s, &s.path))
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
) -> Result<Value, Failure> {
    let e2e = simulator(s)?;
    let used = if s.has_rate_steps() {
        None
    } else {
        used_requirement(s)?
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
    let a = e2e_verify::answer(&e2e, &inputs).map_err(|e| library(e, s, &s.path))?;
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
/// is the study's). Not bound yet: the noise split, the angle-dependent, compensated and
/// rate-step sections, the decision.
pub fn check_turntable(
    s: &Study,
    tolerances: &std::path::Path,
    samples: Option<u64>,
    seed: Option<u64>,
) -> Result<Value, Failure> {
    let sheet = s.load_sheet(tolerances)?;
    let e2e = simulator(s)?;
    let settings = McSettings::new(
        samples.unwrap_or(s.monte_carlo.samples),
        seed.unwrap_or(s.monte_carlo.seed),
    );
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != calib_lsq::Reading::USER {
        sims.push(
            e2e.with_reading(calib_lsq::Reading::USER)
                .map_err(|e| library(e, s, &s.path))?,
        );
    }
    let names = e2e.turntable().rotation_error_names();
    let mut checks = Vec::new();
    for sim in &sims {
        let c = sim
            .check_sheet(&sheet, &settings)
            .map_err(|e| library(e, s, sheet.source()))?;
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
    Ok(v)
}
