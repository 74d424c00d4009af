//! Throughput of the time-domain simulator (issue 21, item 5): noise samples per second of a
//! whole simulated calibration run (white + Gauss-Markov + quantization at every position,
//! the estimator on the position averages) against its generator alone, in the same run and
//! on the same threads: the same draws per sample (two normals by the 32-bit ziggurat and one
//! quantization uniform, from ChaCha8 words read a block at a time) and the ChaCha8 words
//! alone (three per sample, what the fast path of those draws takes). Everything is measured
//! twice: on all of rayon's threads and on one thread.
//!
//! `cargo run --release -p e2e-verify --example timedomain_throughput [CALIBRATIONS]`

use calib_lsq::{Reading, Timing};
use e2e_verify::McSettings;
use e2e_verify::ziggurat::{WordBlock, Ziggurat};
use gw_model::noise::{GaussMarkov, NoiseModel};
use rayon::prelude::*;
use std::time::Instant;

/// The paper's simulator, shared with the tests.
use testkit::e2e as common;

/// Samples per chunk of the generator-alone runs.
const CHUNK: u64 = 1 << 20;

/// Seconds to run `f` over `samples` samples in chunks of [`CHUNK`] on the current pool.
fn timed(samples: u64, f: &(dyn Fn(&mut WordBlock<mc_verify::McRng>, u64) -> f64 + Sync)) -> f64 {
    let t = Instant::now();
    let sink: f64 = (0..samples.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut words = WordBlock::new(mc_verify::chunk_rng(1, c));
            f(&mut words, CHUNK.min(samples - c * CHUNK))
        })
        .sum();
    std::hint::black_box(sink);
    t.elapsed().as_secs_f64()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let calibrations: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(2_000);
    let e2e = common::paper(Reading::USER);
    // 32 positions x 10 s at 100 Hz: 32,000 samples per output and calibration
    let timing = Timing::uniform(e2e.len(), 10.0, 2.0, 100.0)?;
    let m = NoiseModel::new(0.004, Some(GaussMarkov::new(0.001, 600.0)?), 0.001)?;
    let noise = vec![Some(m.clone()), Some(m)];
    let ub = alloc_opt::paper::table4_rad();
    let bounds = e2e.box_of(&ub, &vec![0.0; e2e.n_errors()])?;
    let settings = McSettings::new(calibrations, 1);
    let threads = rayon::current_num_threads();
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut pools = vec![(threads, None)];
    if threads > 1 {
        pools.push((1, Some(&one)));
    }
    for (n_threads, pool) in pools {
        let measure = || -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
            let t = Instant::now();
            let run = e2e.simulate_time_domain(&bounds, &noise, &timing, &settings)?;
            let sim = t.elapsed().as_secs_f64();
            let samples = run.noise_samples();
            // the generator alone: the simulator's draws per sample, summed
            let generator = timed(samples, &|words, n| {
                let z = Ziggurat::get();
                let mut s = 0.0;
                for _ in 0..n {
                    s += z.sample(words) + z.sample(words) + words.unit_32();
                }
                s
            });
            // ChaCha8 alone: three words per sample, from the same blocks
            let chacha = timed(samples, &|words, n| {
                let mut s = 0u32;
                for _ in 0..n {
                    s = s.wrapping_add(words.next_u32() ^ words.next_u32() ^ words.next_u32());
                }
                f64::from(s)
            });
            let rate = samples as f64 / sim;
            let generator_rate = samples as f64 / generator;
            let chacha_rate = samples as f64 / chacha;
            println!(
                "{n_threads} thread(s): time-domain simulator, {calibrations} calibrations, {samples} noise samples in {sim:.2} s: {rate:.3e} samples/s; yield {:.4}",
                run.count().fraction()
            );
            println!(
                "  generator alone (ChaCha8 + 32-bit ziggurat: two normals and a uniform per sample): {generator_rate:.3e} samples/s; simulator / generator = {:.2}",
                rate / generator_rate
            );
            println!(
                "  ChaCha8 words alone (three per sample): {chacha_rate:.3e} samples/s ({:.3e} words/s); simulator / words = {:.2}, generator / words = {:.2}",
                3.0 * chacha_rate,
                rate / chacha_rate,
                generator_rate / chacha_rate
            );
            Ok(())
        };
        match pool {
            Some(p) => p
                .install(measure)
                .map_err(|e| e as Box<dyn std::error::Error>)?,
            None => measure().map_err(|e| e as Box<dyn std::error::Error>)?,
        }
    }
    Ok(())
}
