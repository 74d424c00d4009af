//! The six-face and three-rotation recording (calib-run/studies/imu-six-face-three-rotation.toml)
//! processed by `calibrate` gives the accelerometer and gyro triads' biases and matrices that
//! an independent implementation of the Ferraris method (Ferraris, Grimaldi and Parvis 1995)
//! gives on the same recording, within the run's expanded uncertainty.

// matrix formulas read as written
#![allow(clippy::needless_range_loop)]

mod common;

use calib_run::{CalibrateOptions, calibrate};
use common::{record, study};
use gw_model::SensorModel;

const RATE_HZ: f64 = 100.0;
const DWELL_S: f64 = 20.0;
const MOVE_S: f64 = 2.0;
const REST_S: f64 = 3.0;
const ROTATION_S: f64 = 8.0;

/// Truth: gyro biases (deg/h) and matrices, accelerometer biases (mg) and matrices (mg/g).
fn truth(s: &study::Study) -> SensorModel {
    let gyro_b = [100.0, -50.0, 30.0];
    let gyro_m = [
        [1.02, 0.01, -0.008],
        [-0.006, 0.98, 0.012],
        [0.004, -0.01, 1.01],
    ];
    let acc_b = [20.0, -10.0, 15.0];
    let acc_m = [[1010.0, 5.0, -3.0], [4.0, 995.0, 6.0], [-2.0, 3.0, 1004.0]];
    let mut outs = s.sensor.outputs().to_vec();
    for (k, o) in outs.iter_mut().enumerate() {
        let (b, m) = if k < 3 {
            (gyro_b[k], gyro_m[k])
        } else {
            (acc_b[k - 3], acc_m[k - 3])
        };
        o.terms[0].value = b;
        for j in 0..3 {
            o.terms[1 + j].value = m[j];
        }
    }
    SensorModel::new(outs).expect("model")
}

/// The Ferraris method on the recording's rows (t, gx, gy, gz, ax, ay, az), with the
/// timeline the simulator used: returns (gyro bias, gyro matrix, accel bias, accel matrix).
#[allow(clippy::type_complexity)]
fn ferraris(
    rows: &[[f64; 7]],
    earth_deg_per_h: &[[f64; 3]; 6],
) -> ([f64; 3], [[f64; 3]; 3], [f64; 3], [[f64; 3]; 3]) {
    let n = |s: f64| (s * RATE_HZ).round() as usize;
    let mean = |a: usize, b: usize, c: usize| {
        rows[a..b].iter().map(|r| r[c]).sum::<f64>() / (b - a) as f64
    };
    // face k: samples [k (dwell + move), + dwell), one second trimmed each side
    let face = |k: usize, c: usize| {
        let start = k * n(DWELL_S + MOVE_S);
        mean(start + n(1.0), start + n(DWELL_S - 1.0), c)
    };
    // faces: +z, -z, +x, -x, +y, -y (the study's positions)
    let plus = [2, 4, 0];
    let minus = [3, 5, 1];
    let mut acc_b = [0.0; 3];
    let mut acc_m = [[0.0; 3]; 3];
    for i in 0..3 {
        acc_b[i] = (0..6).map(|k| face(k, 4 + i)).sum::<f64>() / 6.0;
        for j in 0..3 {
            acc_m[i][j] = (face(plus[j], 4 + i) - face(minus[j], 4 + i)) / 2.0;
        }
    }
    // gyro bias: the statics' mean less the earth's rate at each face (known; the scale
    // factors' effect on it is second order)
    let mut gyro_b = [0.0; 3];
    for i in 0..3 {
        gyro_b[i] = (0..6)
            .map(|k| face(k, 1 + i) - earth_deg_per_h[k][i])
            .sum::<f64>()
            / 6.0;
    }
    // rotations: after the last face, a move to the start pose, then per rotation a rest, the
    // turn, a rest; integrate (output - bias - earth rate at rest) over the turn and one
    // second of rest each side, divide by 360 deg
    let after = 5 * n(DWELL_S + MOVE_S) + n(DWELL_S) + n(MOVE_S);
    let dt_h = 1.0 / RATE_HZ / 3600.0;
    let rot_axis = [2, 0, 1]; // phi_o turns about z, phi_m about x, phi_i about y
    let mut gyro_m = [[0.0; 3]; 3];
    for r in 0..3 {
        let start = after + r * n(2.0 * REST_S + ROTATION_S) + n(REST_S);
        let j = rot_axis[r];
        for i in 0..3 {
            // the bias from the statics and the earth's rate at the start pose (+z up)
            let rest = gyro_b[i] + earth_deg_per_h[0][i];
            let integral: f64 = rows[start - n(1.0)..start + n(ROTATION_S) + n(1.0)]
                .iter()
                .map(|row| (row[1 + i] - rest) * dt_h)
                .sum();
            gyro_m[i][j] = integral / 360.0;
        }
    }
    (gyro_b, gyro_m, acc_b, acc_m)
}

