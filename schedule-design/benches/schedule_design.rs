//! Cost of evaluating a candidate schedule in the schedule designer, for the paper's study
//! (two-axis table, 15 deg grid: 576 candidates, 32 positions), under the paper's reading
//! (fixed rows) and the user's (rows through the projection):
//! - `from_scratch`: the path every command takes for a schedule, the baseline: positions to
//!   a `Calibration` (regressions factored), `EndToEnd::new` (pose frames), `linearization`,
//!   `allocate_direct` (one conic solve);
//! - `precomputed_exact`: `DesignProblem::evaluate`, the designer's exact evaluation (the
//!   candidates' regressor rows, nominal inputs and derivative blocks computed once; same
//!   conic solve, bit-identical J): the solve dominates both;
//! - `linearization_from_scratch` and `linearization_precomputed`: the same two paths up to
//!   M only (without the solve), to show what the precomputation saves;
//! - `screen_swap`: `Neighbourhood::screen` of one slot, per swap (element): the Woodbury
//!   update of the rows, the dual lower bound from the schedule's multipliers and, when that
//!   does not decide, the dual screening solver. This is the inner evaluation of the exchange;
//!   only swaps it cannot rule out are evaluated exactly.
//!
//! The figures to read are the ratios of elements per second within one run.
//! Run: `cargo bench -p schedule-design --bench schedule_design`.

use calib_lsq::{Calibration, Position, Reading, Schedule};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use e2e_verify::EndToEnd;
use schedule_design::{DesignProblem, candidates_with, grid_positions_deg};
use std::hint::black_box;
use tt_kinematics::{Pose, paper};

fn bench(c: &mut Criterion) {
    let table = paper::table3();
    let sensor = gw_model::paper::gyrowheel();
    let site = gw_model::paper::site();
    let study: Vec<Vec<f64>> = calib_lsq::paper::schedule()
        .positions()
        .iter()
        .map(|p| p.joint_angles_deg().to_vec())
        .collect();
    let grid = candidates_with(
        grid_positions_deg(&table, 15.0).expect("valid step"),
        &study,
    );
    for (label, reading) in [
        ("paper_reading", Reading::PAPER),
        ("user_reading", Reading::USER),
    ] {
        let problem = DesignProblem::new(&table, &sensor, &site, reading, &[0.0; 8], grid.clone())
            .expect("identifiable grid");
        let s: Vec<usize> = study
            .iter()
            .map(|p| problem.index_of(p).expect("on the grid"))
            .collect();
        let hood = problem.neighbourhood(&s, 10.0).expect("feasible schedule");
        let swaps = hood.screen(0).expect("slot 0").len() as u64;
        // the path every command takes: positions to a calibration, then the end-to-end model
        let e2e_from_scratch = || {
            let poses: Vec<Pose> = study
                .iter()
                .map(|p| Pose::from_deg(p).expect("finite"))
                .collect();
            let positions = study
                .iter()
                .zip(&poses)
                .map(|(p, q)| {
                    Position::new(table.nominal_rotation(q).expect("pose"), p.clone())
                        .expect("finite")
                })
                .collect();
            let schedule = Schedule::new(positions).expect("positions");
            let cal = Calibration::new(&sensor, &site, &schedule).expect("identifiable");
            EndToEnd::new(&table, &cal, &poses, reading).expect("valid")
        };
        let mut g = c.benchmark_group(format!("schedule_evaluation_{label}"));
        g.throughput(Throughput::Elements(1));
        g.bench_function("from_scratch", |b| {
            b.iter(|| {
                let e2e = e2e_from_scratch();
                let linear = e2e.linearization();
                black_box(
                    e2e.allocate_direct(&linear, &[0.0; 8])
                        .expect("allocation")
                        .objective(),
                )
            });
        });
        g.bench_function("linearization_from_scratch", |b| {
            b.iter(|| {
                let e2e = e2e_from_scratch();
                black_box(e2e.linearization().matrix()[(0, 0)])
            });
        });
        g.bench_function("linearization_precomputed", |b| {
            b.iter(|| {
                black_box(
                    problem
                        .linearization(black_box(&s))
                        .expect("identifiable")
                        .matrix()[(0, 0)],
                )
            });
        });
        g.bench_function("precomputed_exact", |b| {
            b.iter(|| {
                black_box(
                    problem
                        .evaluate(black_box(&s))
                        .expect("evaluation")
                        .objective(),
                )
            });
        });
        g.throughput(Throughput::Elements(swaps));
        g.bench_function("screen_swap", |b| {
            b.iter(|| black_box(hood.screen(black_box(7)).expect("slot").len()));
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(4));
    targets = bench
}
criterion_main!(benches);
