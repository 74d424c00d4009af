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
//! rectangles). All inputs live in [`RequirementInputs`], which a study file can fill.

use crate::InputError;
use anyhow::Result;
use calib_lsq::{Reading, RequirementProblem, Schedule};
use clap::Parser;
use gw_model::units::{deg_per_h_to_rad_per_s, rad_to_deg};
use gw_model::{DeltaRKind, DriftCoefficients, Site};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// Arguments of `requirement`.
#[derive(Debug, Parser)]
pub struct Args {
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

/// Everything the requirement depends on, in the units of study files; defaults are the
/// paper's inputs plus this project's documented choices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RequirementInputs {
    /// Test-site latitude, deg north (default Harbin 45.75).
    pub latitude_deg: f64,
    /// Earth rotation rate, rad/s (default WGS-84 7.2921159e-5).
    pub earth_rate_rad_per_s: f64,
    /// Required calibration accuracy $\omega_m$, deg/h (paper: 0.01).
    pub omega_m_deg_per_h: f64,
    /// $x$-axis coefficients in eq 1 order, deg/h, deg/h/g, deg/h/g^2 (default Table 1).
    pub coefficients_x_deg_per_h: [f64; 7],
    /// $y$-axis coefficients in eq 1 order (default Table 1).
    pub coefficients_y_deg_per_h: [f64; 7],
    /// Calibration positions `[phi1_deg, phi2_deg]` (default: the 4 x 8 grid of
    /// `Schedule::paper_default`).
    pub schedule_deg: Vec<[f64; 2]>,
    /// Reading of eq 13, `outputs/estimate/form`.
    pub reading: String,
    /// `small-angle` (eq 7, default) or `exact`.
    pub delta_r: String,
}

impl Default for RequirementInputs {
    fn default() -> Self {
        let site = Site::paper_default();
        Self {
            latitude_deg: site.latitude_deg(),
            earth_rate_rad_per_s: site.earth_rate_rad_per_s(),
            omega_m_deg_per_h: calib_lsq::PAPER_OMEGA_M_DEG_PER_H,
            coefficients_x_deg_per_h: gw_model::TABLE_1_X_DEG_PER_H,
            coefficients_y_deg_per_h: gw_model::TABLE_1_Y_DEG_PER_H,
            schedule_deg: Schedule::paper_default()
                .positions()
                .iter()
                .map(|p| [p.phi_1_deg(), p.phi_2_deg()])
                .collect(),
            reading: Reading::PAPER.to_string(),
            delta_r: DeltaRKind::SmallAngle.name().to_string(),
        }
    }
}

impl RequirementInputs {
    /// Build the library problem, naming the offending key on bad input.
    ///
    /// # Errors
    /// [`InputError`] naming the key (`latitude_deg`, `schedule_deg`, `reading`, ...).
    pub fn problem(&self) -> Result<RequirementProblem, InputError> {
        let bad = |key: &str, e: &dyn std::fmt::Display| InputError::new(key, e.to_string());
        let site = Site::from_deg(self.latitude_deg, self.earth_rate_rad_per_s)
            .map_err(|e| bad("latitude_deg/earth_rate_rad_per_s", &e))?;
        let coefficients = DriftCoefficients::from_deg_per_h(
            self.coefficients_x_deg_per_h,
            self.coefficients_y_deg_per_h,
        )
        .map_err(|e| bad("coefficients", &e))?;
        let pairs: Vec<(f64, f64)> = self.schedule_deg.iter().map(|p| (p[0], p[1])).collect();
        let schedule = Schedule::from_deg(&pairs).map_err(|e| bad("schedule_deg", &e))?;
        let reading: Reading = self.reading.parse().map_err(|e| bad("reading", &e))?;
        let delta_r_kind = match self.delta_r.as_str() {
            "small-angle" => DeltaRKind::SmallAngle,
            "exact" => DeltaRKind::Exact,
            other => {
                return Err(InputError::new(
                    "delta_r",
                    format!("expected `small-angle` or `exact`, got `{other}`"),
                ));
            }
        };
        let problem = RequirementProblem {
            coefficients,
            site,
            schedule,
            omega_m_rad_per_s: deg_per_h_to_rad_per_s(1.0),
            reading,
            delta_r_kind,
        };
        problem
            .with_omega_m_deg_per_h(self.omega_m_deg_per_h)
            .map_err(|e| bad("omega_m_deg_per_h", &e))
    }
}

/// The JSON object printed by `--json` for one problem.
///
/// # Errors
/// As [`RequirementProblem::requirement`].
pub fn requirement_json(
    inputs: &RequirementInputs,
    problem: &RequirementProblem,
) -> Result<serde_json::Value, calib_lsq::CalibError> {
    let r = problem.requirement()?;
    let [psi, theta, gamma] = r.deg();
    Ok(json!({
        "reading": problem.reading.to_string(),
        "reading_formula": problem.reading.formula(),
        "latitude_deg": problem.site.latitude_deg(),
        "earth_rate_rad_per_s": problem.site.earth_rate_rad_per_s(),
        "omega_m_deg_per_h": inputs.omega_m_deg_per_h,
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
    let mut inputs = RequirementInputs::default();
    if let Some(r) = &args.reading {
        inputs.reading.clone_from(r);
    }
    let problem = inputs.problem()?;
    if args.all_readings {
        let mut rows = Vec::new();
        for reading in Reading::all() {
            let p = RequirementProblem {
                reading,
                ..problem.clone()
            };
            let row = match requirement_json(&inputs, &p) {
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
    let v = requirement_json(&inputs, &problem)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let req = &v["orientation_requirement_deg"];
        println!(
            "orientation requirement (eq 15-16), Table 1, omega_m = {} deg/h, latitude {} deg, {} positions, {} Delta-R",
            inputs.omega_m_deg_per_h,
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

    /// The default inputs are the library's paper problem.
    #[test]
    fn default_inputs_build_the_paper_problem() {
        assert_eq!(
            RequirementInputs::default().problem().unwrap(),
            RequirementProblem::paper()
        );
    }

    /// A study file may give only some keys; the rest keep the paper defaults.
    #[test]
    fn partial_inputs_fill_from_defaults() {
        let v: RequirementInputs =
            serde_json::from_str(r#"{"latitude_deg": 30.0, "delta_r": "exact"}"#).unwrap();
        let p = v.problem().unwrap();
        assert_eq!(p.delta_r_kind, DeltaRKind::Exact);
        assert_eq!(p.schedule, Schedule::paper_default());
        assert!(serde_json::from_str::<RequirementInputs>(r#"{"latitude": 30.0}"#).is_err());
    }

    /// Bad inputs name their key; an unidentifiable schedule names the coefficient.
    #[test]
    fn bad_inputs_name_the_key() {
        let mut v = RequirementInputs {
            schedule_deg: [0.0, 90.0, 180.0, 270.0]
                .iter()
                .flat_map(|&a| [0.0, 90.0, 180.0, 270.0].map(|b| [a, b]))
                .collect(),
            ..RequirementInputs::default()
        };
        let e = v.problem().unwrap_err();
        assert_eq!(e.location, "schedule_deg");
        assert!(e.reason.contains("D(x)_xy"), "{}", e.reason);
        v = RequirementInputs {
            omega_m_deg_per_h: -1.0,
            ..RequirementInputs::default()
        };
        assert_eq!(v.problem().unwrap_err().location, "omega_m_deg_per_h");
        v = RequirementInputs {
            delta_r: "tiny".into(),
            ..RequirementInputs::default()
        };
        assert_eq!(v.problem().unwrap_err().location, "delta_r");
    }
}
