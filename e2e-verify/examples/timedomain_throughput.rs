//! Throughput of the time-domain simulator (issue 21, item 5): noise samples per second of a
//! whole simulated calibration run (white + Gauss-Markov + quantization at every position,
//! the estimator on the position averages) against drawing the same number of normal pairs
//! alone (the generator: ChaCha8 and Box-Muller), in the same run on the same threads.
//!
//! `cargo run --release -p e2e-verify --example timedomain_throughput [CALIBRATIONS]`

use calib_lsq::{Calibration, Reading, Timing};
use e2e_verify::noise::standard_normal_pair;
use e2e_verify::{EndToEnd, McSettings};
use gw_model::noise::{GaussMarkov, NoiseModel};
use rayon::prelude::*;
use std::time::Instant;
use tt_kinematics::{Pose, paper};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let calibrations: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(2_000);
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &calib_lsq::paper::schedule(),
    )?;
    let poses: Vec<Pose> = cal
        .schedule()
        .positions()
        .iter()
        .map(|p| Pose::from_deg(p.joint_angles_deg()))
        .collect::<Result<_, _>>()?;
    let e2e = EndToEnd::new(&paper::table3(), &cal, &poses, Reading::USER)?;
    // 32 positions x 10 s at 100 Hz: 32,000 samples per output and calibration
    let timing = Timing::uniform(e2e.len(), 10.0, 2.0, 100.0)?;
    let m = NoiseModel::new(0.004, Some(GaussMarkov::new(0.001, 600.0)?), 0.001)?;
    let noise = vec![Some(m.clone()), Some(m)];
    let ub = alloc_opt::paper::table4_rad();
    let bounds = e2e.box_of(&ub, &vec![0.0; e2e.n_errors()])?;
    let settings = McSettings::new(calibrations, 1);
    let t = Instant::now();
    let run = e2e.simulate_time_domain(&bounds, &noise, &timing, &settings)?;
    let sim = t.elapsed().as_secs_f64();
    // the generator alone: the same number of normal pairs, chunked the same way
    let pairs = run.noise_samples;
    let chunk = 1u64 << 20;
    let t = Instant::now();
    let sink: f64 = (0..pairs.div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let mut rng = mc_verify::chunk_rng(1, c);
            let mut s = 0.0;
            for _ in 0..chunk.min(pairs - c * chunk) {
                let (a, b) = standard_normal_pair(&mut rng);
                s += a + b;
            }
            s
        })
        .sum();
    let generator = t.elapsed().as_secs_f64();
    std::hint::black_box(sink);
    let rate = run.noise_samples as f64 / sim;
    let gen_rate = pairs as f64 / generator;
    println!(
        "time-domain simulator: {calibrations} calibrations, {} noise samples in {sim:.2} s: {rate:.3e} samples/s on {} threads",
        run.noise_samples,
        rayon::current_num_threads()
    );
    println!(
        "generator alone (ChaCha8 + Box-Muller, one normal pair per sample): {gen_rate:.3e} pairs/s; simulator / generator = {:.2}",
        rate / gen_rate
    );
    println!(
        "yield over turntables and simulated noise: {:.4}",
        run.yield_fraction()
    );
    Ok(())
}
