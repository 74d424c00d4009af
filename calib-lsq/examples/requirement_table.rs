//! Every reading of eq 13 side by side, and the sensitivity of the requirement (eq 16) to the
//! latitude and to the schedule, for the paper's sensor described as data.
//!
//! Run: `cargo run --release -p calib-lsq --example requirement_table`

use calib_lsq::{CalibError, Calibration, Reading, RequirementProblem, Schedule, paper};
use gw_model::Site;
use tt_core::DeltaRKind;

fn fmt(r: &[Option<f64>; 3]) -> String {
    r.iter()
        .map(|v| v.map_or("-".to_string(), |d| format!("{d:.6}")))
        .collect::<Vec<_>>()
        .join(" | ")
}

fn problem(
    site: &Site,
    schedule: &Schedule,
    reading: Reading,
) -> Result<RequirementProblem, CalibError> {
    let cal = Calibration::new(&gw_model::paper::gyrowheel(), site, schedule)?;
    Ok(RequirementProblem::new(
        cal,
        reading,
        DeltaRKind::SmallAngle,
    ))
}

fn main() -> Result<(), CalibError> {
    let site = gw_model::paper::site();
    let schedule = paper::schedule();
    println!(
        "## Requirement per reading (Table 1, omega_m = 0.01 deg/h, Harbin 45.75 N, default 4x8 schedule, eq 7)\n"
    );
    println!(
        "| reading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg) | angles of x | angles of y |"
    );
    println!("|---|---|---|---|---|---|---|");
    for reading in Reading::all() {
        let p = problem(&site, &schedule, reading)?;
        let names = |k| -> Result<String, CalibError> {
            Ok(p.region(k)?
                .sensitive_angles()
                .iter()
                .map(|&j| tt_core::OrientationAxis::ALL[j].name())
                .collect::<Vec<_>>()
                .join(","))
        };
        let (sx, sy) = (names(0)?, names(1)?);
        match p.requirement() {
            Ok(r) => println!(
                "| `{reading}` | `{}` | {} | {sx} | {sy} |",
                reading.formula(),
                fmt(&r.requirement().deg())
            ),
            Err(CalibError::Unbounded { .. } | CalibError::NoSensitivity) => println!(
                "| `{reading}` | `{}` | unbounded | unbounded | unbounded | {sx} | {sy} |",
                reading.formula()
            ),
            Err(e) => return Err(e),
        }
    }

    println!("\n## Sensitivity to latitude (paper's reading and schedule)\n");
    println!("| latitude (deg) | I_psi | I_theta | I_gamma |");
    println!("|---|---|---|---|");
    for lat in [
        0.0, 20.0, 30.0, 40.0, 44.25, 45.0, 45.75, 47.0, 50.0, 60.0, 75.0, 89.0,
    ] {
        let s = Site::from_deg(lat, site.earth_rate_rad_per_s())?;
        let r = problem(&s, &schedule, Reading::PAPER)?.requirement()?;
        println!("| {lat} | {} |", fmt(&r.requirement().deg()));
    }

    println!("\n## Sensitivity to the schedule (paper's reading, Harbin)\n");
    println!("| schedule (phi1 step x phi2 step, deg) | positions | I_psi | I_theta | I_gamma |");
    println!("|---|---|---|---|---|");
    for (s1, s2) in [
        (90.0, 45.0),
        (30.0, 45.0),
        (30.0, 30.0),
        (15.0, 15.0),
        (5.0, 45.0),
        (60.0, 45.0),
        (90.0, 30.0),
        (45.0, 45.0),
    ] {
        let steps = |s: f64| {
            (0..(360.0 / s) as usize)
                .map(|k| k as f64 * s)
                .collect::<Vec<_>>()
        };
        let sched = paper::grid(&steps(s1), &steps(s2))?;
        let r = problem(&site, &sched, Reading::PAPER)?.requirement()?;
        println!(
            "| {s1} x {s2} | {} | {} |",
            sched.len(),
            fmt(&r.requirement().deg())
        );
    }
    Ok(())
}
