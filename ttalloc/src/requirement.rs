//! `cargo xtask requirement [--study FILE] [--json] [--reading R | --all-readings]`: the
//! orientation requirement of eq 15-16 (paper §2.2-2.3, Figure 5) for the study's sensor.
//!
//! `--json` prints one object: `{"study", "reading", "reading_formula", "delta_r",
//! "orientation_requirement_deg": {"psi", "theta", "gamma"} (null where no output constrains
//! the angle), "outputs": [{"name", "accuracy", "unit", "sensitive_angles", "half_sides_deg"}],
//! "unconstrained_outputs": [...], "given_requirement_deg", "note"}`.

use crate::InputError;
use crate::loaded as st;
use anyhow::Result;
use calib_lsq::{CalibError, OrientationRequirement, Reading, RequirementProblem};
use clap::Parser;
use serde::Serialize;
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

use crate::json::{PerAngle, deg3};

/// One output's requirement box.
#[derive(Debug, Serialize)]
pub struct RequirementOutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// The angles it is sensitive to (`null` when the requirement failed).
    sensitive_angles: Option<Vec<&'static str>>,
    /// The half sides of its largest box, degrees (`null` where unconstrained, or when the
    /// requirement failed).
    half_sides_deg: Option<PerAngle<Option<f64>>>,
}

/// The requirement under one reading (`requirement --all-readings --json` prints a list).
#[derive(Debug, Serialize)]
pub struct RequirementJson<'a> {
    /// The reading of eq 13.
    reading: String,
    /// Its formula.
    reading_formula: String,
    /// The Delta-R kind.
    delta_r: String,
    /// Test positions.
    schedule_positions: usize,
    /// I_psi, I_theta, I_gamma, degrees (`null` where no output constrains the angle; the
    /// whole `null` when the requirement failed, `note`).
    orientation_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// Every output's box.
    outputs: Vec<RequirementOutputJson<'a>>,
    /// The outputs that constrain no angle.
    unconstrained_outputs: Vec<String>,
    /// Why there is no requirement, else `null`.
    note: Option<String>,
}

/// The view of one requirement.
#[must_use]
pub fn requirement_json<'a>(
    p: &'a RequirementProblem,
    r: &Result<OrientationRequirement, CalibError>,
) -> RequirementJson<'a> {
    RequirementJson {
        reading: p.reading.to_string(),
        reading_formula: p.reading.formula().to_string(),
        delta_r: p.delta_r_kind.name().to_string(),
        schedule_positions: p.calibration.schedule().len(),
        orientation_requirement_deg: r.as_ref().ok().map(|r| deg3(&r.requirement().to_array())),
        outputs: p
            .calibration
            .outputs()
            .iter()
            .map(|o| {
                let b = r
                    .as_ref()
                    .ok()
                    .and_then(|r| r.boxes().iter().find(|b| b.output() == o.output().name));
                RequirementOutputJson {
                    name: &o.output().name,
                    unit: &o.output().unit,
                    accuracy: o.output().accuracy,
                    sensitive_angles: b.map(|b| {
                        (0..3)
                            .filter(|&j| b.half_rad()[j].is_some())
                            .map(|j| OrientationAxis::ALL[j].name())
                            .collect()
                    }),
                    half_sides_deg: b.map(|b| deg3(&b.half_rad())),
                }
            })
            .collect(),
        unconstrained_outputs: r
            .as_ref()
            .map(|r| r.unconstrained_outputs().to_vec())
            .unwrap_or_default(),
        note: r.as_ref().err().map(ToString::to_string),
    }
}

/// `requirement --json`: the study's requirement under its reading (or `--reading`).
#[derive(Debug, Serialize)]
pub struct StudyRequirementJson<'a> {
    /// The requirement (its keys at the top level).
    #[serde(flatten)]
    requirement: RequirementJson<'a>,
    /// The study's path.
    study: &'a str,
    /// The requirement the study gives, degrees (`null`: computed).
    given_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// How the given requirement disagrees with the computed one, else `null`.
    disagreement: Option<String>,
}

fn text(r: &Result<OrientationRequirement, CalibError>) -> String {
    let mut s = String::new();
    match r {
        Ok(r) => {
            for axis in OrientationAxis::ALL {
                let name = axis.name();
                match r.requirement().get(axis) {
                    Some(v) => s.push_str(&format!(
                        "I_{name:<5} = {} deg\n",
                        study::fmt::sig(v.to_degrees(), 8)
                    )),
                    None => s.push_str(&format!("I_{name:<5} : none (no output constrains it)\n")),
                }
            }
            for b in r.boxes() {
                let sides: Vec<String> = (0..3)
                    .filter_map(|j| {
                        b.half_rad()[j].map(|h| {
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
                    b.output(),
                    sides.join(", ")
                ));
            }
            for o in r.unconstrained_outputs() {
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
        let problems: Vec<(RequirementProblem, _)> = Reading::all()
            .into_iter()
            .map(|reading| {
                let p = RequirementProblem {
                    reading,
                    ..problem.clone()
                };
                let r = p.requirement();
                (p, r)
            })
            .collect();
        let rows: Vec<(Reading, RequirementJson<'_>)> = problems
            .iter()
            .map(|(p, r)| (p.reading, requirement_json(p, r)))
            .collect();
        if args.json {
            let v: Vec<&RequirementJson<'_>> = rows.iter().map(|(_, v)| v).collect();
            crate::json::print(&v)?;
        } else {
            let mut t = format!(
                "study {} ({})\nreading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg)\n",
                s.name, s.path
            );
            for (reading, v) in rows {
                let f = |a: OrientationAxis| {
                    v.orientation_requirement_deg
                        .as_ref()
                        .and_then(|req| *req.get(a))
                        .filter(|d| d.is_finite())
                        .map_or_else(|| "-".to_string(), |d| study::fmt::sig(d, 7))
                };
                let [psi, theta, gamma] = OrientationAxis::ALL.map(f);
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
        crate::json::print(&StudyRequirementJson {
            requirement: requirement_json(&problem, &r),
            study: &s.path,
            given_requirement_deg: given.map(|g| deg3(&g)),
            disagreement: resolved.disagreement,
        })?;
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
