//! The published definitions (IEEE Std 952-1997 Annex C; IEEE Std 1293-1998; El-Sheimy, Hou,
//! Niu 2008, Table I) on synthetic seeded logs with known noise: white noise of density N has
//! ADEV(tau) = N / sqrt(tau); a random walk of K has ADEV = K sqrt(tau / 3); a flicker floor
//! of bias instability B has ADEV = sqrt(2 ln 2 / pi) B = 0.664 B; the fitted N, K, B recover
//! the known values within tolerances derived from the equivalent degrees of freedom.

mod common;

use allan::{FLICKER_FLOOR_FACTOR, NoiseModel, PowerLaw, Settings, StreamingAllan};
use common::{Recipe, flicker_components};

/// How many of its own conservative standard uncertainties (derived from the equivalent
/// degrees of freedom of every point, `NoiseFit::*_uncertainty`) a fitted parameter may miss
/// the known value by (dimensionless): five, a false failure below 6e-7 for a Gaussian
/// estimate, and the uncertainty is an upper bound.
const SIGMAS: f64 = 5.0;

/// The confidence of the per-point bands that must hold the exact curve at every cluster time
/// (dimensionless): 1 - 1e-6, so a false failure anywhere on a 20-point curve is below 2e-5.
const WIDE_CONFIDENCE: f64 = 1.0 - 1e-6;

/// The largest relative uncertainty a fit may report for the recovery tests to mean anything
/// (dimensionless): 5 %, so that SIGMAS uncertainties stay within 25 % of the value.
const MAX_RELATIVE_UNCERTAINTY: f64 = 0.05;

fn analyse(
    recipe: &Recipe,
    samples: u64,
    rate_hz: f64,
    seed: u64,
    settings: Settings,
) -> allan::Analysis {
    let mut a = StreamingAllan::new(settings).unwrap();
    recipe.generate(samples, seed, |y| a.push(y).unwrap());
    let r = a.analyse().unwrap();
    assert_eq!(r.samples(), samples);
    assert!((r.rate_hz() - rate_hz).abs() == 0.0);
    r
}

/// IEEE Std 952 Annex C (eq C.4): white rate noise of two-sided density N^2 has
/// ADEV(tau) = N / sqrt(tau), and N is the 1 s value of the -1/2 line. Samples of sd sigma
/// at f_s have N = sigma / sqrt(f_s).
#[test]
fn white_noise_adev_is_n_over_sqrt_tau_ieee952_eq_c4() {
    let (sigma, rate): (f64, f64) = (0.05, 200.0); // deg/s per sample, Hz
    let n_true = sigma / rate.sqrt(); // deg/s/sqrt(Hz)
    let recipe = Recipe::white(sigma);
    let settings = Settings::new(rate)
        .confidence(WIDE_CONFIDENCE)
        .noise(NoiseModel::Fixed(PowerLaw::White));
    let r = analyse(&recipe, 1 << 18, rate, 11, settings);
    assert!(r.points().len() >= 15, "{} points", r.points().len());
    for p in r.points() {
        let exact = n_true / p.tau_s().sqrt();
        assert!(
            p.lower() <= exact && exact <= p.upper(),
            "tau {} s: N/sqrt(tau) = {exact} outside [{}, {}]",
            p.tau_s(),
            p.lower(),
            p.upper()
        );
    }
    let fit = r.fit();
    let u = fit
        .white_noise_uncertainty()
        .expect("white noise is fitted");
    assert!(u < MAX_RELATIVE_UNCERTAINTY * n_true, "uncertainty {u}");
    assert!(
        (fit.white_noise() - n_true).abs() <= SIGMAS * u,
        "N = {} +- {u}, known {n_true}",
        fit.white_noise()
    );
    // the curve only falls: no floor, B is an upper bound at the longest cluster time
    assert!(!fit.floor_reached());
    assert_eq!(
        fit.floor_tau_s().to_bits(),
        r.points().last().unwrap().tau_s().to_bits()
    );
}

