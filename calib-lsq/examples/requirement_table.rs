//! Every reading of eq 13 side by side, and the sensitivity of the requirement (eq 16) to the
//! latitude and to the schedule.
//!
//! Run: `cargo run --release -p calib-lsq --example requirement_table`

use calib_lsq::{CalibError, Reading, RequirementProblem, Schedule};
use gw_model::units::rad_to_deg;
use gw_model::{DeltaRKind, OrientationAngles, SensingAxis, Site};

/// Claims (1)-(3) of §2.2 checked on a few points of each plane; returns a short verdict.
fn claims(p: &RequirementProblem) -> Result<String, CalibError> {
    let d = 0.02f64.to_radians();
    let x = p.plane(SensingAxis::X)?;
    let y = p.plane(SensingAxis::Y)?;
    let rel = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300);
    // (1) x not affected by gamma, y not by psi.
    let ax = x.analysis();
    let ay = y.analysis();
    let k = p.delta_r_kind;
    let x0 = ax.delta_omega_for_angles(&OrientationAngles::new(d, 0.5 * d, 0.0)?, k)?;
    let xg = ax.delta_omega_for_angles(&OrientationAngles::new(d, 0.5 * d, d)?, k)?;
    let y0 = ay.delta_omega_for_angles(&OrientationAngles::new(0.0, 0.5 * d, d)?, k)?;
    let yp = ay.delta_omega_for_angles(&OrientationAngles::new(d, 0.5 * d, d)?, k)?;
    let c1 = rel(x0, xg) && rel(y0, yp);
    // (2) even in each plane angle.
    let c2 = rel(x.rate_error(d, 0.5 * d)?, x.rate_error(-d, 0.5 * d)?)
        && rel(x.rate_error(d, 0.5 * d)?, x.rate_error(d, -0.5 * d)?)
        && rel(y.rate_error(d, 0.5 * d)?, y.rate_error(-d, 0.5 * d)?)
        && rel(y.rate_error(d, 0.5 * d)?, y.rate_error(d, -0.5 * d)?);
    // (3) rises with |angle| along each axis of each plane.
    let mut c3 = true;
    for plane in [&x, &y] {
        for (cu, cv) in [(1.0, 0.0), (0.0, 1.0), (1.0, 0.7)] {
            let mut last = 0.0;
            for i in 1..=8 {
                let s = d * i as f64 / 4.0;
                let v = plane.rate_error(cu * s, cv * s)?;
                c3 &= v > last;
                last = v;
            }
        }
    }
    let yn = |b: bool| if b { "yes" } else { "no" };
    Ok(format!("{} | {} | {}", yn(c1), yn(c2), yn(c3)))
}

fn main() -> Result<(), CalibError> {
    let base = RequirementProblem::paper();
    println!(
        "## Requirement per reading (Table 1, omega_m = 0.01 deg/h, Harbin 45.75 N, default 4x8 schedule, small-angle eq 7)\n"
    );
    println!(
        "| reading | error vector | I_psi (deg) | I_theta (deg) | I_gamma (deg) | x-plane theta | y-plane theta | (1) | (2) | (3) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for reading in Reading::all() {
        let p = RequirementProblem {
            reading,
            ..base.clone()
        };
        let c = claims(&p)?;
        match p.requirement() {
            Ok(r) => {
                let [a, b, g] = r.deg();
                println!(
                    "| `{reading}` | `{}` | {a:.6} | {b:.6} | {g:.6} | {:.6} | {:.6} | {c} |",
                    reading.formula(),
                    rad_to_deg(r.x_plane.half_v_rad),
                    rad_to_deg(r.y_plane.half_u_rad)
                );
            }
            Err(CalibError::Unbounded { .. }) => println!(
                "| `{reading}` | `{}` | unbounded | unbounded | unbounded | | | {c} |",
                reading.formula()
            ),
            Err(e) => return Err(e),
        }
    }

    println!("\n## Default reading, exact rotation instead of eq 7\n");
    let exact = RequirementProblem {
        delta_r_kind: DeltaRKind::Exact,
        ..base.clone()
    };
    let r = exact.requirement()?;
    println!("exact: {:?} deg", r.deg());
    let r = base.requirement()?;
    println!("small-angle: {:?} deg", r.deg());

    println!("\n## Sensitivity to latitude (default reading and schedule)\n");
    println!("| latitude (deg) | I_psi | I_theta | I_gamma |");
    println!("|---|---|---|---|");
    for lat in [
        0.0, 20.0, 30.0, 40.0, 44.25, 45.0, 45.75, 47.0, 50.0, 60.0, 75.0, 89.0,
    ] {
        let p = RequirementProblem {
            site: Site::from_deg(lat, base.site.earth_rate_rad_per_s())?,
            ..base.clone()
        };
        let [a, b, g] = p.requirement()?.deg();
        println!("| {lat} | {a:.6} | {b:.6} | {g:.6} |");
    }

    println!("\n## Sensitivity to the schedule (default reading, Harbin)\n");
    println!("| schedule | positions | I_psi | I_theta | I_gamma |");
    println!("|---|---|---|---|---|");
    let schedules: Vec<(&str, Schedule)> = vec![
        (
            "default: phi1 90-deg steps x phi2 45-deg steps",
            Schedule::paper_default(),
        ),
        ("phi1 30 x phi2 45", Schedule::grid_deg(30.0, 45.0)?),
        ("phi1 30 x phi2 30", Schedule::grid_deg(30.0, 30.0)?),
        ("phi1 15 x phi2 15", Schedule::grid_deg(15.0, 15.0)?),
        ("phi1 5 x phi2 45", Schedule::grid_deg(5.0, 45.0)?),
        (
            "phi1 1 x phi2 45 (near-continuous)",
            Schedule::grid_deg(1.0, 45.0)?,
        ),
        ("phi1 60 x phi2 45", Schedule::grid_deg(60.0, 45.0)?),
        ("phi1 90 x phi2 30", Schedule::grid_deg(90.0, 30.0)?),
        ("phi1 45 x phi2 45", Schedule::grid_deg(45.0, 45.0)?),
    ];
    for (name, s) in schedules {
        let n = s.len();
        let p = RequirementProblem {
            schedule: s,
            ..base.clone()
        };
        let [a, b, g] = p.requirement()?.deg();
        println!("| {name} | {n} | {a:.6} | {b:.6} | {g:.6} |");
    }
    Ok(())
}
