//! Statistics against theory. To first order (eq 26) dtheta = dphi_z2 + dalpha_z1 at every
//! pose; with LB = 0 each term is uniform on [-UB, UB] (uniform magnitude, fair sign), so
//! dtheta has variance (UB_z2^2 + UB_z1^2) / 3 and the trapezoidal (triangular when the two
//! bounds are equal, as in Table 4) density of a sum of two uniforms.

mod common;

use common::table4;
use mc_verify::{ErrorBox, McConfig, MonteCarlo, TurntableSampler, chunk_rng};
use tt_kinematics::units::arcmin_to_rad;
use tt_kinematics::{ErrorComponent, OrientationAxis};

const SAMPLES: u64 = 1_000_000;

/// Acceptance in standard errors for every statistical comparison (a Gaussian 5-sigma event
/// has probability 6e-7; the seed is fixed, so the test is deterministic anyway).
const SIGMAS: f64 = 5.0;

/// CDF of X + Y, X ~ U(-a, a), Y ~ U(-b, b) independent.
fn sum_of_uniforms_cdf(z: f64, a: f64, b: f64) -> f64 {
    let r = |t: f64| if t > 0.0 { 0.5 * t * t } else { 0.0 };
    (r(z + a + b) - r(z - a + b) - r(z + a - b) + r(z - a - b)) / (4.0 * a * b)
}

fn theta_theory(bounds: &ErrorBox, seed: u64) {
    let ub = bounds.ub_rad();
    let (a, b) = (
        ub[ErrorComponent::DphiZ2.index()],
        ub[ErrorComponent::DalphaZ1.index()],
    );
    let r = MonteCarlo::new(*bounds, McConfig::new(SAMPLES, seed))
        .unwrap()
        .run();
    let theta = r.axis(OrientationAxis::Theta);
    let n = SAMPLES as f64;

    // moments of U(-a,a) + U(-b,b): variance s2, fourth central moment mu4
    let s2 = (a * a + b * b) / 3.0;
    let mu4 = (a.powi(4) + b.powi(4)) / 5.0 + 6.0 * (a * a / 3.0) * (b * b / 3.0);
    // mean: standard error sqrt(s2 / n)
    assert!(
        theta.mean_rad.abs() <= SIGMAS * (s2 / n).sqrt(),
        "mean {} rad",
        theta.mean_rad
    );
    // variance: standard error of the sample variance sqrt((mu4 - s2^2) / n)
    let var = theta.variance_rad2(SAMPLES);
    let se_var = ((mu4 - s2 * s2) / n).sqrt();
    assert!(
        (var - s2).abs() <= SIGMAS * se_var,
        "variance {var} vs theory {s2} (se {se_var})"
    );
    // histogram: every bin against its binomial expectation
    let h = &theta.histogram;
    let edges = h.edges_rad();
    let mut worst_z = 0.0_f64;
    for (j, &count) in h.counts.iter().enumerate() {
        let p = sum_of_uniforms_cdf(edges[j + 1], a, b) - sum_of_uniforms_cdf(edges[j], a, b);
        let expected = n * p;
        let sd = (n * p * (1.0 - p)).sqrt().max(1.0);
        let z = (count as f64 - expected).abs() / sd;
        worst_z = worst_z.max(z);
        assert!(
            z <= SIGMAS,
            "bin {j}: {count} vs {expected:.1} expected ({z:.1} sigma)"
        );
    }
    assert!(worst_z > 0.0);
}

#[test]
fn delta_theta_matches_triangular_law_of_two_equal_uniforms_with_table4_bounds() {
    theta_theory(&table4(), 31);
}

#[test]
fn delta_theta_matches_trapezoidal_law_of_two_unequal_uniforms() {
    let mut ub = [0.3; 8];
    ub[ErrorComponent::DphiZ2.index()] = 0.9;
    ub[ErrorComponent::DalphaZ1.index()] = 0.35;
    let b = ErrorBox::from_upper_rad(ub.map(arcmin_to_rad)).unwrap();
    theta_theory(&b, 32);
}

/// The sampling law itself (NOTES item 15): |chi_i| uniform in [LB_i, UB_i], fair signs.
#[test]
fn sampler_draws_uniform_magnitudes_in_the_box_with_fair_signs() {
    let lb = [0.1, 0.0, 0.2, 0.3, 0.0, 0.05, 0.1, 0.2].map(arcmin_to_rad);
    let ub = [0.4, 0.8, 0.4, 0.8, 0.3, 0.3, 0.4, 0.4].map(arcmin_to_rad);
    let s = TurntableSampler::new(&ErrorBox::new(lb, ub).unwrap());
    let n = 200_000;
    let mut rng = chunk_rng(5, 0);
    let mut positive = [0u64; 8];
    let mut mag_sum = [0.0; 8];
    for _ in 0..n {
        let (pose, chi) = s.sample(&mut rng);
        assert!((0.0..std::f64::consts::TAU).contains(&pose.phi1_rad));
        assert!((0.0..std::f64::consts::TAU).contains(&pose.phi2_rad));
        for i in 0..8 {
            assert!(
                chi[i].abs() >= lb[i] && chi[i].abs() <= ub[i],
                "{i}: {}",
                chi[i]
            );
            positive[i] += u64::from(chi[i] > 0.0);
            mag_sum[i] += chi[i].abs();
        }
    }
    let nf = f64::from(n);
    for i in 0..8 {
        // sign: binomial(n, 1/2), sd sqrt(n)/2
        let z = (positive[i] as f64 - nf / 2.0).abs() / (nf.sqrt() / 2.0);
        assert!(z <= SIGMAS, "component {i}: sign z = {z}");
        // magnitude mean (LB + UB) / 2, sd of the mean (UB - LB) / sqrt(12 n)
        let w = ub[i] - lb[i];
        let z = (mag_sum[i] / nf - 0.5 * (lb[i] + ub[i])).abs() / (w / (12.0 * nf).sqrt());
        assert!(z <= SIGMAS, "component {i}: magnitude z = {z}");
    }
}
