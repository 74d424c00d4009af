//! The modified, Hadamard and total deviations of the streaming estimator against direct
//! whole-log estimators written here from their definitions (NIST SP 1065 eqs 14, 18, 25),
//! fully overlapping and decimated, over logs spanning many blocks; the cluster-time grids.

mod common;

use allan::{Settings, Taus};
use approx::assert_relative_eq;
use common::Recipe;

/// Agreement of two sums of the same squares in different orders (relative, rounding).
const ROUNDING: f64 = 1e-9;

/// The phase x_0 = 0, x_t = sum of the first t samples minus their mean (the estimators
/// ignore a constant).
fn phase(y: &[f64]) -> Vec<f64> {
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let mut x = vec![0.0];
    for v in y {
        x.push(x[x.len() - 1] + v - mean);
    }
    x
}

/// Modified Allan deviation at cluster m, windows starting every `s` samples and ending
/// with x_N at the latest for s = 1 (SP 1065 eq 14), inside x_N for s > 1.
fn direct_mdev(x: &[f64], m: usize, s: usize) -> f64 {
    let n = x.len() - 1;
    let (mut sum, mut count) = (0.0, 0usize);
    let mut j = 0;
    while (s == 1 && j + 3 * m <= n + 1) || (s > 1 && j + 3 * m <= n) {
        let inner: f64 = (j..j + m)
            .map(|i| x[i + 2 * m] - 2.0 * x[i + m] + x[i])
            .sum();
        sum += inner * inner;
        count += 1;
        j += s;
    }
    (sum / (2.0 * (m as f64).powi(4) * count as f64)).sqrt()
}

/// Overlapping Hadamard deviation (SP 1065 eq 18), every `s` samples.
fn direct_hdev(x: &[f64], m: usize, s: usize) -> f64 {
    let n = x.len() - 1;
    let (mut sum, mut count) = (0.0, 0usize);
    let mut t = 3 * m;
    while t <= n {
        let d = x[t] - 3.0 * x[t - m] + 3.0 * x[t - 2 * m] - x[t - 3 * m];
        sum += d * d;
        count += 1;
        t += s;
    }
    (sum / (6.0 * (m as f64).powi(2) * count as f64)).sqrt()
}

/// Total deviation (SP 1065 eq 25): the phases at multiples of `s` reflected at both ends.
fn direct_totdev(x: &[f64], m: usize, s: usize) -> f64 {
    let xs: Vec<f64> = x.iter().step_by(s).copied().collect();
    let n = xs.len() - 1;
    let r = m / s;
    let at = |i: isize| -> f64 {
        if i < 0 {
            2.0 * xs[0] - xs[(-i) as usize]
        } else if i as usize > n {
            2.0 * xs[n] - xs[2 * n - i as usize]
        } else {
            xs[i as usize]
        }
    };
    let ri = r as isize;
    let sum: f64 = (1..n as isize)
        .map(|c| {
            let d = at(c - ri) - 2.0 * at(c) + at(c + ri);
            d * d
        })
        .sum();
    (sum / (2.0 * (m as f64).powi(2) * (n - 1) as f64)).sqrt()
}

fn recipe() -> Recipe {
    Recipe {
        bias: 2.0,
        white_sd: 0.1,
        rw_step: 1e-3,
        gauss_markov: vec![(0.05, 0.99)],
    }
}

/// Fully overlapping cluster sizes (m <= R = 64) and decimated ones (R = 4: m = 8 ... every
/// m/4 samples) equal the direct estimators over a log of 20,000 samples (five blocks).
#[test]
fn streaming_mdev_hdev_totdev_equal_direct_estimators() {
    let y = recipe().collect(20_000, 5);
    let x = phase(&y);
    for overlap in [64u64, 4] {
        let r = allan::analyse(&y, Settings::new(10.0).overlap(overlap)).unwrap();
        assert!(r.points().len() >= 12);
        for p in r.points() {
            let (m, s) = (p.cluster() as usize, p.stride() as usize);
            assert_eq!(
                s,
                if p.cluster() <= overlap {
                    1
                } else {
                    m / overlap as usize
                }
            );
            let what = format!("R = {overlap}, m = {m}");
            assert_relative_eq!(p.mdev(), direct_mdev(&x, m, s), max_relative = ROUNDING);
            assert_relative_eq!(p.hdev(), direct_hdev(&x, m, s), max_relative = ROUNDING);
            assert_relative_eq!(p.totdev(), direct_totdev(&x, m, s), max_relative = ROUNDING);
            let _ = what;
        }
    }
}

/// The grids: decade (1, 10, 100, ...), all (every size to 64, then 32 per octave), a list;
/// each point equals the direct estimators; a listed time the log is too short for is an
/// error naming it.
#[test]
fn decade_all_and_listed_cluster_times() {
    let y = recipe().collect(9_000, 6);
    let x = phase(&y);
    let sizes = |t: Taus| -> Vec<u64> {
        allan::analyse(&y, Settings::new(10.0).taus(t))
            .unwrap()
            .points()
            .iter()
            .map(|p| p.cluster())
            .collect()
    };
    assert_eq!(sizes(Taus::Decade), [1, 10, 100, 1000]);
    let all = sizes(Taus::All);
    assert_eq!(&all[..64], &(1..=64).collect::<Vec<u64>>()[..]);
    assert_eq!(&all[64..66], &[66, 68]);
    assert!(all.iter().all(|m| 3 * m <= 9_000) && *all.last().unwrap() > 2_900);
    let listed = Taus::List(vec![0.1, 30.0, 12.3, 299.9]);
    let r = allan::analyse(&y, Settings::new(10.0).taus(listed)).unwrap();
    let ms: Vec<u64> = r.points().iter().map(|p| p.cluster()).collect();
    assert_eq!(ms, [1, 123, 300, 2999]);
    for p in r.points() {
        let (m, s) = (p.cluster() as usize, p.stride() as usize);
        assert_relative_eq!(p.mdev(), direct_mdev(&x, m, s), max_relative = ROUNDING);
        assert_relative_eq!(p.hdev(), direct_hdev(&x, m, s), max_relative = ROUNDING);
        assert_relative_eq!(p.totdev(), direct_totdev(&x, m, s), max_relative = ROUNDING);
    }
    let e = allan::analyse(&y, Settings::new(10.0).taus(Taus::List(vec![1.0, 300.1]))).unwrap_err();
    assert!(
        matches!(
            e,
            allan::AllanError::ClusterTooLong {
                needed: 9003,
                samples: 9000,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("`300.1` s"), "{e}");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 0.05, 0.15] {
        let e = allan::StreamingAllan::new(Settings::new(10.0).taus(Taus::List(vec![bad])))
            .unwrap_err();
        assert!(
            matches!(e, allan::AllanError::InvalidTau { .. }),
            "{bad}: {e:?}"
        );
        assert!(e.to_string().starts_with("taus: "), "{e}");
    }
}