fn parse(csv: &[u8]) -> Vec<[f64; 7]> {
    std::str::from_utf8(csv)
        .expect("utf8")
        .lines()
        .skip(1)
        .map(|l| {
            let mut r = [0.0; 7];
            for (c, v) in l.split(',').enumerate() {
                r[c] = v.parse().expect("number");
            }
            r
        })
        .collect()
}

#[test]
fn six_faces_and_three_rotations_match_the_ferraris_method_within_the_run_uncertainty() {
    let s = study("imu-six-face-three-rotation.toml");
    let t = truth(&s);
    let sim = calib_run::simulate::SimSettings {
        sample_rate_hz: RATE_HZ,
        dwell_s: DWELL_S,
        move_s: MOVE_S,
        rest_s: REST_S,
        rotation_s: ROTATION_S,
        white_per_sqrt_hz: common::white(&s),
        table_errors_rad: None,
        log_angles: false,
        seed: 1995,
        repeats: 1,
    };
    let csv = record(&s, &t, &sim);
    let run = calibrate(
        &s,
        csv.as_slice(),
        "six-face.csv",
        &CalibrateOptions::default(),
    )
    .expect("processed");
    // the detection found the six faces and the three rotations
    let kinds: Vec<_> = run
        .segments()
        .iter()
        .map(|g| (g.entry(), g.kind().name()))
        .collect();
    assert_eq!(
        kinds,
        [
            (0, "static"),
            (1, "static"),
            (2, "static"),
            (3, "static"),
            (4, "static"),
            (5, "static"),
            (6, "rotation"),
            (7, "rotation"),
            (8, "rotation")
        ]
    );
    let earth: Vec<[f64; 3]> = s
        .calibration
        .schedule()
        .positions()
        .iter()
        .take(6)
        .map(|p| {
            let w = s.site.inputs(p.base_from_sensor()).rate_rad_per_s
                * (180.0 / std::f64::consts::PI * 3600.0);
            [w.x, w.y, w.z]
        })
        .collect();
    let earth: [[f64; 3]; 6] = earth.try_into().expect("six faces");
    let (gb, gm, ab, am) = ferraris(&parse(&csv), &earth);
    let axes = ["x", "y", "z"];
    let check = |name: String, reference: f64| {
        let (_, c) = run.coefficient(&name).expect("coefficient");
        let (u, _) = c.expanded();
        assert!(
            (c.value() - reference).abs() <= u,
            "{name}: calibrate {} vs Ferraris {reference} (U = {u})",
            c.value()
        );
    };
    for i in 0..3 {
        check(format!("bg_{}", axes[i]), gb[i]);
        check(format!("ba_{}", axes[i]), ab[i]);
        for j in 0..3 {
            check(format!("mg_{}{}", axes[i], axes[j]), gm[i][j]);
            check(format!("ma_{}{}", axes[i], axes[j]), am[i][j]);
        }
    }
    // and both near the truth (the Ferraris reference is not a copy of the truth)
    let (_, c) = run.coefficient("mg_xx").expect("mg_xx");
    assert!((c.value() - 1.02).abs() <= c.expanded().0);
    assert!((gm[0][0] - 1.02).abs() < 1e-3);
}
