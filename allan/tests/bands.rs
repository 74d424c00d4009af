//! Confidence bands and equivalent degrees of freedom against repeated seeded logs.

mod common;

use allan::{NoiseModel, PowerLaw, Settings};
use common::Recipe;

/// Half-width of the acceptance interval of a binomial count, in standard deviations of the
/// count (dimensionless): 4.5, a false failure below 7e-6 per cluster time and setting, under
/// 2e-4 for the about 25 counts tested.
const BINOMIAL_SIGMAS: f64 = 4.5;

/// Slack for the chi-squared approximation itself (the estimate is a weighted sum of
/// chi-squared variables, not one; the coverage of its interval differs from the nominal one by
/// a few percent at a handful of degrees of freedom; fraction of the runs): 0.04.
const CHI2_APPROXIMATION: f64 = 0.04;

/// Logs per coverage test.
const RUNS: u64 = 400;

fn coverage(settings: Settings, samples: u64) -> Vec<(u64, f64, u64)> {
    let recipe = Recipe::white(1.0);
    let mut hits: Vec<u64> = Vec::new();
    let mut first = None;
    for seed in 0..RUNS {
        let y = recipe.collect(samples, 1000 + seed);
        let r = allan::analyse(&y, settings.clone()).unwrap();
        if hits.is_empty() {
            hits = vec![0; r.points().len()];
            first = Some(r.clone());
        }
        for (h, p) in hits.iter_mut().zip(r.points()) {
            let truth = recipe.avar(p.cluster()).sqrt();
            if p.lower() <= truth && truth <= p.upper() {
                *h += 1;
            }
        }
    }
    let first = first.unwrap();
    first
        .points()
        .iter()
        .zip(hits)
        .map(|(p, h)| (p.cluster(), p.edf(), h))
        .collect()
}

fn check(settings: Settings, samples: u64, confidence: f64) {
    let n = RUNS as f64;
    let sd = (n * confidence * (1.0 - confidence)).sqrt();
    for (m, edf, hits) in coverage(settings.confidence(confidence), samples) {
        let lo = n * (confidence - CHI2_APPROXIMATION) - BINOMIAL_SIGMAS * sd;
        let hi = n * (confidence + CHI2_APPROXIMATION) + BINOMIAL_SIGMAS * sd;
        let h = hits as f64;
        eprintln!("COV m={m} edf={edf:.1} {:.3}", h / n);
        assert!(
            lo <= h && h <= hi,
            "m = {m} (edf {edf:.1}): {hits} of {RUNS} bands hold the truth, expected {:.0} in [{lo:.0}, {hi:.0}]",
            n * confidence
        );
    }
}

/// The default 1-sigma (68.3 %) bands hold the exact Allan deviation of white noise in 68.3 %
/// of the logs at every cluster time, fully overlapping (m <= R = 16) and decimated.
#[test]
fn one_sigma_bands_cover_the_truth_at_the_stated_rate() {
    check(
        Settings::new(1.0)
            .overlap(16)
            .noise(NoiseModel::Fixed(PowerLaw::White)),
        1 << 12,
        allan::chi2::ONE_SIGMA,
    );
}

/// With the noise type identified from the curve's slope (the default) the coverage holds too.
#[test]
fn identified_noise_bands_cover_the_truth_at_the_stated_rate() {
    check(
        Settings::new(1.0).overlap(16),
        1 << 12,
        allan::chi2::ONE_SIGMA,
    );
}

/// A settable confidence: 95 % bands hold the truth in 95 % of the logs.
#[test]
fn ninety_five_percent_bands_cover_the_truth_at_the_stated_rate() {
    check(
        Settings::new(1.0)
            .overlap(16)
            .noise(NoiseModel::Fixed(PowerLaw::White)),
        1 << 12,
        0.95,
    );
}

/// Relative error allowed between the predicted equivalent degrees of freedom and those
/// measured from the scatter of the estimates over the runs (dimensionless): the measured
/// 2 mean^2 / var has a relative standard error of about sqrt(2 / runs) = 4.5 % at 1000
/// runs (more with the heavy tail at few degrees of freedom); 25 % is over five of them.
const EDF_SCATTER: f64 = 0.25;

/// The predicted degrees of freedom match the scatter of the Allan variance over 1000 white
/// logs (2 mean^2 / var of the estimate), fully overlapping (R = 1024) and decimated (R = 4):
/// a wrong overlap factor (a factor of 1.5 to 2 at these sizes) would fail.
#[test]
fn predicted_degrees_of_freedom_match_the_scatter_of_the_estimate() {
    let recipe = Recipe::white(1.0);
    let runs = 1000u64;
    let samples = 1u64 << 10;
    let mut checked = [0, 0];
    for overlap in [4, 1024] {
        let settings = Settings::new(1.0)
            .overlap(overlap)
            .noise(NoiseModel::Fixed(PowerLaw::White));
        let mut sums: Vec<(f64, f64)> = Vec::new();
        let mut edfs = Vec::new();
        for seed in 0..runs {
            let y = recipe.collect(samples, 50_000 + seed);
            let r = allan::analyse(&y, settings.clone()).unwrap();
            if sums.is_empty() {
                sums = vec![(0.0, 0.0); r.points().len()];
                edfs = r
                    .points()
                    .iter()
                    .map(|p| (p.cluster(), p.stride(), p.edf()))
                    .collect();
            }
            for (s, p) in sums.iter_mut().zip(r.points()) {
                let v = p.adev() * p.adev();
                s.0 += v;
                s.1 += v * v;
            }
        }
        let n = runs as f64;
        for ((m, stride, edf), (s1, s2)) in edfs.iter().zip(sums) {
            if *edf > 200.0 || *edf < 3.0 {
                continue; // too precise to see, or too heavy-tailed
            }
            let mean = s1 / n;
            let var = (s2 - n * mean * mean) / (n - 1.0);
            let measured = 2.0 * mean * mean / var;
            assert!(
                (measured / edf - 1.0).abs() <= EDF_SCATTER,
                "m = {m}, stride {stride}: predicted {edf:.2}, measured {measured:.2}"
            );
            checked[usize::from(*stride > 1)] += 1;
        }
    }
    assert!(checked[0] >= 4 && checked[1] >= 4, "{checked:?}");
}
