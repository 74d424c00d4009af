//! Turntables per second of the end-to-end Monte Carlo (exact chain at every position, every
//! output calibrated) for the paper's study, on one thread and on all, against the reference
//! path (plain matrix chain, calib-lsq's analysis) measured in the same run.
//!
//! Run: `cargo run --release -p e2e-verify --example end_to_end_throughput`

use calib_lsq::Reading;
use e2e_verify::McSettings;
use std::time::Instant;

/// The paper's simulator, shared with the tests.
use testkit::e2e as common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = common::paper(reading);
        let linear = e2e.linearization();
        let bounds = e2e.box_of(&alloc_opt::paper::table4_rad(), &[0.0; 8])?;
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
        let t = Instant::now();
        one.install(|| {
            e2e.monte_carlo()
                .rate_distribution(&linear, &bounds, &McSettings::new(n, 2017))
        })?;
        let single = n as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        e2e.monte_carlo()
            .rate_distribution(&linear, &bounds, &McSettings::new(n, 2017))?;
        let all = n as f64 / t.elapsed().as_secs_f64();
        let chis = e2e
            .monte_carlo()
            .sample_chi(&bounds, &McSettings::new(400, 2017))?;
        let t = Instant::now();
        for chi in &chis {
            std::hint::black_box(e2e.run(chi)?);
        }
        let reference = 400.0 / t.elapsed().as_secs_f64();
        println!(
            "{reading}: {single:.3e} turntables/s on one thread, {all:.3e} on {} threads; reference path {reference:.3e} on one thread ({:.1}x)",
            rayon::current_num_threads(),
            single / reference
        );
    }
    Ok(())
}
