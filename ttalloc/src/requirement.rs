//! `cargo xtask requirement [--study FILE] [--json] [--reading R | --all-readings]`: the
//! orientation requirement of eq 15-16 (paper §2.2-2.3, Figure 5) for the study's sensor.
//!
//! `--json` prints one object: `{"study", "reading", "reading_formula", "delta_r",
//! "orientation_requirement_deg": {"psi", "theta", "gamma"} (null where no output constrains
//! the angle), "outputs": [{"name", "accuracy", "unit", "sensitive_angles", "half_sides_deg"}],
//! "unconstrained_outputs": [...], "given_requirement_deg", "note"}`.

use crate::InputError;
use crate::study as st;
use anyhow::Result;
use calib_lsq::{CalibError, OrientationRequirement, Reading, RequirementProblem};
use clap::Parser;
use serde_json::{Value, json};
use study::fmt::num;
use tt_core::OrientationAxis;

/// Arguments of `requirement`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub study: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Reading of eq 13 as `outputs/estimate/form` (e.g. `actual/beta1/printed`); default:
    /// the study's.
    #[arg(long)]
    pub reading: Option<String>,
    /// Evaluate every reading of eq 13 side by side (not with `--reading`).
    #[arg(long, conflicts_with = "reading")]
    pub all_readings: bool,
}

use crate::out::deg3;

/// The JSON object of one requirement.
#[must_use]
pub fn requirement_json(
    p: &RequirementProblem,
    r: &Result<OrientationRequirement, CalibError>,
) -> Value {
    let outputs: Vec<Value> = p
        .calibration
        .outputs()
        .iter()
        .map(|o| {
            let b = r.as_ref().ok().and_then(|r| r.boxes.iter().find(|b| b.output == o.output().name));
            json!({
                "name": o.output().name,
                "unit": o.output().unit,
                "accuracy": o.output().accuracy,
                "sensitive_angles": b.map(|b| (0..3).filter(|&j| b.half_rad[j].is_some()).map(|j| OrientationAxis::ALL[j].name()).collect::<Vec<_>>()),
                "half_sides_deg": b.map(|b| deg3(&b.half_rad)),
            })
        })
        .collect();
    json!({
        "reading": p.reading.to_string(),
        "reading_formula": p.reading.formula(),
        "delta_r": p.delta_r_kind.name(),
        "schedule_positions": p.calibration.schedule().len(),
        "orientation_requirement_deg": r.as_ref().ok().map(|r| deg3(&r.requirement.to_array())),
        "outputs": outputs,
        "unconstrained_outputs": r.as_ref().map(|r| r.unconstrained_outputs.clone()).unwrap_or_default(),
        "note": r.as_ref().err().map(ToString::to_string),
    })
}

fn text(r: &Result<OrientationRequirement, CalibError>) -> String {
    let mut s = String::new();
    match r {
        Ok(r) => {
            for axis in OrientationAxis::ALL {
                let name = axis.name();
                match r.requirement.get(axis) {
                    Some(v) => s.push_str(&format!(
                        "I_{name:<5} = {} deg\n",
                        study::fmt::sig(v.to_degrees(), 8)
                    )),
                    None => s.push_str(&format!("I_{name:<5} : none (no output constrains it)\n")),
                }
            }
            for b in &r.boxes {
                let sides: Vec<String> = (0..3)
                    .filter_map(|j| {
                        b.half_rad[j].map(|h| {
                            format!(
                                "{} {} deg",
                                OrientationAxis::ALL[j].name(),
                                num(h.to_degrees())
                            )
                        })
                    })
                    .collect();
                s.push_str(&format!(
                    "  output {}: largest box {}\n",
                    b.output,
                    sides.join(", ")
                ));
            }
            for o in &r.unconstrained_outputs {
                s.push_str(&format!(
                    "  output {o}: no requirement (it meets its accuracy under every constant orientation error; only the end-to-end allocation bounds the turntable for it)\n"
                ));
            }
        }
        Err(e) => s.push_str(&format!("no requirement: {e}\n")),
    }
    s
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let s = st::load(args.study.as_deref())?;
    let mut problem = st::requirement_problem(&s);
    if let Some(r) = &args.reading {
        problem.reading = r
            .parse()
            .map_err(|e: CalibError| InputError::new("--reading", e.to_string()))?;
    }
    let resolved = st::requirement(&s)?;
    let given = match s.requirement {
        study::RequirementSource::Given { rad } => Some(rad.map(Some)),
        study::RequirementSource::Computed => None,
    };
    if args.all_readings {
        let rows: Vec<(Reading, Value)> = Reading::all()
            .into_iter()
            .map(|reading| {
                let p = RequirementProblem {
                    reading,
                    ..problem.clone()
                };
                let r = p.requirement();
                (reading, requirement_json(&p, &r))
            })
            .collect();
        if args.json {
            let v: Vec<Value> = rows.into_iter().map(|(_, v)| v).collect();
            crate::out::print(&(serde_json::to_string_pretty(&v)? + "\n"))?;
        } else {
            let mut t = format!(
                "study {} ({})\nreading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg)\n",
                s.name, s.path
            );
            for (reading, v) in rows {
                let req = &v["orientation_requirement_deg"];
                let f = |k: &str| {
                    req[k]
                        .as_f64()
                        .map_or_else(|| "-".to_string(), |d| study::fmt::sig(d, 7))
                };
                let [psi, theta, gamma] = OrientationAxis::ALL.map(|a| f(a.name()));
                t.push_str(&format!(
                    "{reading} | {} | {psi} | {theta} | {gamma}\n",
                    reading.formula(),
                ));
            }
            crate::out::print(&t)?;
        }
        return Ok(());
    }
    let r = problem.requirement();
    if args.json {
        let mut v = requirement_json(&problem, &r);
        v["study"] = json!(s.path);
        v["given_requirement_deg"] = given.map_or(Value::Null, |g| deg3(&g));
        v["disagreement"] = json!(resolved.disagreement);
        crate::out::print(&(serde_json::to_string_pretty(&v)? + "\n"))?;
    } else {
        let mut t = format!(
            "orientation requirement (eq 15-16), study {} ({}), {} positions, {} Delta-R\nreading: {} ({})\n",
            s.name,
            s.path,
            problem.calibration.schedule().len(),
            problem.delta_r_kind.name(),
            problem.reading,
            problem.reading.formula()
        );
        for o in problem.calibration.outputs() {
            t.push_str(&format!(
                "  output {}: accuracy {} {}\n",
                o.output().name,
                num(o.output().accuracy),
                o.output().unit
            ));
        }
        t.push_str(&text(&r));
        if let Some(d) = &resolved.disagreement {
            t.push_str(d);
            t.push('\n');
        }
        crate::out::print(&t)?;
    }
    Ok(())
}
