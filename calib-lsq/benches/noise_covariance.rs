//! Cost of the noise covariance of a calibration: 128 positions, 4 outputs (two gyros with
//! bias and three g-sensitivities, two accelerometers with bias, scale factor, two
//! misalignments and a second-order term), every output with white noise, a Gauss-Markov
//! bias and quantization, 60 s dwell, 10 s moves, 1000 Hz. Target: under 1 ms.
//!
//! - `covariance`: `Calibration::noise_covariances` (for every output: the 128 x 128
//!   position covariance, white and correlated, then A+ S A+^T and A Cov A^T);
//! - `covariance_white_only`: the same with white noise and quantization only;
//! - `lsq_solve` (baseline): one least-squares solve per output with the regression already
//!   factored (`Regression::solve`, what a calibration from measured outputs costs);
//! - `calibration_new` (baseline): building the `Calibration` (every regression factored:
//!   QR, rank, Jacobi SVD), which the covariance reuses.
//!
//! Run: `cargo bench -p calib-lsq --bench noise_covariance`.

use calib_lsq::{Calibration, Position, Schedule, Timing};
use criterion::{Criterion, criterion_group, criterion_main};
use gw_model::noise::{GaussMarkov, NoiseModel, WhiteDensity};
use gw_model::{Output, Regressor, SensorModel, Term};
use nalgebra::{DVector, Rotation3, Vector3};
use std::hint::black_box;

fn term(c: &str, r: &str, value: f64) -> Term {
    Term {
        coefficient: c.into(),
        regressor: Regressor::parse(r).expect("valid regressor"),
        value,
        known: false,
    }
}

fn sensor() -> SensorModel {
    let gyro = |axis: &str, w: &str| Output {
        name: format!("g{axis}"),
        unit: "deg_per_h".into(),
        accuracy: 0.1,
        terms: vec![
            Term {
                known: true,
                ..term(&format!("omega_{axis}"), w, 1.0)
            },
            term(&format!("bg_{axis}"), "1", 0.6),
            term(&format!("gs_{axis}x"), "a_x", 0.3),
            term(&format!("gs_{axis}y"), "a_y", -0.2),
            term(&format!("gs_{axis}z"), "a_z", 0.15),
        ],
    };
    let acc = |axis: &str, own: &str, others: [&str; 2]| Output {
        name: format!("a{axis}"),
        unit: "mg".into(),
        accuracy: 0.1,
        terms: vec![
            term(&format!("ba_{axis}"), "1", 0.8),
            term(&format!("sf_{axis}"), own, 1000.3),
            term(&format!("mis_{axis}1"), others[0], 0.5),
            term(&format!("mis_{axis}2"), others[1], -0.3),
            term(&format!("k2_{axis}"), &format!("{own}^2"), 0.02),
        ],
    };
    SensorModel::new(vec![
        gyro("x", "w_x"),
        gyro("y", "w_y"),
        acc("x", "a_x", ["a_y", "a_z"]),
        acc("z", "a_z", ["a_x", "a_y"]),
    ])
    .expect("valid sensor")
}

/// 128 positions of a three-axis table R = Rz(o) Rx(m) Ry(i): m every 45 deg, i every 22.5
/// deg, o = 0.
fn schedule() -> Schedule {
    let mut positions = Vec::new();
    for m in 0..8 {
        for i in 0..16 {
            let (m, i) = (f64::from(m) * 45.0, f64::from(i) * 22.5);
            let r = Rotation3::from_axis_angle(&Vector3::x_axis(), m.to_radians())
                * Rotation3::from_axis_angle(&Vector3::y_axis(), i.to_radians());
            positions.push(Position::new(*r.matrix(), vec![0.0, m, i]).expect("finite"));
        }
    }
    Schedule::new(positions).expect("positions")
}

fn bench(c: &mut Criterion) {
    let sensor = sensor();
    let site = gw_model::paper::site();
    let schedule = schedule();
    let cal = Calibration::new(&sensor, &site, &schedule).expect("identifiable");
    let timing = Timing::uniform(128, 60.0, 10.0, 1000.0).expect("valid timing");
    let gyro = NoiseModel::from_datasheet(
        "deg_per_h",
        Some(WhiteDensity::DegPerSqrtH(0.15)),
        Some((0.5, 3600.0)),
        Some(0.22),
    )
    .expect("valid noise");
    let acc = NoiseModel::from_datasheet(
        "mg",
        Some(WhiteDensity::MPerSPerSqrtH(0.07)),
        Some((0.05, 600.0)),
        Some(0.002),
    )
    .expect("valid noise");
    let noise = vec![Some(gyro.clone()), Some(gyro), Some(acc.clone()), Some(acc)];
    let white: Vec<Option<NoiseModel>> = noise
        .iter()
        .map(|n| {
            n.as_ref().map(|n| {
                NoiseModel::new(n.white_per_sqrt_hz(), None::<GaussMarkov>, n.quantization())
                    .expect("valid noise")
            })
        })
        .collect();
    let y: Vec<DVector<f64>> = cal
        .outputs()
        .iter()
        .map(|o| o.a_beta() + DVector::from_fn(128, |i, _| (i as f64 * 0.37).sin()))
        .collect();

    let mut g = c.benchmark_group("noise_covariance_128_positions_4_outputs");
    g.bench_function("covariance", |b| {
        b.iter(|| black_box(cal.noise_covariances(black_box(&noise), &timing)))
    });
    g.bench_function("covariance_white_only", |b| {
        b.iter(|| black_box(cal.noise_covariances(black_box(&white), &timing)))
    });
    let windows = timing.windows();
    let gyro_noise = noise[0].clone().expect("noise");
    let reg = cal.outputs()[0].regression();
    let pos = gyro_noise.window_covariance(&windows, 1000.0).expect("fs");
    let coef = reg.coefficient_covariance(&pos).expect("sized");
    g.bench_function("part_window_covariance_1_output", |b| {
        b.iter(|| black_box(gyro_noise.window_covariance(black_box(&windows), 1000.0)))
    });
    g.bench_function("part_coefficient_covariance_1_output", |b| {
        b.iter(|| black_box(reg.coefficient_covariance(black_box(&pos))))
    });
    g.bench_function("part_rate_error_covariance_1_output", |b| {
        b.iter(|| black_box(reg.rate_error_covariance(black_box(&coef))))
    });
    g.bench_function("lsq_solve", |b| {
        b.iter(|| {
            for (o, y) in cal.outputs().iter().zip(&y) {
                black_box(o.regression().solve(black_box(y)).expect("sized"));
            }
        })
    });
    g.bench_function("calibration_new", |b| {
        b.iter(|| black_box(Calibration::new(&sensor, &site, black_box(&schedule))))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
