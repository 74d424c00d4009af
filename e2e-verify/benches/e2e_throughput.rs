//! Throughput of the end-to-end evaluation (turntables/s: exact chain at the 32 positions, both
//! axes calibrated), one thread, Table 4's box, USER reading:
//! - `fast_path`: [`EndToEnd::delta_omega`] (factored chain, precomputed pseudo-inverse);
//! - `reference_path`: [`EndToEnd::run`] on the same draws (tt-kinematics' chain per position,
//!   calib-lsq's full eq 7-14 analysis with both estimates, a QR of A' per draw), the baseline;
//! - `monte_carlo`: [`EndToEnd::sample_rates`] (drawing included).
//!
//! Run: `CARGO_TARGET_DIR=target cargo bench -p e2e-verify --bench e2e_throughput`.

use alloc_opt::paper_table4_rad;
use calib_lsq::Reading;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use e2e_verify::{EndToEnd, McSettings};
use mc_verify::ErrorBox;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let e2e = EndToEnd::paper(Reading::USER);
    let bounds = ErrorBox::from_upper_rad(paper_table4_rad()).expect("Table 4 is valid");
    let n = 1024_u64;
    let draws = e2e
        .sample_rates(&bounds, &McSettings::new(n, 2017))
        .expect("valid settings");
    let mut g = c.benchmark_group("end_to_end_1_thread");
    g.throughput(Throughput::Elements(n));
    g.bench_function("fast_path", |b| {
        b.iter(|| {
            draws
                .iter()
                .map(|d| e2e.delta_omega(black_box(&d.chi_rad)).expect("finite")[0])
                .sum::<f64>()
        });
    });
    g.bench_function("reference_path", |b| {
        b.iter(|| {
            draws
                .iter()
                .map(|d| {
                    e2e.run(black_box(&d.chi_rad))
                        .expect("finite")
                        .delta_omega_rad_per_s()[0]
                })
                .sum::<f64>()
        });
    });
    g.bench_function("monte_carlo", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(
                    e2e.sample_rates(&bounds, &McSettings::new(n, 2017))
                        .expect("valid settings")
                        .len(),
                )
            })
        });
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
