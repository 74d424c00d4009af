//! A recording simulated from a study with known coefficients, noise and table errors comes
//! back with the known coefficients inside the stated uncertainty.

mod common;

use approx::assert_relative_eq;
use calib_run::{CalibrateOptions, calibrate};
use common::{record, settings, study, truth};

/// The shift of coefficient j of output k from the study's value, in units of 1e-3 of a
/// typical size: a truth that is not the prior.
fn shift(k: usize, j: usize, v: f64) -> f64 {
    v + 0.05 * (1.0 + k as f64) * if j % 2 == 0 { 1.0 } else { -1.0 }
}

fn options() -> CalibrateOptions {
    let mut o = CalibrateOptions::default();
    // the simulated dwell (20 s) is shorter than the study's (60 s)
    o.detect.min_static_s = Some(5.0);
    o
}

#[test]
fn detected_segments_match_the_imu_triad_schedule_and_recover_the_truth() {
    let s = study("imu-triad-example.toml");
    let t = truth(&s, shift);
    let rec = record(&s, &t, &settings(&s, 50.0, 20.0, 7));
    let run = calibrate(&s, rec.as_slice(), "sim.csv", &options()).expect("processed");
    assert_eq!(run.segments().len(), s.positions_deg.len());
    for (i, seg) in run.segments().iter().enumerate() {
        assert_eq!(seg.entry(), i, "static intervals in schedule order");
    }
    let mut worst: f64 = 0.0;
    for (k, o) in run.outputs().iter().enumerate() {
        let truth_o = &t.outputs()[k];
        for (c, tv) in o.coefficients().iter().zip(truth_o.estimated()) {
            let (u_exp, _) = c.expanded();
            worst = worst.max((c.value() - tv.value).abs() / c.u_combined());
            assert!(
                (c.value() - tv.value).abs() <= 5.0 * c.u_combined(),
                "{} = {} vs truth {} (U = {u_exp})",
                c.name(),
                c.value(),
                tv.value
            );
        }
    }
    assert!(worst > 0.0);
}

#[test]
fn coverage_of_the_expanded_uncertainty_over_many_seeds_is_near_its_probability() {
    // 40 recordings x 26 coefficients: the fraction of |estimate - truth| <= U (k for 95 %)
    let s = study("imu-triad-example.toml");
    let t = truth(&s, shift);
    let (mut inside, mut total) = (0u32, 0u32);
    for seed in 0..40 {
        let rec = record(&s, &t, &settings(&s, 20.0, 15.0, 1000 + seed));
        let run = calibrate(&s, rec.as_slice(), "sim.csv", &options()).expect("processed");
        for (k, o) in run.outputs().iter().enumerate() {
            for (c, tv) in o.coefficients().iter().zip(t.outputs()[k].estimated()) {
                total += 1;
                inside += u32::from((c.value() - tv.value).abs() <= c.expanded().0);
            }
        }
    }
    let frac = f64::from(inside) / f64::from(total);
    // 1040 checks (correlated within a run): 0.95 within a generous band; the Birge-ratio
    // inflation makes it conservative, never liberal by more than sampling
    assert!(
        (0.92..=0.995).contains(&frac),
        "coverage {frac} ({inside}/{total})"
    );
}

#[test]
fn measured_white_noise_equals_the_simulated_density() {
    let s = study("imu-triad-example.toml");
    let t = truth(&s, shift);
    let rec = record(&s, &t, &settings(&s, 50.0, 20.0, 3));
    let run = calibrate(&s, rec.as_slice(), "sim.csv", &options()).expect("processed");
    for (o, w) in run.outputs().iter().zip(common::white(&s)) {
        // 24 x ~18 s of white noise: the pooled Allan estimate within 10 %
        assert_relative_eq!(o.noise().white_per_sqrt_hz, w, max_relative = 0.1);
    }
}

