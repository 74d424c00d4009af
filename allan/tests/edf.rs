//! The equivalent degrees of freedom against the exact variance of the estimator's quadratic
//! form, computed by brute force from the covariance of the second differences; the cost of
//! decimation; chi-squared quantiles.

use allan::PowerLaw;
use allan::chi2::{chi2_quantile, gamma_pq, interval};
use allan::edf::{edf, terms};
use approx::assert_relative_eq;

/// Satterthwaite's degrees of freedom of sum_i d_i^2 for Gaussian d = C z, z iid:
/// (tr S)^2 / tr(S^2) with S = C C^T.
fn brute_force(c: &[Vec<f64>]) -> f64 {
    let n = c.len();
    let mut s = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..n {
            s[i][j] = c[i].iter().zip(&c[j]).map(|(a, b)| a * b).sum();
        }
    }
    let tr: f64 = (0..n).map(|i| s[i][i]).sum();
    let tr2: f64 = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| s[i][j] * s[j][i])
        .sum();
    tr * tr / tr2
}

/// Rows of the second differences d_t = x_{t+2m} - 2 x_{t+m} + x_t (t = 0, s, 2s, ...) as
/// combinations of the log's N samples (white noise: x is their running sum) or of its N + 1
/// phase values (quantization: x itself white), or of the N increments of a random walk.
fn rows(noise: PowerLaw, samples: usize, m: usize, stride: usize) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    let mut t = 0;
    while t + 2 * m <= samples {
        let row = match noise {
            PowerLaw::Quantization => {
                let mut r = vec![0.0; samples + 1];
                r[t] += 1.0;
                r[t + m] -= 2.0;
                r[t + 2 * m] += 1.0;
                r
            }
            _ => {
                // coefficient of sample j: +1 in the second window, -1 in the first
                let mut r = vec![0.0; samples];
                for v in &mut r[t..t + m] {
                    *v -= 1.0;
                }
                for v in &mut r[t + m..t + 2 * m] {
                    *v += 1.0;
                }
                if noise == PowerLaw::RandomWalk {
                    // sample j = sum of increments 0..=j
                    let mut acc = 0.0;
                    let mut inc = vec![0.0; samples];
                    for j in (0..samples).rev() {
                        acc += r[j];
                        inc[j] = acc;
                    }
                    inc
                } else {
                    r
                }
            }
        };
        out.push(row);
        t += stride;
    }
    out
}

/// White noise (iid samples) and quantization (white phase) are exact: the degrees of
/// freedom equal the brute-force quadratic form's to rounding, overlapping, decimated and not
/// overlapping, down to a single term.
#[test]
fn white_and_quantization_degrees_of_freedom_are_exact() {
    for noise in [PowerLaw::White, PowerLaw::Quantization] {
        for samples in [7usize, 40, 61] {
            for m in [1usize, 2, 4, 8, 16] {
                if 2 * m > samples {
                    continue;
                }
                for stride in [1, 2, 4, 8, 16].into_iter().filter(|s| m % s == 0) {
                    let c = rows(noise, samples, m, stride);
                    assert_eq!(
                        c.len() as u64,
                        terms(samples as u64, m as u64, stride as u64)
                    );
                    let exact = brute_force(&c);
                    let ours = edf(noise, samples as u64, m as u64, stride as u64);
                    assert_relative_eq!(ours, exact, max_relative = 1e-12);
                }
            }
        }
    }
}

/// Relative difference allowed between the continuous random-walk model of the degrees of
/// freedom (|t|^3 generalized autocovariance, Greenhall and Riley's F = infinity) and the
/// exact value for a discrete random walk of the samples (dimensionless): the models differ
/// by terms of order 1/m^2 in the covariances; 6 % at m >= 4 (measured: 3.1 % at m = 4,
/// 0.8 % at m = 8, 0.2 % at m = 16).
const RANDOM_WALK_MODEL: f64 = 0.06;

