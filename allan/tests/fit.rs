//! The joint fit of the IEEE Std 952 / 1293 terms and its Gauss-Markov alternative on seeded
//! synthetic logs with known terms: each comes back within its stated uncertainty; terms the
//! log cannot show are said to be unresolved; the fit does not depend on the log's scale or
//! sample rate.

mod common;

use allan::{Resolution, Settings};
use common::Recipe;

/// How many of its stated standard uncertainties a fitted parameter may miss the known value
/// by (dimensionless): four, a false failure below 1e-4 for a Gaussian estimate.
const SIGMAS: f64 = 4.0;

/// Relative agreement of the same fit in other units (rounding of the scaled problem).
const SCALE_ROUNDING: f64 = 1e-9;

fn within(got: f64, u: Option<f64>, want: f64, what: &str) {
    let u = u.unwrap_or_else(|| panic!("{what}: no uncertainty"));
    assert!(
        (got - want).abs() <= SIGMAS * u,
        "{what}: {got} +- {u} vs the known {want}"
    );
    assert!(
        u < 0.25 * want,
        "{what}: uncertainty {u} too large to mean anything"
    );
}

/// White noise and a rate random walk: N and K within their uncertainties; no Gauss-Markov
/// term is resolved and the flicker floor is not significant.
#[test]
fn white_and_rate_random_walk_come_back_within_their_uncertainty() {
    let rate: f64 = 100.0;
    let recipe = Recipe {
        bias: 1.0,
        white_sd: 0.05,
        rw_step: 2e-5,
        gauss_markov: vec![],
    };
    let y = recipe.collect(1 << 20, 21);
    let r = allan::analyse(&y, Settings::new(rate)).unwrap();
    let f = r.fit();
    let n_true = 0.05 / rate.sqrt();
    // a random walk of steps q per sample: K^2 = q^2 f_s (K sqrt(tau/3) at tau)
    let k_true = 2e-5 * rate.sqrt();
    within(
        f.white_term().value(),
        f.white_term().uncertainty(),
        n_true,
        "N",
    );
    within(
        f.rate_random_walk_term().value(),
        f.rate_random_walk_term().uncertainty(),
        k_true,
        "K",
    );
    assert_eq!(f.white_term().resolution(), Resolution::Resolved);
    assert_eq!(f.rate_random_walk_term().resolution(), Resolution::Resolved);
    assert!(
        !f.flicker_term().resolution().is_resolved(),
        "{:?}",
        f.flicker_term()
    );
    assert!(
        !f.rate_ramp_term().resolution().is_resolved(),
        "{:?}",
        f.rate_ramp_term()
    );
}

/// White noise and a first-order Gauss-Markov bias (sd 0.05, Tc = 20 s): the Gauss-Markov
/// fit finds sigma and Tc (not the cluster time of the peak, 1.89 Tc) within their
/// uncertainties, and fits the curve better than the power terms.
#[test]
fn gauss_markov_sigma_and_correlation_time_come_back_within_their_uncertainty() {
    let rate: f64 = 10.0;
    let tc = 20.0;
    let recipe = Recipe {
        bias: 0.0,
        white_sd: 0.1,
        rw_step: 0.0,
        gauss_markov: vec![(0.05, (-1.0 / (rate * tc)).exp())],
    };
    let y = recipe.collect(1 << 20, 22);
    let r = allan::analyse(&y, Settings::new(rate)).unwrap();
    let g = r.fit().gauss_markov().unwrap();
    assert_eq!(
        g.correlation_s().resolution(),
        Resolution::Resolved,
        "{g:?}"
    );
    within(
        g.correlation_s().value(),
        g.correlation_s().uncertainty(),
        tc,
        "Tc",
    );
    within(g.sigma().value(), g.sigma().uncertainty(), 0.05, "sigma");
    within(
        g.white().value(),
        g.white().uncertainty(),
        0.1 / rate.sqrt(),
        "N",
    );
    assert!(g.rss() < g.power_rss(), "{} vs {}", g.rss(), g.power_rss());
}

