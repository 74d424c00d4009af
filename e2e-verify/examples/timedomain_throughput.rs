//! Throughput of the time-domain simulator (issue 21, item 5): noise samples per second of a
//! whole simulated calibration run (white + Gauss-Markov + quantization at every position,
//! the estimator on the position averages) against the generator alone, in the same run on
//! the same threads: the same number of normal pairs (ziggurat over ChaCha8, the simulator's
//! draws: a white and a Gauss-Markov term per sample), the same by Box-Muller (the former
//! generator) and the ChaCha8 words alone.
//!
//! `cargo run --release -p e2e-verify --example timedomain_throughput [CALIBRATIONS]`

use calib_lsq::{Calibration, Reading, Timing};
use e2e_verify::noise::standard_normal_pair;
use e2e_verify::ziggurat::Ziggurat;
use e2e_verify::{EndToEnd, McSettings};
use gw_model::noise::{GaussMarkov, NoiseModel};
use rand_core::Rng;
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
    let timed = |f: &(dyn Fn(&mut mc_verify::McRng, u64) -> f64 + Sync)| {
        let t = Instant::now();
        let sink: f64 = (0..pairs.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let mut rng = mc_verify::chunk_rng(1, c);
                f(&mut rng, chunk.min(pairs - c * chunk))
            })
            .sum();
        std::hint::black_box(sink);
        t.elapsed().as_secs_f64()
    };
    let normals = timed(&|rng, n| {
        let z = Ziggurat::get();
        let mut s = 0.0;
        for _ in 0..n {
            s += z.sample(rng) + z.sample(rng);
        }
        s
    });
    // the Box-Muller pairs the simulator drew before the ziggurat (two words, ln, sqrt, sin_cos)
    let box_muller = timed(&|rng, n| {
        let mut s = 0.0;
        for _ in 0..n {
            let (a, b) = standard_normal_pair(rng);
            s += a + b;
        }
        s
    });
    // ChaCha8 alone: two words per sample, as the fast path of two ziggurat draws takes
    let words = timed(&|rng, n| {
        let mut s = 0u64;
        for _ in 0..n {
            s = s.wrapping_add(rng.next_u64() ^ rng.next_u64());
        }
        s as f64
    });
    let rate = run.noise_samples as f64 / sim;
    let pair_rate = pairs as f64 / normals;
    let word_rate = 2.0 * pairs as f64 / words;
    let box_muller_rate = pairs as f64 / box_muller;
    println!(
        "time-domain simulator: {calibrations} calibrations, {} noise samples in {sim:.2} s: {rate:.3e} samples/s on {} threads",
        run.noise_samples,
        rayon::current_num_threads()
    );
    println!(
        "normal generator alone (ChaCha8 + ziggurat, one normal pair per sample): {pair_rate:.3e} pairs/s; simulator / normal generator = {:.2}",
        rate / pair_rate
    );
    println!(
        "Box-Muller pairs (ChaCha8, the former generator): {box_muller_rate:.3e} pairs/s; ziggurat / Box-Muller = {:.2}",
        pair_rate / box_muller_rate
    );
    println!(
        "ChaCha8 alone: {word_rate:.3e} words/s ({:.3e} word pairs/s); simulator / ChaCha8 word pairs = {:.2}",
        word_rate / 2.0,
        rate / (word_rate / 2.0)
    );
    println!(
        "yield over turntables and simulated noise: {:.4}",
        run.yield_fraction()
    );
    Ok(())
}