/// A random walk of the samples is close to the continuous model from m = 4 on.
#[test]
fn random_walk_degrees_of_freedom_match_a_discrete_random_walk() {
    for (samples, m, stride) in [
        (64usize, 4usize, 1usize),
        (64, 8, 1),
        (96, 16, 4),
        (96, 8, 8),
    ] {
        let exact = brute_force(&rows(PowerLaw::RandomWalk, samples, m, stride));
        let ours = edf(
            PowerLaw::RandomWalk,
            samples as u64,
            m as u64,
            stride as u64,
        );
        assert!(
            (ours / exact - 1.0).abs() <= RANDOM_WALK_MODEL,
            "N {samples}, m {m}, s {stride}: {ours} vs {exact}"
        );
    }
}

/// What decimation costs: with R = 256 evaluations per cluster time the white, flicker and
/// random-walk degrees of freedom stay within 0.1 % of the fully overlapping estimator's
/// (the overlap gain is saturated long before); quantization noise, whose differences are
/// independent beyond lag 2m, keeps only R/m of them.
#[test]
fn decimation_costs_no_degrees_of_freedom_except_for_quantization() {
    let n = 1u64 << 27;
    for m in [512u64, 4096, 1 << 14, 1 << 17, 1 << 22] {
        for noise in [PowerLaw::White, PowerLaw::Flicker, PowerLaw::RandomWalk] {
            let full = edf(noise, n, m, 1);
            let dec = edf(noise, n, m, m / 256);
            assert!(
                (dec / full - 1.0).abs() < 1e-3,
                "{noise} m {m}: {dec} vs {full}"
            );
        }
        let full = edf(PowerLaw::Quantization, n, m, 1);
        let dec = edf(PowerLaw::Quantization, n, m, m / 256);
        assert_relative_eq!(dec / full, 256.0 / m as f64, max_relative = 0.01);
    }
}

/// More samples, more degrees of freedom; longer clusters, fewer (every type).
#[test]
fn degrees_of_freedom_grow_with_samples_and_shrink_with_cluster_time() {
    for noise in PowerLaw::ALL {
        let mut last = f64::INFINITY;
        for k in 0..18 {
            let m = 1u64 << k;
            let v = edf(noise, 1 << 20, m, (m / 64).max(1));
            assert!(
                v > 0.0 && v.is_finite() && v < last * 1.001,
                "{noise} m {m}: {v} after {last}"
            );
            last = v;
        }
        assert!(edf(noise, 1 << 21, 64, 1) > edf(noise, 1 << 20, 64, 1));
    }
    assert_eq!(
        edf(PowerLaw::White, 3, 2, 1).to_bits(),
        0.0f64.to_bits(),
        "no term: N < 2m"
    );
}

/// Chi-squared quantiles against published values (to the printed digits) and the
/// regularized gamma functions' identities.
#[test]
fn chi_squared_quantiles_match_published_values() {
    // printed to 3-5 digits in any table (Abramowitz & Stegun 26.8); full digits: scipy.stats.chi2.ppf
    for (nu, p, q) in [
        (1.0, 0.5, 0.454_936_423_119_572_8),
        (10.0, 0.95, 18.307_038_053_275_146),
        (2.0, 0.1, 0.210_721_031_315_652_6), // -2 ln 0.9
        (100.0, 0.99, 135.806_723_171_026_76),
    ] {
        assert_relative_eq!(chi2_quantile(nu, p), q, max_relative = 1e-12);
    }
    // P + Q = 1 and the exponential case P(1, x) = 1 - e^-x
    for (a, x) in [(0.3, 0.1), (1.0, 2.5), (7.5, 3.0), (5e7, 5.0001e7)] {
        let (p, q) = gamma_pq(a, x);
        assert_relative_eq!(p + q, 1.0, max_relative = 1e-14);
    }
    assert_relative_eq!(
        gamma_pq(1.0, 2.5).0,
        1.0 - (-2.5f64).exp(),
        max_relative = 1e-14
    );
    // a band at huge degrees of freedom: the normal limit sigma (1 -+ 1/sqrt(2 nu))
    let (lo, hi) = interval(1.0, 1e8, allan::chi2::ONE_SIGMA);
    assert_relative_eq!(1.0 - lo, (2e8f64).sqrt().recip(), max_relative = 1e-3);
    assert_relative_eq!(hi - 1.0, (2e8f64).sqrt().recip(), max_relative = 1e-3);
}
