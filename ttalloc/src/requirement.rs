//! `cargo xtask requirement [--study FILE] [--json] [--reading R | --all-readings]`: the
//! orientation requirement of eq 15-16 (paper §2.2-2.3, Figure 5) for the study's sensor.
//!
//! `--json` prints one object: `{"study", "reading", "reading_formula", "delta_r",
//! "orientation_requirement_deg": {"psi", "theta", "gamma"} (null where no output constrains
//! the angle), "outputs": [{"name", "accuracy", "unit", "sensitive_angles", "half_sides_deg"}],
//! "unconstrained_outputs": [...], "given_requirement_deg", "note"}`.

use crate::InputError;
use anyhow::Result;
use calib_lsq::{CalibError, OrientationRequirement};
use clap::Parser;
use tt_core::OrientationAxis;
use tt_core::human::num;
use tt_lab::requirement::{Options, RequirementJson};

/// Arguments of `requirement`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// `--study` (default: the paper's) and `--json`.
    #[command(flatten)]
    pub input: crate::args::StudyJson,
    /// Reading of eq 13 as `outputs/estimate/form` (e.g. `actual/beta1/printed`); default:
    /// the study's.
    #[arg(long)]
    pub reading: Option<String>,
    /// Evaluate every reading of eq 13 side by side (not with `--reading`).
    #[arg(long, conflicts_with = "reading")]
    pub all_readings: bool,
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
                        tt_core::human::sig(v.to_degrees(), 8)
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
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = args.input.study.load()?;
    let reading = match &args.reading {
        Some(r) => Some(
            r.parse()
                .map_err(|e: CalibError| InputError::new("--reading", e.to_string()))?,
        ),
        None => None,
    };
    let opts = Options::default().reading(reading);
    if args.all_readings {
        let all = tt_lab::requirement::all_readings(&s, &opts).map_err(crate::input::lab)?;
        let rows: Vec<RequirementJson<'_>> = all.iter().map(|r| r.view()).collect();
        if args.input.json {
            crate::json::print(&rows)?;
        } else {
            let mut t = format!(
                "study {} ({})\nreading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg)\n",
                s.name, s.path
            );
            for (r, v) in all.iter().zip(&rows) {
                let reading = r.reading();
                let f = |a: OrientationAxis| {
                    v.orientation_requirement_deg()
                        .and_then(|req| *req.get(a))
                        .filter(|d| d.is_finite())
                        .map_or_else(|| "-".to_string(), |d| tt_core::human::sig(d, 7))
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
    let answer = tt_lab::requirement::requirement(&s, &opts).map_err(crate::input::lab)?;
    if args.input.json {
        crate::json::print(&answer.view())?;
    } else {
        let problem = answer.computed().problem();
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
        t.push_str(&text(answer.computed().result()));
        if let Some(d) = answer.disagreement() {
            t.push_str(d);
            t.push('\n');
        }
        crate::out::print(&t)?;
    }
    Ok(())
}
