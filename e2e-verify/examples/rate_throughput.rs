//! End to end with rate steps against the static end to end for the same number of schedule
//! entries, measured in the same run (issue 23): the example study
//! `studies/tactical-rate-table-example.toml` (24 static positions and 6 rate steps) against
//! the same study with the 6 rate steps replaced by static positions at their starting angles
//! (30 static positions), one thread, the same draws of the navigation-grade box.
//!
//! Run: `cargo run --release -p e2e-verify --example rate_throughput [DRAWS]`

use e2e_verify::{EndToEnd, McSettings};
use std::path::Path;
use std::time::Instant;
use study::Study;
use tt_kinematics::Pose;

fn simulator(s: &Study) -> Result<EndToEnd, Box<dyn std::error::Error>> {
    let poses: Vec<Pose> = s
        .schedule_angles_deg()
        .iter()
        .map(|p| Pose::from_deg(p))
        .collect::<Result<_, _>>()?;
    Ok(EndToEnd::new(
        &s.turntable,
        &s.calibration,
        &poses,
        s.reading,
    )?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = root.join("studies/tactical-rate-table-example.toml");
    let text = std::fs::read_to_string(&path)?;
    let rate = Study::parse("tactical-rate-table-example.toml", &text)?;
    // the same entries, every one static
    let start = text
        .find("[[calibration.rate_steps]]")
        .ok_or("no rate step")?;
    let end = text.find("[monte_carlo]").ok_or("no monte_carlo")?;
    let mut positions = rate.positions_deg.clone();
    positions.extend(rate.rate_steps.iter().map(|r| r.angles_deg.clone()));
    let static_text = format!("{}{}", &text[..start], &text[end..]);
    let static_study = Study::parse("static.toml", &static_text)?.with_positions_deg(positions)?;
    let n: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200_000);
    let tol = study::Tolerances::load(
        &root.join("studies/tolerances/three-axis-navigation-grade.toml"),
        &rate.turntable,
    )?;
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut per_s = Vec::new();
    for (what, s) in [("static", &static_study), ("rate steps", &rate)] {
        let e2e = simulator(s)?;
        let linear = e2e.linearization();
        let bounds = e2e.box_of(&tol.ub_rad, &vec![0.0; e2e.n_errors()])?;
        // warm-up, then the timed run
        one.install(|| {
            e2e.monte_carlo()
                .rate_distribution(&linear, &bounds, &McSettings::new(n / 10, 1))
        })?;
        let t = Instant::now();
        one.install(|| {
            e2e.monte_carlo()
                .rate_distribution(&linear, &bounds, &McSettings::new(n, 2017))
        })?;
        let rate_per_s = n as f64 / t.elapsed().as_secs_f64();
        println!(
            "{what}: {} entries, {rate_per_s:.3e} turntables/s on one thread",
            e2e.len()
        );
        per_s.push(rate_per_s);
    }
    println!(
        "rate steps / static: {:.2}x the time per turntable (same run, same entries)",
        per_s[0] / per_s[1]
    );
    Ok(())
}