/// IEEE Std 952 Annex C (eq C.12): a rate random walk K has ADEV(tau) = K sqrt(tau / 3);
/// with white noise N the fit recovers both, and the floor is the bottom of the bend,
/// ADEV_min = sqrt(2 N K / sqrt 3) at tau = sqrt(3) N / K.
#[test]
fn rate_random_walk_and_white_noise_recovered_ieee952_eq_c12() {
    let (sigma, step, rate) = (0.05, 1e-4, 100.0); // per sample, per sample, Hz
    let n_true = sigma / f64::sqrt(rate);
    let k_true = step * f64::sqrt(rate); // unit/s/sqrt(Hz): increments of step every 1/rate s
    let mut recipe = Recipe::white(sigma);
    recipe.rw_step = step;
    recipe.bias = 3.0;
    let r = analyse(
        &recipe,
        1 << 20,
        rate,
        12,
        Settings::new(rate).confidence(WIDE_CONFIDENCE),
    );
    // the exact curve of this discrete process inside every (wide) band
    for p in r.points() {
        let exact = recipe.avar(p.cluster()).sqrt();
        assert!(
            p.lower() <= exact && exact <= p.upper(),
            "tau {}: exact {exact} outside [{}, {}] ({})",
            p.tau_s(),
            p.lower(),
            p.upper(),
            p.noise()
        );
    }
    let fit = r.fit();
    let un = fit.white_noise_uncertainty().unwrap();
    let k = fit.rate_random_walk().expect("a +1/2 slope is fitted");
    let uk = fit.rate_random_walk_uncertainty().unwrap();
    assert!(
        un < MAX_RELATIVE_UNCERTAINTY * n_true && uk < 2.0 * MAX_RELATIVE_UNCERTAINTY * k_true,
        "N {} +- {un}, K {k} +- {uk}",
        fit.white_noise()
    );
    assert!(
        (fit.white_noise() - n_true).abs() <= SIGMAS * un,
        "N {} +- {un} vs {n_true}",
        fit.white_noise()
    );
    assert!(
        (k - k_true).abs() <= SIGMAS * uk,
        "K {k} +- {uk} vs {k_true}"
    );
    let bend = (2.0 * n_true * k_true / 3f64.sqrt()).sqrt();
    let ub = fit.bias_instability_uncertainty().unwrap();
    assert!(
        (fit.bias_instability() - bend / FLICKER_FLOOR_FACTOR).abs() <= SIGMAS * ub,
        "B {} +- {ub} vs bend {}",
        fit.bias_instability(),
        bend / FLICKER_FLOOR_FACTOR
    );
    assert!(fit.floor_reached());
    let tau_bend = 3f64.sqrt() * n_true / k_true;
    assert!(
        fit.floor_tau_s() > tau_bend / 2.5 && fit.floor_tau_s() < tau_bend * 2.5,
        "floor at {} s, bend at {tau_bend} s",
        fit.floor_tau_s()
    );
}

/// Largest relative ripple of the flat part of the Gauss-Markov sum's exact Allan deviation
/// around 0.664 B (dimensionless): two components per decade from 0.01 s to 1e5 s give a
/// floor flat to 0.22 % from 1.28 s to 1311 s (measured); 1 % leaves room.
const FLICKER_RIPPLE: f64 = 0.01;

/// IEEE Std 952 Annex C (eq C.9): flicker noise of two-sided density B^2 / (2 pi f) has a flat
/// Allan deviation sqrt(2 ln 2 / pi) B = 0.664 B. Checked on the exact Allan variance of the
/// synthetic flicker (Gauss-Markov components spread over seven decades), then the fit
/// recovers B from a seeded log of it with white noise.
#[test]
fn flicker_floor_is_0664_b_ieee952_eq_c9() {
    let (b, sigma, rate) = (2e-3, 0.01, 100.0);
    let gm = flicker_components(b, rate, 0.01, 1e5);
    let flicker = Recipe {
        bias: 0.0,
        white_sd: 0.0,
        rw_step: 0.0,
        gauss_markov: gm.clone(),
    };
    // theory: the floor is flat at 0.664 B from 1 s to 1000 s
    let mut worst: f64 = 0.0;
    for k in 7..17 {
        let adev = flicker.avar(1 << k).sqrt();
        worst = worst.max((adev / (FLICKER_FLOOR_FACTOR * b) - 1.0).abs());
    }
    assert!(worst <= FLICKER_RIPPLE, "ripple {worst}");
    assert!(
        (FLICKER_FLOOR_FACTOR - (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt()).abs()
            < 1e-15
    );
    // the fit on a log of white noise plus that flicker
    let recipe = Recipe {
        bias: -7.0,
        white_sd: sigma,
        rw_step: 0.0,
        gauss_markov: gm,
    };
    let r = analyse(
        &recipe,
        1 << 20,
        rate,
        13,
        Settings::new(rate).confidence(WIDE_CONFIDENCE),
    );
    for p in r.points() {
        let exact = recipe.avar(p.cluster()).sqrt();
        assert!(
            p.lower() <= exact && exact <= p.upper(),
            "tau {}: {exact} outside [{}, {}]",
            p.tau_s(),
            p.lower(),
            p.upper()
        );
    }
    let fit = r.fit();
    let ub = fit.bias_instability_uncertainty().unwrap();
    assert!(ub < MAX_RELATIVE_UNCERTAINTY * b, "uncertainty {ub}");
    assert!(
        (fit.bias_instability() - b).abs() <= SIGMAS * ub + FLICKER_RIPPLE * b,
        "B {} +- {ub} vs {b}",
        fit.bias_instability()
    );
    let n_true = sigma / f64::sqrt(rate);
    let un = fit.white_noise_uncertainty().unwrap();
    assert!(
        (fit.white_noise() - n_true).abs() <= SIGMAS * un,
        "N {} +- {un} vs {n_true}",
        fit.white_noise()
    );
}
