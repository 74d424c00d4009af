//! The streaming estimator against a direct, whole-log overlapping Allan deviation written
//! independently in the test (cluster means, not phase; no blocks, no rings).

mod common;

use allan::{NoiseModel, PowerLaw, Settings, StreamingAllan};
use approx::assert_relative_eq;
use common::{Recipe, direct_oadev};

/// Relative agreement of the streaming and direct deviations (dimensionless): both sum the
/// same squares in a different order and build the differences from a running phase or from
/// compensated prefix sums; 1e-9 is rounding for logs of 10^5 samples with a large bias.
const ROUNDING: f64 = 1e-9;

fn log() -> (Recipe, Vec<f64>) {
    let mut r = Recipe::white(0.3);
    r.rw_step = 1e-3;
    r.bias = 250.0;
    let y = r.collect(100_003, 21);
    (r, y)
}

/// The decimated overlapping deviation (evaluations every `stride` samples), directly.
fn direct_strided(y: &[f64], m: usize, stride: usize) -> f64 {
    let mean = |a: usize| y[a..a + m].iter().sum::<f64>() / m as f64;
    let mut sum = 0.0;
    let mut terms = 0usize;
    let mut t = 0;
    while t + 2 * m <= y.len() {
        let d = mean(t + m) - mean(t);
        sum += d * d;
        terms += 1;
        t += stride;
    }
    (sum / (2.0 * terms as f64)).sqrt()
}

/// Fully overlapping cluster sizes (m <= R) equal the textbook overlapping Allan deviation
/// (every window of m samples) to rounding; the cluster times run from one sample to the
/// longest with three clusters.
#[test]
fn streaming_equals_direct_overlapping_adev_to_rounding() {
    let (_, y) = log();
    let rate = 50.0;
    let settings = Settings::new(rate).overlap(1 << 16);
    let r = allan::analyse(&y, settings).unwrap();
    let expected_levels = (0..).take_while(|k| 3 * (1usize << k) <= y.len()).count();
    assert_eq!(r.points().len(), expected_levels);
    assert_eq!(r.points()[0].cluster(), 1);
    for p in r.points() {
        assert_eq!(p.stride(), 1, "m = {} is fully overlapping", p.cluster());
        assert_eq!(p.terms(), y.len() as u64 - 2 * p.cluster() + 1);
        assert_relative_eq!(p.tau_s(), p.cluster() as f64 / rate, max_relative = 1e-15);
        let direct = direct_oadev(&y, p.cluster() as usize);
        assert_relative_eq!(p.adev(), direct, max_relative = ROUNDING);
    }
}

/// Beyond R samples the clusters are evaluated every m/R samples: equal to the same strided
/// estimator computed directly.
#[test]
fn decimated_levels_equal_the_direct_strided_estimator() {
    let (_, y) = log();
    let r = allan::analyse(&y, Settings::new(1.0).overlap(8)).unwrap();
    let mut decimated = 0;
    for p in r.points() {
        let expected_stride = (p.cluster() / 8).max(1);
        assert_eq!(p.stride(), expected_stride);
        let direct = direct_strided(&y, p.cluster() as usize, p.stride() as usize);
        assert_relative_eq!(p.adev(), direct, max_relative = ROUNDING);
        if p.stride() > 1 {
            decimated += 1;
        }
    }
    assert!(decimated >= 10);
}

/// One sample at a time, slices of any size, and a file read in blocks give the same result
/// bit for bit (the blocks are formed the same way whatever the pushes).
#[test]
fn pushes_and_slices_of_any_size_give_identical_results() {
    let (_, y) = log();
    let settings = Settings::new(10.0).noise(NoiseModel::Fixed(PowerLaw::White));
    let mut one = StreamingAllan::new(settings.clone()).unwrap();
    for &v in &y {
        one.push(v).unwrap();
    }
    let mut sliced = StreamingAllan::new(settings).unwrap();
    let mut rest = &y[..];
    let mut k = 1;
    while !rest.is_empty() {
        let take = (k * 7919 % 10_007).min(rest.len());
        sliced.extend(&rest[..take]).unwrap();
        rest = &rest[take..];
        k += 1;
    }
    assert_eq!(one.analyse().unwrap(), sliced.analyse().unwrap());
}

/// Analysing part way and going on gives the same curve (to rounding) as one analysis at the
/// end: the pending block is folded in, not lost or counted twice.
#[test]
fn analysing_part_way_then_continuing_loses_nothing() {
    let (_, y) = log();
    let settings = Settings::new(10.0);
    let mut a = StreamingAllan::new(settings.clone()).unwrap();
    a.extend(&y[..33_333]).unwrap();
    let early = a.analyse().unwrap();
    assert_eq!(early.samples(), 33_333);
    a.extend(&y[33_333..]).unwrap();
    let late = a.analyse().unwrap();
    let once = allan::analyse(&y, settings).unwrap();
    assert_eq!(late.points().len(), once.points().len());
    for (p, q) in late.points().iter().zip(once.points()) {
        assert_eq!(p.terms(), q.terms());
        assert_relative_eq!(p.adev(), q.adev(), max_relative = ROUNDING);
    }
}

/// A constant offset (a gyro's bias, the earth's rate) leaves the curve unchanged, to the
/// precision of the offset samples themselves (an offset of 1e4 on samples of 0.3 keeps 12
/// of their 16 digits).
#[test]
fn a_constant_offset_leaves_the_curve_unchanged() {
    let (_, y) = log();
    let shifted: Vec<f64> = y.iter().map(|v| v + 1e4).collect();
    let a = allan::analyse(&y, Settings::new(1.0)).unwrap();
    let b = allan::analyse(&shifted, Settings::new(1.0)).unwrap();
    for (p, q) in a.points().iter().zip(b.points()) {
        assert_relative_eq!(p.adev(), q.adev(), max_relative = 1e-8);
    }
}
