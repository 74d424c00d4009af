//! Throughput of the Monte Carlo core (samples/s), one thread:
//! - `paper/general_plan`: [`MonteCarlo::run`] on the paper's table (Table 3, Table 4 bounds,
//!   LB = 0): the compiled plan on lanes of samples, statistics included, hot loop on the
//!   widest SIMD level of the CPU;
//! - `paper/specialised_kernel`: the same run through the kept hand-written paper kernel
//!   ([`mc_verify::baseline::paper_kernel_run`]), the baseline of the 90 % goal;
//! - `paper/general_plan_portable`: the general plan on the portable level (SSE2 on x86-64);
//! - `paper/generator_alone`, `paper/generator_words_only`: [`MonteCarlo::draw_only`] and
//!   [`MonteCarlo::draw_words_only`] (the same random turntables drawn and decoded, or their
//!   words only);
//! - `paper/plain_chain`: [`MonteCarlo::run_model`] with [`ExactChain`] (dense 3x3
//!   matrices), same samples, same statistics;
//! - `three_axis/general_plan`, `three_axis/generator_alone`,
//!   `three_axis/generator_words_only`: a three-axis table (13 angular errors, 3 joints,
//!   bounds 0.3-0.6 arcmin, LB = 0), the baseline of the 0.35 goal.
//!
//! Criterion times each function in turn; ratios between separate benchmarks on a machine
//! shared with other jobs are less reliable than the interleaved rounds of
//! `examples/throughput.rs`, which the README quotes.
//!
//! Run: `cargo bench -p mc-verify --bench mc_throughput`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mc_verify::baseline::paper_kernel_run;
use mc_verify::{ErrorBox, McConfig, MonteCarlo, SimdLevel};
use std::hint::black_box;
use tt_kinematics::{ExactChain, paper};

/// Table 4 of the paper, arcmin (order of eq 25).
const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// The requirement of eq 16 on every angle, rad.
fn eq16() -> tt_core::Requirement {
    tt_core::Requirement::from_options([Some(0.027_f64.to_radians()); 3]).expect("valid")
}

fn paper_mc(samples: u64) -> MonteCarlo {
    let t = paper::table3();
    let b = ErrorBox::from_arcmin(&t, vec![0.0; 8], TABLE4_ARCMIN.to_vec()).expect("Table 4");
    MonteCarlo::new(&t, b, McConfig::new(samples, 2017, eq16())).expect("valid config")
}

fn three_axis_mc(samples: u64) -> MonteCarlo {
    let t = tt_kinematics::conformance::three_axis();
    let ub = (0..13).map(|i| 0.3 + 0.025 * f64::from(i)).collect();
    let b = ErrorBox::from_arcmin(&t, vec![0.0; 13], ub).expect("valid box");
    MonteCarlo::new(&t, b, McConfig::new(samples, 2017, eq16())).expect("valid config")
}

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let n = 1u64 << 20;
    let paper = paper_mc(n);
    let three = three_axis_mc(n);

    let mut g = c.benchmark_group("paper");
    g.throughput(Throughput::Elements(n));
    g.bench_function("general_plan", |b| {
        b.iter(|| pool.install(|| black_box(paper.run().max_abs_rad())));
    });
    g.bench_function("specialised_kernel", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(
                    paper_kernel_run(&paper)
                        .expect("the paper's table")
                        .max_abs_rad(),
                )
            })
        });
    });
    g.bench_function("general_plan_portable", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(
                    paper
                        .run_with_simd(SimdLevel::Portable)
                        .expect("always available")
                        .max_abs_rad(),
                )
            })
        });
    });
    g.bench_function("generator_alone", |b| {
        b.iter(|| pool.install(|| black_box(paper.draw_only())));
    });
    g.bench_function("generator_words_only", |b| {
        b.iter(|| pool.install(|| black_box(paper.draw_words_only())));
    });
    let n_plain = 1u64 << 16;
    let plain = paper_mc(n_plain);
    let chain = ExactChain::new(&paper::table3());
    g.throughput(Throughput::Elements(n_plain));
    g.bench_function("plain_chain", |b| {
        b.iter(|| {
            pool.install(|| black_box(plain.run_model(&chain).expect("finite").max_abs_rad()))
        });
    });
    g.finish();

    let mut g = c.benchmark_group("three_axis");
    g.throughput(Throughput::Elements(n));
    g.bench_function("general_plan", |b| {
        b.iter(|| pool.install(|| black_box(three.run().max_abs_rad())));
    });
    g.bench_function("generator_alone", |b| {
        b.iter(|| pool.install(|| black_box(three.draw_only())));
    });
    g.bench_function("generator_words_only", |b| {
        b.iter(|| pool.install(|| black_box(three.draw_words_only())));
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(4));
    targets = bench
}
criterion_main!(benches);
