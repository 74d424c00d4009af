//! Throughput of the Monte Carlo core (samples/s), one thread:
//! - `fast_chain`: [`MonteCarlo::run`] (quaternion fast path, statistics included, hot loop
//!   on the widest SIMD level of the CPU);
//! - `fast_chain_portable`: the same on the portable level (SSE2 on x86-64);
//! - `plain_chain`: [`MonteCarlo::run_model`] with [`ExactChain`] (ten dense 3x3 rotations,
//!   eq 17-24), the baseline; same samples, same statistics;
//! - `generator_alone`: [`MonteCarlo::draw_only`], drawing the same random turntables only
//!   (the words and their decoding into chi);
//! - `generator_words_only`: [`MonteCarlo::draw_words_only`], the words alone.
//!
//! Run: `CARGO_TARGET_DIR=target cargo bench -p mc-verify --bench mc_throughput`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mc_verify::{ErrorBox, McConfig, MonteCarlo, SimdLevel};
use std::hint::black_box;
use tt_kinematics::ExactChain;

/// Table 4 of the paper, arcmin (order of eq 25).
const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

fn mc(samples: u64) -> MonteCarlo {
    let bounds = ErrorBox::from_arcmin([0.0; 8], TABLE4_ARCMIN).expect("Table 4 is valid");
    MonteCarlo::new(bounds, McConfig::new(samples, 2017)).expect("valid config")
}

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let mut g = c.benchmark_group("mc_core_1_thread");
    let n_fast = 1u64 << 20;
    let fast = mc(n_fast);
    g.throughput(Throughput::Elements(n_fast));
    g.bench_function("fast_chain", |b| {
        b.iter(|| pool.install(|| black_box(fast.run().max_abs_rad())));
    });
    g.bench_function("fast_chain_portable", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(
                    fast.run_with_simd(SimdLevel::Portable)
                        .expect("always available")
                        .max_abs_rad(),
                )
            })
        });
    });
    g.bench_function("generator_alone", |b| {
        b.iter(|| pool.install(|| black_box(fast.draw_only())));
    });
    g.bench_function("generator_words_only", |b| {
        b.iter(|| pool.install(|| black_box(fast.draw_words_only())));
    });
    let n_plain = 1u64 << 16;
    let plain = mc(n_plain);
    g.throughput(Throughput::Elements(n_plain));
    g.bench_function("plain_chain", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(
                    plain
                        .run_model(&ExactChain::default())
                        .expect("finite")
                        .max_abs_rad(),
                )
            })
        });
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(4));
    targets = bench
}
criterion_main!(benches);
