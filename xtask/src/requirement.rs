//! `cargo xtask requirement [--json] [--reading R] [--all-readings]`: the orientation
//! requirement of eq 15-16 (paper §2.2-2.3, Figure 5).
//!
//! Prints $I_\psi$, $I_\theta$, $I_\gamma$ in degrees for the paper's inputs (Table 1,
//! $\omega_m$ = 0.01 deg/h) with this project's defaults for what the paper leaves open
//! (Harbin 45.75 deg N, WGS-84 earth rate, the default 32-position schedule, the reading of
//! eq 13 that reproduces the paper, the small-angle $\Delta\mathbf R$ of eq 7).
//!
//! `--json` prints one object:
//! `{"reading": "intended/beta1/printed", "latitude_deg": 45.75, "orientation_requirement_deg":
//! {"psi": .., "theta": .., "gamma": ..}, ...}` with further keys (inputs and both planes'
//! rectangles). All inputs come from the study file (`--study FILE`, default the paper's
//! `studies/gyrowheel-2017.toml`); `--reading` overrides the study's reading of eq 13.

use crate::InputError;
use crate::study::Study;
use anyhow::Result;
use calib_lsq::{Reading, RequirementProblem};
use clap::Parser;
use gw_model::units::{rad_per_s_to_deg_per_h, rad_to_deg};
use serde_json::json;

/// Arguments of `requirement`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file (default: `studies/gyrowheel-2017.toml`, the paper's inputs).
    #[arg(long)]
    pub study: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Reading of eq 13 as `outputs/estimate/form` (e.g. `actual/beta1/printed`); default: the
    /// one that reproduces the paper, `intended/beta1/printed`.
    #[arg(long)]
    pub reading: Option<String>,
    /// Evaluate every reading of eq 13 side by side (slower: about 10 s optimised).
    #[arg(long)]
    pub all_readings: bool,
}

/// The JSON object printed by `--json` for one problem.
///
/// # Errors
/// As [`RequirementProblem::requirement`].
pub fn requirement_json(
    problem: &RequirementProblem,
) -> Result<serde_json::Value, calib_lsq::CalibError> {
    let r = problem.requirement()?;
    let [psi, theta, gamma] = r.deg();
    Ok(json!({
        "reading": problem.reading.to_string(),
        "reading_formula": problem.reading.formula(),
        "latitude_deg": problem.site.latitude_deg(),
        "earth_rate_rad_per_s": problem.site.earth_rate_rad_per_s(),
        "omega_m_deg_per_h": rad_per_s_to_deg_per_h(problem.omega_m_rad_per_s),
        "delta_r": problem.delta_r_kind.name(),
        "schedule_positions": problem.schedule.len(),
        "orientation_requirement_deg": {"psi": psi, "theta": theta, "gamma": gamma},
        "planes_deg": {
            "x": {"delta_psi": rad_to_deg(r.x_plane.half_u_rad), "delta_theta": rad_to_deg(r.x_plane.half_v_rad)},
            "y": {"delta_theta": rad_to_deg(r.y_plane.half_u_rad), "delta_gamma": rad_to_deg(r.y_plane.half_v_rad)},
        },
        "theta_rule": "min of the x-plane and y-plane half-sides",
    }))
}

/// Run the command.
pub fn run(args: &Args) -> Result<()> {
    let study = Study::load_or_paper(args.study.as_deref())?;
    let mut problem = study.requirement_problem();
    if let Some(r) = &args.reading {
        problem.reading = r
            .parse()
            .map_err(|e: calib_lsq::CalibError| InputError::new("--reading", e.to_string()))?;
    }
    if args.all_readings {
        let mut rows = Vec::new();
        for reading in Reading::all() {
            let p = RequirementProblem {
                reading,
                ..problem.clone()
            };
            let row = match requirement_json(&p) {
                Ok(v) => v,
                Err(calib_lsq::CalibError::Unbounded { .. }) => json!({
                    "reading": reading.to_string(),
                    "reading_formula": reading.formula(),
                    "orientation_requirement_deg": null,
                    "note": "unbounded: this reading gives no rate error in some direction",
                }),
                Err(e) => return Err(e.into()),
            };
            rows.push(row);
        }
        if args.json {
            println!("{}", serde_json::to_string_pretty(&rows)?);
        } else {
            println!("reading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg)");
            for row in &rows {
                let req = &row["orientation_requirement_deg"];
                let f = |k: &str| {
                    req[k]
                        .as_f64()
                        .map_or_else(|| "unbounded".to_string(), |v| format!("{v:.7}"))
                };
                println!(
                    "{} | {} | {} | {} | {}",
                    row["reading"].as_str().unwrap_or_default(),
                    row["reading_formula"].as_str().unwrap_or_default(),
                    f("psi"),
                    f("theta"),
                    f("gamma")
                );
            }
        }
        return Ok(());
    }
    let v = requirement_json(&problem)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let req = &v["orientation_requirement_deg"];
        println!(
            "orientation requirement (eq 15-16), study {}, omega_m = {} deg/h, latitude {} deg, {} positions, {} Delta-R",
            study.file.name,
            rad_per_s_to_deg_per_h(problem.omega_m_rad_per_s),
            problem.site.latitude_deg(),
            problem.schedule.len(),
            problem.delta_r_kind.name()
        );
        println!(
            "reading: {} ({})",
            problem.reading,
            problem.reading.formula()
        );
        for k in ["psi", "theta", "gamma"] {
            let d = req[k].as_f64().unwrap_or(f64::NAN);
            println!("I_{k:<5} = {d:.9} deg  (rounded {d:.3} deg)");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's study file builds exactly the library's paper problem (Table 1, Harbin,
    /// WGS-84, the default schedule, the paper's reading, eq 7).
    #[test]
    fn paper_study_builds_the_paper_problem() {
        assert_eq!(
            Study::paper().unwrap().requirement_problem(),
            RequirementProblem::paper()
        );
    }

    /// A reading flag that does not parse is an input error naming the flag.
    #[test]
    fn bad_reading_flag_names_the_flag() {
        let args = Args {
            study: None,
            json: true,
            reading: Some("sideways".into()),
            all_readings: false,
        };
        let e = run(&args).unwrap_err();
        let e = e.downcast_ref::<InputError>().expect("input error");
        assert_eq!(e.location, "--reading");
    }
}
