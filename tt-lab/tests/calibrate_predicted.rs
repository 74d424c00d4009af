//! The plan's predicted uncertainty of a processed run (issue 36) on a study with rate steps:
//! it is computed (it was "-" for such a study), it is the end-to-end noise part's covariance
//! of the coefficients for the same schedule and timing, and recordings simulated with the
//! study's noise and timing scatter as it predicts.

use approx::assert_relative_eq;
use calib_run::segments::{SegmentKind, SegmentSpec};
use calib_run::simulate::{SimSettings, simulate_recording};
use calib_run::{CalibrateOptions, Run, calibrate};
use study::Study;

/// One quantity computed two ways in double precision (a sub-regression against the plan's).
const SAME_REL: f64 = 1e-9;

/// The sample rate of the test study and its recordings, Hz.
const RATE_HZ: f64 = 100.0;
/// The test study's static dwell, s.
const DWELL_S: f64 = 20.0;
/// The moves between positions, s.
const MOVE_S: f64 = 2.0;
/// The rest before and after each rotation in the recordings, s.
const REST_S: f64 = 3.0;

/// studies/stim300-rate-table-example.toml (24 static positions, six rate steps at
/// +-100 deg/s) with a short timing (20 s dwells at 100 Hz: each rate step turns the fewest
/// whole revolutions lasting 20 s, 6 in 21.6 s) and its white noise only (the simulator draws
/// white noise; the bias instability lines are left out, so the plan and the recordings hold
/// the same noise).
fn test_study() -> Study {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/stim300-rate-table-example.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        match key {
            "bias_instability" | "bias_correlation_s" => continue,
            "dwell_s" => out.push_str(&format!("dwell_s = {DWELL_S}\n")),
            "sample_rate_hz" => out.push_str(&format!("sample_rate_hz = {RATE_HZ}\n")),
            "move_s" => out.push_str(&format!("move_s = {MOVE_S}\n")),
            _ => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Study::parse(path, &out).unwrap()
}

/// The simulator's timeline (calib_run::simulate) as a segments list: each static position's
/// dwell, each rate step's rotation, of kind `rotation_kind`.
fn segments(s: &Study, settings: &SimSettings, rotation_kind: SegmentKind) -> Vec<SegmentSpec> {
    let n = |secs: f64| (secs * settings.sample_rate_hz).round() as u64;
    let mut out = Vec::new();
    let mut at = 0;
    let mut here = s.positions_deg[0].clone();
    let mut push = |start: u64, len: u64, kind| {
        out.push(SegmentSpec {
            start,
            end: start + len,
            entry: out.len(),
            kind,
            line: out.len() as u64 + 2,
        });
    };
    for p in &s.positions_deg {
        if *p != here {
            at += n(settings.move_s);
            here = p.clone();
        }
        push(at, n(settings.dwell_s), SegmentKind::Static);
        at += n(settings.dwell_s);
    }
    for step in &s.rate_steps {
        if step.angles_deg != here {
            at += n(settings.move_s);
            here = step.angles_deg.clone();
        }
        at += n(settings.rest_s);
        push(at, n(settings.rotation_s), rotation_kind);
        at += n(settings.rotation_s) + n(settings.rest_s);
    }
    out
}

/// A recording of the test study realising its timing: the study's dwell and each rate
/// step's whole revolutions in the study's window, the study's white noise, seed `seed`.
fn run(s: &Study, seed: u64, kind: SegmentKind) -> Run {
    let timing = s.timing.as_ref().unwrap();
    let window = timing.rate_step_s()[0];
    assert!(
        timing
            .rate_step_s()
            .iter()
            .all(|w| (w - window).abs() < 1e-12)
    );
    let settings = SimSettings {
        move_s: MOVE_S,
        rest_s: REST_S,
        rotation_s: window,
        ..SimSettings::for_study(s, RATE_HZ, DWELL_S, seed)
    };
    let mut csv = Vec::new();
    simulate_recording(s, &s.sensor, &settings, &mut csv).unwrap();
    let options = CalibrateOptions {
        segments: Some(segments(s, &settings, kind)),
        ..CalibrateOptions::default()
    };
    calibrate(s, csv.as_slice(), "simulated.csv", &options).unwrap()
}

#[test]
fn predicted_u_of_a_rate_step_study_equals_the_end_to_end_noise_covariance() {
    let s = test_study();
    let timing = s.timing.as_ref().unwrap();
    assert_eq!(timing.rate_step_s().len(), 6);
    let e2e = tt_lab::loaded::simulator(&s).unwrap();
    let plan = e2e
        .calibration()
        .noise_covariances(&s.noise, timing)
        .unwrap();
    // rate steps held at their commanded rate: every output uses every entry
    let r = run(&s, 1, SegmentKind::Rate);
    for (o, c) in r.outputs().iter().zip(&plan) {
        let sigma = c.as_ref().unwrap().coefficients().sigma();
        assert_eq!(o.coefficients().len(), sigma.len());
        assert!(
            o.predicted_basis().contains("24 of 24 static"),
            "{}",
            o.predicted_basis()
        );
        assert!(o.predicted_basis().contains("6 of 6 rate steps"));
        for (cr, &want) in o.coefficients().iter().zip(sigma.iter()) {
            let got = cr.predicted_u().expect("computed for a rate-step study");
            assert_relative_eq!(got, want, max_relative = SAME_REL);
        }
    }
}

#[test]
fn measured_uncertainties_of_simulated_rate_step_runs_agree_with_predicted_u() {
    let s = test_study();
    // Rotations (hand-like rate profile, the study's window): the gyro outputs use all 30
    // entries, the accelerometers the 24 static ones (their prediction without the rate steps).
    const SEEDS: u64 = 6;
    let (mut z2, mut nz) = (0.0, 0.0);
    let (mut resid2, mut nr) = (0.0, 0.0);
    let (mut worst_white_only, mut white_only) = (0.0_f64, 0);
    for seed in 1..=SEEDS {
        let r = run(&s, seed, SegmentKind::Rotation);
        for (k, o) in r.outputs().iter().enumerate() {
            let truth: Vec<f64> = s.sensor.outputs()[k]
                .terms
                .iter()
                .filter(|t| !t.known)
                .map(|t| t.value)
                .collect();
            let rate = s.sensor.outputs()[k]
                .terms
                .iter()
                .any(|t| t.regressor.involves_rate());
            assert_eq!(
                o.predicted_basis().contains("left out"),
                !rate,
                "{}",
                o.predicted_basis()
            );
            for (c, t) in o.coefficients().iter().zip(&truth) {
                let p = c.predicted_u().expect("computed");
                z2 += ((c.value() - t) / p).powi(2);
                nz += 1.0;
                resid2 += (c.u_residuals().unwrap() / p).powi(2);
                nr += 1.0;
                if o.noise().floor == 0.0 {
                    white_only += 1;
                    worst_white_only = worst_white_only.max((c.u_measured_noise() / p - 1.0).abs());
                }
            }
        }
    }
    // The residuals' uncertainty (sqrt(chi2 / dof) times the measured-noise one: the scale of
    // the measured noise cancels), squared, over predicted_u squared: chi2 / dof with dof 26 for
    // a gyro, 20 for an accelerometer; its mean over 6 outputs and 6 seeds has a standard
    // deviation of about sqrt(2 / 23 / 36) = 0.05: within 4 of them.
    let mean_r2 = resid2 / nr;
    assert!(
        (mean_r2 - 1.0).abs() < 0.2,
        "mean (u_residuals / predicted_u)^2 = {mean_r2}"
    );
    // The estimates' errors standardized by predicted_u: 6 seeds x 24 coefficients; a mean
    // square of 1 with a standard deviation of sqrt(2 / 144) = 0.12 for independent
    // coefficients (larger with their correlation within an output): within 0.4.
    let mean_z2 = z2 / nz;
    assert!(
        (mean_z2 - 1.0).abs() < 0.4,
        "mean squared standardized error {mean_z2}"
    );
    // The measured-noise uncertainty where the Allan fit finds white noise alone (no floor):
    // the pooled density over 24 segments of 2,000 samples against the study's, and weighted
    // against ordinary least squares (rotation windows 21.6 s against 20 s dwells): within 5 %.
    assert!(white_only > 0);
    assert!(
        worst_white_only < 0.05,
        "u_measured_noise / predicted_u - 1 = {worst_white_only} without a floor"
    );
}
