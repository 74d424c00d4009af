//! Throughput of the end-to-end evaluation (turntables/s: exact chain at every position of the
//! paper's schedule, both outputs calibrated, eq 14), one thread, Table 4's box, for both
//! readings of eq 13 that matter:
//! - `fast_path`: [`EndToEnd::delta_omega_into`] (pose frames, nominal inputs, the least-squares
//!   pseudo-inverse and the needed regressor blocks computed once);
//! - `reference_path`: [`EndToEnd::run`] on the same turntables (tt-kinematics' chain per
//!   position, calib-lsq's full analysis with a QR per turntable), the baseline measured in the
//!   same run: the ratio of the two is the figure to read, not the absolute times;
//! - `monte_carlo`: [`e2e_verify::MonteCarloQuestions::rate_distribution`] (drawing and streaming statistics included).
//!
//! Run: `cargo bench -p e2e-verify --bench e2e_throughput`.

use calib_lsq::{Calibration, Reading};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use e2e_verify::{EndToEnd, McSettings};
use std::hint::black_box;
use tt_kinematics::{Pose, paper};

/// Turntables per benchmark iteration.
const DRAWS: u64 = 512;

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let table = paper::table3();
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &calib_lsq::paper::schedule(),
    )
    .expect("the paper's schedule identifies every coefficient");
    let poses: Vec<Pose> = cal
        .schedule()
        .positions()
        .iter()
        .map(|p| Pose::from_deg(p.joint_angles_deg()))
        .collect::<Result<_, _>>()
        .expect("the paper's poses are finite");
    for (label, reading) in [
        ("paper_reading", Reading::PAPER),
        ("user_reading", Reading::USER),
    ] {
        let e2e = EndToEnd::new(&table, &cal, &poses, reading).expect("valid study");
        let linear = e2e.linearization();
        let bounds = e2e
            .box_of(&alloc_opt::paper::table4_rad(), &[0.0; 8])
            .expect("Table 4 is a valid box");
        let settings = McSettings::new(DRAWS, 2017);
        let chis = e2e
            .monte_carlo()
            .sample_chi(&bounds, &settings)
            .expect("valid settings");
        let mut g = c.benchmark_group(format!("end_to_end_1_thread_{label}"));
        g.throughput(Throughput::Elements(DRAWS));
        g.bench_function("fast_path", |b| {
            let mut work = e2e.work();
            b.iter(|| {
                let mut s = 0.0;
                for chi in &chis {
                    e2e.delta_omega_into(black_box(chi), &mut work)
                        .expect("finite");
                    s += work.delta_omega[0];
                }
                s
            });
        });
        g.bench_function("reference_path", |b| {
            b.iter(|| {
                chis.iter()
                    .map(|chi| e2e.run(black_box(chi)).expect("finite").delta_omega()[0])
                    .sum::<f64>()
            });
        });
        g.bench_function("monte_carlo", |b| {
            b.iter(|| {
                pool.install(|| {
                    black_box(
                        e2e.monte_carlo()
                            .rate_distribution(&linear, &bounds, &settings)
                            .expect("valid settings")
                            .count()
                            .samples(),
                    )
                })
            });
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
