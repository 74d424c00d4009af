//! Rate steps with noise (issue 35, "rate tests and noise"): a rate step's output is averaged
//! over its whole revolutions, a window placed after the static positions in the schedule's
//! time order; the covariance of the estimate (calib-lsq) and the end-to-end noise answer
//! count it. Checked against the physics (a scale factor seen at 100 deg/s against one seen
//! under the earth's rate) and against the independent time-domain simulator.

mod common;

use approx::assert_relative_eq;
use e2e_verify::{EndToEnd, McSettings};
use study::Study;

/// Rounding of the least squares on columns of very different size (1 against 3.6e5 deg/h),
/// relative: far below any physical effect compared here.
const LSQ_ROUNDING: f64 = 1e-6;

/// Calibrations per time-domain check (as tests/timedomain.rs).
const CALIBRATIONS: u64 = 10_000;

/// Allowed deviation of a simulated variance from the predicted one, relative: 5 standard
/// errors of a sample variance of `CALIBRATIONS` normal draws, sqrt(2 / (N - 1)) each (1.4%).
fn variance_tolerance() -> f64 {
    5.0 * (2.0 / (CALIBRATIONS as f64 - 1.0)).sqrt()
}

/// The site's earth rate along the vertical, deg/h (the shipped example's site: WGS-84
/// rate, latitude 45.75 deg), computed here from the site's two numbers, not by the model.
fn vertical_earth_rate_deg_per_h() -> f64 {
    7.292_115_9e-5_f64.to_degrees() * 3600.0 * 45.75_f64.to_radians().sin()
}

/// A one-gyro study on the three-axis rate table of tactical-rate-table-example.toml: the z
/// gyro with its rate input (known), a bias and a scale-factor error, noise `noise` (TOML
/// lines), the four static positions z up and z down at two headings, the rate steps
/// `steps_deg_per_s` about the vertical outer axis with z up (no `revolutions`: the default
/// rule), and the timing `dwell_s`, `sample_rate_hz`, `move_s`.
fn gyro_study(
    noise: &str,
    steps_deg_per_s: &[f64],
    dwell_s: f64,
    sample_rate_hz: f64,
    move_s: f64,
) -> Study {
    let example = common::study("tactical-rate-table-example");
    let table = &example.text[..example.text.find("\n[sensor]").expect("a sensor")];
    let steps: String = steps_deg_per_s
        .iter()
        .map(|r| {
            format!(
                "[[calibration.rate_steps]]\njoint = \"phi_o\"\nrate_deg_per_s = {r:?}\nangles_deg = [0, 0, 0]\n\n"
            )
        })
        .collect();
    let text = format!(
        r#"{table}
[sensor]

[[sensor.outputs]]
name = "gz"
unit = "deg_per_h"
accuracy = 10.0
terms = [
  {{ coefficient = "omega_gz", regressor = "w_z", value = 1.0, known = true }},
  {{ coefficient = "bg_z", regressor = "1", value = 0.4 }},
  {{ coefficient = "sf_gz", regressor = "w_z", value = 1.5e-4 }},
]

[sensor.outputs.noise]
{noise}

[calibration]
positions_deg = [[0, 0, 0], [90, 0, 0], [0, 180, 0], [90, 180, 0]]

{steps}[calibration.timing]
dwell_s = {dwell_s:?}
sample_rate_hz = {sample_rate_hz:?}
move_s = {move_s:?}

[monte_carlo]
samples = 1000
seed = 1
"#
    );
    Study::parse("gyro.toml", &text).unwrap_or_else(|e| panic!("{e}"))
}

/// The standard deviation of the scale-factor estimate `sf_gz` under the study's noise.
fn scale_factor_sigma(s: &Study) -> f64 {
    let c = s.calibration.outputs()[0]
        .noise_covariance(
            s.noise[0].as_ref().expect("noise"),
            s.timing.as_ref().expect("timing"),
        )
        .expect("covariance");
    let j = c
        .coefficients()
        .names()
        .iter()
        .position(|n| n == "sf_gz")
        .expect("sf_gz estimated");
    c.coefficients().sigma()[j]
}

/// $S_{xx} = \sum_i (x_i - \bar x)^2$.
fn sxx(x: &[f64]) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| (v - mean).powi(2)).sum()
}

/// The physics the issue found inverted: with white noise and equal windows, a bias plus a
/// scale factor is a straight-line fit, whose slope has variance $\sigma^2/S_{xx}$. Static
/// positions see the scale factor through the earth's vertical rate only (10.8 deg/h), rate
/// steps at +-100 deg/s through 360,000 deg/h: the scale factor's standard uncertainty
/// shrinks by $\sqrt{S_{xx,\text{static}}/S_{xx,\text{all}}}$ (4.2e-5), from about 70,000
/// ppm to 3 ppm. The 36 s dwell is exactly 10 revolutions at 100 deg/s, so every window
/// (default revolutions) is 36 s.
#[test]
fn rate_steps_at_100_deg_per_s_shrink_the_scale_factor_sigma_by_the_regressor_ratio() {
    let white = "white_deg_per_sqrt_h = 0.15";
    let with_steps = gyro_study(white, &[100.0, -100.0], 36.0, 100.0, 5.0);
    let static_only = gyro_study(white, &[], 36.0, 100.0, 5.0);
    let timing = with_steps.timing.as_ref().expect("timing");
    assert_eq!(timing.rate_step_s(), &[36.0, 36.0]);
    assert_eq!(with_steps.rate_steps[0].revolutions, 10);

    let e = vertical_earth_rate_deg_per_h();
    let r = 100.0 * 3600.0;
    let x_static = [e, e, -e, -e];
    let x_all = [e, e, -e, -e, r + e, -r + e];
    // the average's sigma: 0.15 deg/sqrt(h) = 9 (deg/h) sqrt(s), over 36 s
    let sigma_avg = 0.15 * 60.0 / 36.0_f64.sqrt();
    let (sf_static, sf_rate) = (
        scale_factor_sigma(&static_only),
        scale_factor_sigma(&with_steps),
    );
    assert_relative_eq!(
        sf_static,
        sigma_avg / sxx(&x_static).sqrt(),
        max_relative = LSQ_ROUNDING
    );
    assert_relative_eq!(
        sf_rate,
        sigma_avg / sxx(&x_all).sqrt(),
        max_relative = LSQ_ROUNDING
    );
    assert_relative_eq!(
        sf_rate / sf_static,
        (sxx(&x_static) / sxx(&x_all)).sqrt(),
        max_relative = LSQ_ROUNDING
    );
    // in ppm (the scale factor is deg/h per deg/h)
    assert!(sf_static * 1e6 > 60_000.0, "{}", sf_static * 1e6);
    assert!(sf_rate * 1e6 < 3.0, "{}", sf_rate * 1e6);
}

