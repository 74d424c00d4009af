//! One long log streamed from its generator through the streaming Allan deviation, with the
//! elapsed time and the peak resident memory (`VmHWM`, Linux, read before anything else is
//! allocated); then the throughput against baselines measured in the same run (a log of 2^22
//! samples in memory, interleaved rounds, best of each).
//!
//! Run: `cargo run --release -p allan --example allan_throughput -- [SAMPLES [GRID RATE_HZ]]`
//! (default 1e8 samples at 100 Hz on the octave grid for the long log; GRID is `octave`,
//! `decade` or `all`: `-- 2.88e6 all 400` is a 2 h log at 400 Hz with every cluster time of
//! the `all` grid, each point carrying the four deviations).

use allan::{Settings, StreamingAllan, Taus};
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Instant;

/// Standard normal pairs (Box-Muller on ChaCha8), scaled.
struct Gen(ChaCha8Rng);

impl Gen {
    fn pair(&mut self) -> (f64, f64) {
        let a = ((self.0.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        let b = (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let r = (-2.0 * a.ln()).sqrt();
        let t = 2.0 * std::f64::consts::PI * b;
        (0.1 * r * t.cos(), 0.1 * r * t.sin())
    }
}

fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let long: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse::<f64>().map(|v| v as u64))
        .transpose()?
        .unwrap_or(100_000_000);
    let grid = match std::env::args().nth(2).as_deref() {
        None | Some("octave") => Taus::Octave,
        Some("decade") => Taus::Decade,
        Some("all") => Taus::All,
        Some(other) => return Err(format!("GRID: `{other}` is not octave, decade or all").into()),
    };
    let rate: f64 = std::env::args()
        .nth(3)
        .map(|s| s.parse::<f64>())
        .transpose()?
        .unwrap_or(100.0);
    // the long log, streamed from its generator
    let t = Instant::now();
    let mut a = StreamingAllan::new(Settings::new(rate).taus(grid))?;
    let mut g = Gen(ChaCha8Rng::seed_from_u64(8));
    let mut block = Vec::with_capacity(1 << 16);
    let mut left = long;
    while left > 0 {
        block.clear();
        while block.len() < (1 << 16) && (left as usize) > block.len() {
            let (x, y) = g.pair();
            block.extend([x, y]);
        }
        block.truncate((left as usize).min(block.len()));
        a.extend(&block)?;
        left -= block.len() as u64;
    }
    let r = a.analyse()?;
    let secs = t.elapsed().as_secs_f64();
    println!(
        "streamed {long} samples (generated on the fly) in {secs:.2} s ({:.3e}/s), {} cluster times with four deviations and the fits, N = {:.6e} per sqrt(Hz) ({:.6e} expected), peak RSS {} KiB",
        long as f64 / secs,
        r.points().len(),
        r.fit().white_noise(),
        0.1 / rate.sqrt(),
        peak_rss_kib().map_or("?".into(), |k| k.to_string())
    );
    // in memory: 2^22 samples, three interleaved rounds
    let n = 1usize << 22;
    let mut g = Gen(ChaCha8Rng::seed_from_u64(7));
    let mut log = Vec::with_capacity(n);
    while log.len() < n {
        let (a, b) = g.pair();
        log.extend([a, b]);
    }
    let (mut best_adev, mut best_sum, mut best_gen) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        let t = Instant::now();
        let mut a = StreamingAllan::new(Settings::new(100.0))?;
        a.extend(black_box(&log))?;
        black_box(a.analyse()?);
        best_adev = best_adev.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        black_box(black_box(&log).iter().sum::<f64>());
        best_sum = best_sum.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut g = Gen(ChaCha8Rng::seed_from_u64(7));
        let mut acc = 0.0;
        for _ in 0..n / 2 {
            let (a, b) = g.pair();
            acc += a + b;
        }
        black_box(acc);
        best_gen = best_gen.min(t.elapsed().as_secs_f64());
    }
    let rate = |s: f64| n as f64 / s;
    println!(
        "in memory, {n} samples: streaming ADEV {:.3e}/s, summing {:.3e}/s (ratio {:.3}), generating {:.3e}/s (ratio {:.2})",
        rate(best_adev),
        rate(best_sum),
        best_sum / best_adev,
        rate(best_gen),
        best_gen / best_adev
    );
    Ok(())
}
