//! Against an independent implementation: golden values from the Python package allantools
//! (`tests/golden/allan_golden.py`, which also generates the logs with a generator written
//! identically here), for the overlapping Allan deviation (fully overlapping and decimated),
//! the equivalent degrees of freedom and the chi-squared confidence intervals.

#[path = "golden/allan_golden.rs"]
mod golden;

use allan::{NoiseModel, PowerLaw, Settings};
use approx::assert_relative_eq;

/// Relative agreement of our deviations and allantools' (dimensionless): the same squares
/// summed in another order, the phase built from another reference (allantools removes the
/// log's mean, we the first block's); measured at most 1.5e-14 on these logs, 1e-12 allowed.
const ADEV_AGREEMENT: f64 = 1e-12;

/// Relative agreement of the degrees of freedom and intervals (dimensionless): the same
/// formulas evaluated in another order; 1e-12.
const FORMULA_AGREEMENT: f64 = 1e-12;

/// Relative agreement with allantools' complete `edf_greenhall` from m = 64 on (dimensionless):
/// it replaces the basic sum by Greenhall and Riley's table approximation when J > 100;
/// measured at most 0.04 %, 0.5 % allowed. (Below m = 34 it filters the phase, F = m,
/// a model of averaged phase points rather than of integrated rate samples: 17 % apart for
/// white noise at m = 1, where our value is the exact one, see tests/edf.rs.)
const GREENHALL_TABLE_AGREEMENT: f64 = 5e-3;

struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0)
    }
    fn normal(&mut self) -> f64 {
        let mut s = 0.0;
        for _ in 0..12 {
            s += self.uniform();
        }
        s - 6.0
    }
}

fn white(n: usize, seed: u64) -> Vec<f64> {
    let mut g = SplitMix64(seed);
    (0..n).map(|_| 0.2 * g.normal()).collect()
}

fn white_rw(n: usize, seed: u64) -> Vec<f64> {
    let mut g = SplitMix64(seed);
    let mut rw = 0.0;
    (0..n)
        .map(|_| {
            let w = 0.05 * g.normal();
            rw += 1e-3 * g.normal();
            3.0 + w + rw
        })
        .collect()
}

fn gm(n: usize, seed: u64) -> Vec<f64> {
    let mut g = SplitMix64(seed);
    let (mut a, mut b) = (0.0, 0.0);
    let ka = 0.05 * (1.0f64 - 0.999 * 0.999).sqrt();
    let kb = 0.02 * (1.0f64 - 0.99 * 0.99).sqrt();
    (0..n)
        .map(|_| {
            let w = 0.1 * g.normal();
            a = 0.999 * a + ka * g.normal();
            b = 0.99 * b + kb * g.normal();
            w + a + b
        })
        .collect()
}

fn check_log(y: &[f64], first: &[f64], rate: f64, oadev: &[f64], strided: &[f64]) {
    for (a, b) in y.iter().zip(first) {
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "the generators differ: {a} vs {b}"
        );
    }
    let full = allan::analyse(y, Settings::new(rate).overlap(1 << 16)).unwrap();
    assert_eq!(full.points().len(), oadev.len());
    for (p, g) in full.points().iter().zip(oadev) {
        assert_relative_eq!(p.adev(), *g, max_relative = ADEV_AGREEMENT);
    }
    let dec = allan::analyse(y, Settings::new(rate).overlap(16)).unwrap();
    for (p, g) in dec.points().iter().zip(strided) {
        assert_eq!(p.stride(), (p.cluster() / 16).max(1));
        assert_relative_eq!(p.adev(), *g, max_relative = ADEV_AGREEMENT);
    }
}

#[test]
fn white_log_matches_allantools() {
    let y = white(golden::SAMPLES, golden::WHITE_SEED);
    check_log(
        &y,
        &golden::WHITE_FIRST,
        golden::WHITE_RATE_HZ,
        &golden::WHITE_OADEV,
        &golden::WHITE_STRIDED,
    );
}

#[test]
fn white_and_random_walk_log_matches_allantools() {
    let y = white_rw(golden::SAMPLES, golden::WHITE_RW_SEED);
    check_log(
        &y,
        &golden::WHITE_RW_FIRST,
        golden::WHITE_RW_RATE_HZ,
        &golden::WHITE_RW_OADEV,
        &golden::WHITE_RW_STRIDED,
    );
}

#[test]
fn gauss_markov_log_matches_allantools() {
    let y = gm(golden::SAMPLES, golden::GM_SEED);
    check_log(
        &y,
        &golden::GM_FIRST,
        golden::GM_RATE_HZ,
        &golden::GM_OADEV,
        &golden::GM_STRIDED,
    );
}

fn law(alpha: i32) -> PowerLaw {
    match alpha {
        2 => PowerLaw::Quantization,
        0 => PowerLaw::White,
        -1 => PowerLaw::Flicker,
        -2 => PowerLaw::RandomWalk,
        _ => unreachable!(),
    }
}

/// Our degrees of freedom are Greenhall and Riley's basic sum (F = infinity) as allantools
/// evaluates it, and agree with its complete algorithm where that uses the same model.
#[test]
fn degrees_of_freedom_match_allantools_greenhall() {
    for &(alpha, n, m, stride, basic, full) in &golden::EDF {
        let ours = allan::edf::edf(law(alpha), n, m, stride);
        assert_relative_eq!(ours, basic, max_relative = FORMULA_AGREEMENT);
        if m >= 64 && full.is_finite() {
            assert!(
                (ours / full - 1.0).abs() <= GREENHALL_TABLE_AGREEMENT,
                "alpha {alpha}, N {n}, m {m}: {ours} vs edf_greenhall {full}"
            );
        }
    }
}

/// The chi-squared intervals equal allantools.confidence_interval (SciPy's chi2.ppf).
#[test]
fn confidence_intervals_match_allantools() {
    for &(dev, edf, c, lo, hi) in &golden::INTERVALS {
        let (l, h) = allan::chi2::interval(dev, edf, c);
        assert_relative_eq!(l, lo, max_relative = FORMULA_AGREEMENT);
        assert_relative_eq!(h, hi, max_relative = FORMULA_AGREEMENT);
    }
    // the analysis uses the same intervals
    let y = white(4096, 9);
    let r = allan::analyse(
        &y,
        Settings::new(1.0).noise(NoiseModel::Fixed(PowerLaw::White)),
    )
    .unwrap();
    for p in r.points() {
        let (l, h) = allan::chi2::interval(p.adev(), p.edf(), allan::chi2::ONE_SIGMA);
        assert_eq!(
            (l.to_bits(), h.to_bits()),
            (p.lower().to_bits(), p.upper().to_bits())
        );
    }
}