/// A Gauss-Markov bias whose correlation time (1e5 s) is ten times the log's length: its
/// correlation time is not resolved (the curve has not turned); the log shows it as what it
/// looks like there, a rate random walk ($K^2 = 2\sigma^2/T_c$).
#[test]
fn a_correlation_time_beyond_the_log_is_not_resolved() {
    let rate: f64 = 10.0;
    let recipe = Recipe {
        bias: 0.0,
        white_sd: 0.1,
        rw_step: 0.0,
        gauss_markov: vec![(0.5, (-1.0 / (rate * 1e5)).exp())],
    };
    let y = recipe.collect(100_000, 23);
    let r = allan::analyse(&y, Settings::new(rate)).unwrap();
    let g = r.fit().gauss_markov().unwrap();
    assert_ne!(
        g.correlation_s().resolution(),
        Resolution::Resolved,
        "{g:?}"
    );
    let k = r.fit().rate_random_walk_term();
    assert_eq!(k.resolution(), Resolution::Resolved, "{k:?}");
    within(
        k.value(),
        k.uncertainty(),
        (2.0 * 0.25 / 1e5f64).sqrt(),
        "K",
    );
}

/// The same log multiplied by 1e100 and 1e-80, and sampled at 1e-9 Hz: the same fit in the
/// new units (issue 32: N and B came out 0 for such logs and rates).
#[test]
fn the_fit_does_not_depend_on_the_logs_scale_or_rate() {
    let recipe = Recipe {
        bias: 3.0,
        white_sd: 0.05,
        rw_step: 1e-4,
        gauss_markov: vec![],
    };
    let y = recipe.collect(60_000, 24);
    let base = allan::analyse(&y, Settings::new(100.0)).unwrap().fit();
    assert!(base.white_noise() > 0.0 && base.bias_instability() > 0.0);
    for scale in [1e100, 1e-80] {
        let ys: Vec<f64> = y.iter().map(|v| v * scale).collect();
        let f = allan::analyse(&ys, Settings::new(100.0)).unwrap().fit();
        for (a, b, what) in [
            (f.white_noise(), base.white_noise(), "N"),
            (f.bias_instability(), base.bias_instability(), "B"),
            (
                f.rate_random_walk().unwrap_or(0.0),
                base.rate_random_walk().unwrap_or(0.0),
                "K",
            ),
        ] {
            let rel = (a / scale - b).abs() / b;
            assert!(
                rel < SCALE_ROUNDING,
                "x{scale:e}: {what} {a} vs {b} (relative {rel:e})"
            );
        }
    }
    // at 1e-9 Hz every cluster time is 1e11 times longer: N^2 / tau and K^2 tau unchanged
    let f = allan::analyse(&y, Settings::new(1e-9)).unwrap().fit();
    let ratio: f64 = 100.0 / 1e-9;
    for (a, b, what) in [
        (f.white_noise(), base.white_noise() * ratio.sqrt(), "N"),
        (f.bias_instability(), base.bias_instability(), "B"),
    ] {
        let rel = (a - b).abs() / b;
        assert!(
            rel < SCALE_ROUNDING,
            "1e-9 Hz: {what} {a} vs {b} (relative {rel:e})"
        );
    }
}

/// Leaving out the Gauss-Markov alternative (`Settings::without_gauss_markov`, what a caller
/// reading only the white density and the floor asks for) leaves it `None` and every other
/// figure of the analysis equal, bit for bit.
#[test]
fn without_the_gauss_markov_fit_every_other_figure_is_bit_identical() {
    let rate: f64 = 10.0;
    let recipe = Recipe {
        bias: 0.0,
        white_sd: 0.1,
        rw_step: 0.0,
        gauss_markov: vec![(0.05, (-1.0 / (rate * 20.0)).exp())],
    };
    let y = recipe.collect(1 << 16, 23);
    let with = allan::analyse(&y, Settings::new(rate)).unwrap();
    let without = allan::analyse(&y, Settings::new(rate).without_gauss_markov()).unwrap();
    assert!(with.fit().gauss_markov().is_some());
    assert!(without.fit().gauss_markov().is_none());
    assert_eq!(with.points(), without.points());
    let (a, b) = (with.fit(), without.fit());
    let bits = |f: &allan::NoiseFit| {
        let mut v: Vec<u64> = [
            f.white_noise(),
            f.bias_instability(),
            f.floor_adev_measured(),
            f.floor_tau_s(),
        ]
        .iter()
        .chain(f.coefficients().iter())
        .map(|x| x.to_bits())
        .collect();
        v.push(u64::from(f.floor_reached()));
        v
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.white_term(), b.white_term());
    assert_eq!(a.flicker_term(), b.flicker_term());
    assert_eq!(a.quantization_term(), b.quantization_term());
}