#[test]
fn the_table_part_predicts_what_table_errors_do_to_the_estimates() {
    // constant table errors of +-20 arcsec on every angle: each estimate moves by its
    // sensitivities times the errors (first order), to within the noise; a sheet of 30 arcsec
    // gives the budget its table part
    let s = study("imu-triad-example.toml");
    let t = truth(&s, shift);
    let n = s.turntable.n_rotation_errors();
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    let chi: Vec<f64> = (0..n)
        .map(|i| if i % 2 == 0 { 20.0 } else { -20.0 } * arcsec)
        .collect();
    let mut sim = settings(&s, 50.0, 20.0, 11);
    sim.table_errors_rad = Some(chi.clone());
    let rec = record(&s, &t, &sim);
    let names = s.turntable.rotation_error_names();
    let sheet = format!(
        "[tolerances_arcmin]\n{}",
        names
            .iter()
            .map(|nm| format!("{nm} = 0.5\n"))
            .collect::<String>()
    );
    let tol = study::Tolerances::parse("sheet.toml", &sheet, &s.turntable).expect("sheet");
    let mut o = options();
    o.tolerances = Some(tol);
    let run = calibrate(&s, rec.as_slice(), "sim.csv", &o).expect("processed");
    let mut moved = 0;
    for (k, out) in run.outputs().iter().enumerate() {
        for (c, tv) in out.coefficients().iter().zip(t.outputs()[k].estimated()) {
            assert!(c.u_table() > 0.0 || c.table_sensitivity().iter().all(|(_, v)| v.abs() < 1e-9));
            let predicted: f64 = c
                .table_sensitivity()
                .iter()
                .map(|(nm, v)| v * chi[names.iter().position(|x| x == nm).expect("named")])
                .sum();
            if predicted.abs() > 4.0 * c.u_measured_noise() {
                moved += 1;
            }
            // what is left after the table's predicted effect is noise (4 sigma)
            assert!(
                (c.value() - tv.value - predicted).abs() <= 4.0 * c.u_measured_noise(),
                "{}: {} - {} - {predicted} vs u {}",
                c.name(),
                c.value(),
                tv.value,
                c.u_measured_noise()
            );
        }
    }
    assert!(
        moved > 0,
        "the table errors move some estimate beyond the noise"
    );
}

#[test]
fn a_corrupted_segment_is_flagged_and_the_robust_fit_says_what_it_changed() {
    // position 5's ax samples shifted by 5 mg (a bumped fixture): the ordinary fit flags the
    // segment, the robust fit down-weights it, names it and moves ba_x toward the truth
    let s = study("imu-triad-example.toml");
    let t = truth(&s, shift);
    let rec = record(&s, &t, &settings(&s, 50.0, 20.0, 21));
    let text = String::from_utf8(rec).expect("utf8");
    let per = (22.0 * 50.0) as usize; // dwell + move, samples
    let (lo, hi) = (5 * per, 5 * per + 1000);
    let bumped: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i > lo && i <= hi {
                let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
                c[4] = (c[4].parse::<f64>().expect("num") + 5.0).to_string();
                c.join(",") + "\n"
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let ordinary = calibrate(&s, bumped.as_bytes(), "sim.csv", &options()).expect("processed");
    let ax = &ordinary.outputs()[3];
    assert!(
        ax.residuals()
            .iter()
            .any(|r| r.outlier && ordinary.segments()[r.segment].entry() == 5)
    );
    let mut o = options();
    o.robust = true;
    let robust = calibrate(&s, bumped.as_bytes(), "sim.csv", &o).expect("processed");
    let rx = &robust.outputs()[3];
    let w5 = rx
        .residuals()
        .iter()
        .find(|r| robust.segments()[r.segment].entry() == 5)
        .expect("entry 5");
    assert!(
        w5.robust_weight < 0.5,
        "down-weighted: {}",
        w5.robust_weight
    );
    let truth_b = t.outputs()[3].estimated().next().expect("ba_x").value;
    let (ord_b, rob_b) = (ax.coefficients()[0].value(), rx.coefficients()[0].value());
    assert!(
        (rob_b - truth_b).abs() < (ord_b - truth_b).abs(),
        "robust {rob_b} ordinary {ord_b} truth {truth_b}"
    );
    assert!(
        rx.notes()
            .iter()
            .any(|n| n.starts_with("robust fit: entry 5")),
        "{:?}",
        rx.notes()
    );
    let change = rx.coefficients()[0].robust_change().expect("reported");
    assert!(change.abs() > 0.0);
}

#[test]
fn logged_table_angles_find_the_rotations_and_give_the_same_estimates() {
    // the six-face and three-rotation recording with the table's angles logged: rest and
    // rotations come from the angles, the rotations' angle from the log
    let s = study("imu-six-face-three-rotation.toml");
    let mut sim = settings(&s, 50.0, 10.0, 8);
    let plain = calibrate(
        &s,
        record(&s, &s.sensor, &sim).as_slice(),
        "sim.csv",
        &CalibrateOptions::default(),
    )
    .expect("processed");
    sim.log_angles = true;
    let logged = calibrate(
        &s,
        record(&s, &s.sensor, &sim).as_slice(),
        "sim.csv",
        &CalibrateOptions::default(),
    )
    .expect("processed");
    assert!(logged.recording().angles_logged);
    assert_eq!(logged.segments().len(), 9);
    for (a, b) in plain.outputs().iter().zip(logged.outputs()) {
        for (ca, cb) in a.coefficients().iter().zip(b.coefficients()) {
            // the same samples' noise (same seed): the two estimates agree within U
            assert!(
                (ca.value() - cb.value()).abs() <= ca.expanded().0,
                "{}: {} vs {}",
                ca.name(),
                ca.value(),
                cb.value()
            );
        }
    }
}
