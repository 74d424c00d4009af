//! Wall time of the JCGM 101 Monte Carlo of the whole calibration (`budget_mc`) on the IMU
//! example (its five specifications, its noise and timing, every angular error rectangular on
//! 10 arcsec), adaptive to two significant digits of u(y), against the end-to-end kernel alone
//! (`rate_distribution`: exact chain at every position, every output calibrated) on the same
//! number of turntables, in the same run.
//!
//! Run: `cargo run --release -p e2e-verify --example budget_mc_speed`

use e2e_verify::McSettings;
use metrology::montecarlo::McSettings as Jcgm101Settings;
use std::time::Instant;
use testkit::e2e as common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let s = common::study("imu-triad-example");
    let e2e = common::study_e2e("imu-triad-example", None);
    let tol = 10.0_f64.to_radians() / 3600.0;
    let tolerances = vec![tol; e2e.n_errors()];
    let law = |n: &str, a: f64| metrology::Input::rectangular(n, 0.0, a);
    let verdict = e2e.budget().plan_verdict(
        &s.specifications,
        &tolerances,
        law,
        &s.noise,
        s.timing.as_ref(),
    )?;
    let table: Vec<_> = e2e
        .error_names()
        .iter()
        .map(|n| law(n, tol))
        .collect::<Result<_, _>>()?;
    let t = Instant::now();
    let mc = e2e.budget().specification_monte_carlo(
        &s.specifications,
        &verdict,
        &table,
        &Jcgm101Settings::default(),
    )?;
    let mc_s = t.elapsed().as_secs_f64();
    let trials = mc.iter().map(|m| m.trials()).max().unwrap_or(0);
    let linear = e2e.linearization();
    let bounds = e2e.box_of(&tolerances, &vec![0.0; e2e.n_errors()])?;
    let t = Instant::now();
    e2e.monte_carlo()
        .rate_distribution(&linear, &bounds, &McSettings::new(trials, 7))?;
    let kernel_s = t.elapsed().as_secs_f64();
    for m in &mc {
        println!(
            "specification {}: u(y) {:.3e}, symmetric {:?}, GUM {}",
            m.spec(),
            m.output().standard_uncertainty(),
            m.output().symmetric(),
            if m.validation().validated() {
                "validated"
            } else {
                "not validated"
            }
        );
    }
    println!(
        "JCGM 101 Monte Carlo: {trials} trials in {mc_s:.2} s on {} threads ({:.3e} trials/s); end-to-end kernel alone on {trials} turntables: {kernel_s:.2} s; ratio {:.2}",
        rayon::current_num_threads(),
        trials as f64 / mc_s,
        mc_s / kernel_s
    );
    Ok(())
}
