//! Throughput of the streaming Allan deviation (samples/s), one thread, on a seeded log of
//! 2^22 samples held in memory:
//! - `streaming_adev`: [`StreamingAllan::extend`] over the log, then
//!   [`StreamingAllan::analyse`] (curve, bands, fit);
//! - `baseline_sum`: summing the same samples (the memory-bound floor of any one-pass method);
//! - `baseline_generate`: generating the samples (ChaCha8, Box-Muller).
//!
//! The ratios between separate criterion benchmarks on a shared machine are less reliable
//! than the interleaved rounds of `examples/throughput.rs`, which the README quotes.
//!
//! Run: `cargo bench -p allan --bench allan_throughput`.

use allan::{Settings, StreamingAllan};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use std::hint::black_box;

fn generate(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let a = ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        let b = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let r = (-2.0 * a.ln()).sqrt();
        let t = 2.0 * std::f64::consts::PI * b;
        out.push(0.1 * r * t.cos());
        out.push(0.1 * r * t.sin());
    }
    out.truncate(n);
    out
}

fn bench(c: &mut Criterion) {
    let n = 1usize << 22;
    let log = generate(n, 7);
    let mut g = c.benchmark_group("allan");
    g.throughput(Throughput::Elements(n as u64));
    g.sample_size(10);
    g.bench_function("streaming_adev", |b| {
        b.iter(|| {
            let mut a = StreamingAllan::new(Settings::new(100.0)).expect("settings");
            a.extend(black_box(&log)).expect("finite");
            black_box(a.analyse().expect("enough samples"))
        });
    });
    g.bench_function("baseline_sum", |b| {
        b.iter(|| black_box(&log).iter().sum::<f64>());
    });
    g.bench_function("baseline_generate", |b| {
        b.iter(|| black_box(generate(n, 7)));
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
