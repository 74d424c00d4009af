//! The GUM budget at the size of a 128-position, 4-output calibration study: 30 input
//! components (table errors, noise terms, site inputs) with a full correlation matrix, and
//! 32 outputs (4 outputs x 8 coefficients), i.e. the contributions, combined uncertainties,
//! Welch-Satterthwaite degrees of freedom, Student-t coverage factors and the 32 x 32
//! covariance. The goal: below 10 ms.
//!
//! - `budget_30x32_correlated`: [`Budget::evaluate`] with a correlation matrix;
//! - `budget_30x32_mapped`: [`Budget::evaluate_mapped`] from 30 independent sources through
//!   a 128 x 30 map (one derived input per position) and 32 x 128 sensitivities (the least
//!   squares of 128 positions).
//!
//! Run: `cargo bench -p metrology --bench budget`.

use criterion::{Criterion, criterion_group, criterion_main};
use metrology::{Budget, BudgetSettings, Input};
use nalgebra::DMatrix;
use std::hint::black_box;

fn entry(i: usize, j: usize) -> f64 {
    let h = ((i * 7919 + j * 104_729 + 13) * 2_654_435_761) % 1_000_003;
    2.0 * h as f64 / 1_000_003.0 - 1.0
}

fn inputs() -> Vec<Input> {
    (0..30)
        .map(|i| match i % 3 {
            0 => Input::rectangular(&format!("table{i}"), 0.0, 1e-4).unwrap(),
            1 => Input::normal(&format!("noise{i}"), 0.0, 2e-5)
                .unwrap()
                .with_dof(10.0 + i as f64)
                .unwrap(),
            _ => Input::arcsine(&format!("wobble{i}"), 0.0, 5e-5).unwrap(),
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let names: Vec<String> = (0..32)
        .map(|j| format!("out{}.coef{}", j / 8, j % 8))
        .collect();
    let b = DMatrix::from_fn(30, 30, |i, j| entry(i, j) + if i == j { 2.0 } else { 0.0 });
    let s = &b * b.transpose();
    let r = DMatrix::from_fn(30, 30, |i, j| s[(i, j)] / (s[(i, i)] * s[(j, j)]).sqrt());
    let correlated = Budget::new(inputs(), BudgetSettings::default())
        .unwrap()
        .with_correlation(r)
        .unwrap();
    let sens = DMatrix::from_fn(32, 30, |i, j| 1e3 * entry(i + 40, j));
    let mut g = c.benchmark_group("budget");
    g.bench_function("budget_30x32_correlated", |bch| {
        bch.iter(|| black_box(correlated.evaluate(&names, black_box(&sens)).unwrap()))
    });
    let independent = Budget::new(inputs(), BudgetSettings::default()).unwrap();
    let map = DMatrix::from_fn(128, 30, |i, j| entry(i + 200, j));
    let lsq = DMatrix::from_fn(32, 128, |i, j| entry(i + 500, j + 7) / 128.0);
    g.bench_function("budget_30x32_mapped", |bch| {
        bch.iter(|| {
            black_box(
                independent
                    .evaluate_mapped(&names, black_box(&lsq), black_box(&map))
                    .unwrap(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