/// The predicted covariance of a rate-step study (calib-lsq, windows in schedule order)
/// against the time-domain simulator (samples at the sample rate, white noise and a
/// Gauss-Markov bias drawn sample by sample, the estimator on the window averages), which
/// does not call the covariance code: 4 positions of 2 s, then rate steps at +-100 deg/s of
/// one revolution each (3.6 s, the default for a 2 s dwell), 25 Hz, 1 s moves. The
/// correlation time (10 s) spans several windows, so the correlated part couples the rate
/// steps' averages with the positions'.
#[test]
fn rate_step_noise_covariance_matches_the_time_domain_simulation() {
    let s = gyro_study(
        "white_deg_per_sqrt_h = 0.15\nbias_instability = 5.0\nbias_correlation_s = 10.0",
        &[100.0, -100.0],
        2.0,
        25.0,
        1.0,
    );
    let timing = s.timing.as_ref().expect("timing");
    assert_relative_eq!(timing.rate_step_s()[0], 3.6, max_relative = 1e-12);
    let e2e = EndToEnd::new(
        &s.turntable,
        &s.calibration,
        &common::poses_of(&s.calibration),
        s.reading,
    )
    .expect("simulator");
    let z = vec![0.0; e2e.n_errors()];
    let zero = e2e.box_of(&z, &z).expect("box");
    let run = e2e
        .simulate_time_domain(&zero, &s.noise, timing, &McSettings::new(CALIBRATIONS, 11))
        .expect("simulation");
    // 4 x 50 samples, 2 x 90
    assert_eq!(run.noise_samples(), CALIBRATIONS * (4 * 50 + 2 * 90));
    let model = s.noise[0].as_ref().expect("noise");
    let predicted = s.calibration.outputs()[0]
        .noise_covariance(model, timing)
        .expect("covariance");
    let p = predicted.coefficients();
    // the correlated term matters here (else the test would check white noise only)
    let corr = p.correlated_sigma();
    let white = p.white_sigma();
    assert!(corr[0] > 0.3 * white[0], "bias: {corr} vs {white}");
    let sim = run.outputs()[0].as_ref().expect("simulated");
    let tol = variance_tolerance();
    let total = p.total();
    for j in 0..total.nrows() {
        let ratio = sim.coefficient_covariance()[(j, j)] / total[(j, j)] - 1.0;
        assert!(ratio.abs() < tol, "coefficient {j}: {ratio} (tol {tol})");
    }
    let ps = predicted.rate_error().sigma();
    assert_eq!(ps.len(), 6);
    for (i, sd) in sim.rate_sigma().iter().enumerate() {
        let ratio = (sd / ps[i]).powi(2) - 1.0;
        assert!(ratio.abs() < tol, "entry {i}: {ratio} (tol {tol})");
    }
}

/// The shipped rate-step example with noise: one window per static position and rate step
/// (84 revolutions at 100 deg/s, the fewest lasting the 300 s dwell: 302.4 s), a noise
/// budget over all 30 entries, and the static dwell scaled by the trade-off while every rate
/// step keeps its revolutions. Before issue 35 the study was refused ("no timing yet").
#[test]
fn rate_step_example_gets_a_noise_budget_over_positions_and_rate_steps() {
    let s = common::study("stim300-rate-table-example");
    let timing = s.timing.clone().expect("timing");
    assert_eq!(timing.positions(), 24);
    assert_eq!(timing.len(), 30);
    for (step, &t) in s.rate_steps.iter().zip(timing.rate_step_s()) {
        assert_eq!(step.revolutions, 84);
        assert_relative_eq!(t, 302.4, max_relative = 1e-12);
    }
    let e2e: EndToEnd = common::study_e2e("stim300-rate-table-example", None);
    let budget = e2e.noise().noise_budget(&s.noise, &timing).expect("budget");
    assert!(budget.per_position().iter().all(|p| p.len() == 30));
    let sigma = budget.sigma();
    assert!(sigma.iter().all(|&s| s > 0.0));
    let longer = e2e
        .noise()
        .noise_budget_at_dwell(&s.noise, &timing, 1200.0)
        .expect("budget at 1200 s");
    assert_eq!(longer.timing().dwell_s(), &[1200.0; 24]);
    assert_eq!(longer.timing().rate_step_s(), timing.rate_step_s());
    // white-dominated at these time scales: a longer dwell lowers every output's sigma
    for (a, b) in longer.sigma().iter().zip(&sigma) {
        assert!(a < b, "{a} against {b}");
    }
}
