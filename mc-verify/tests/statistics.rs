//! Statistics against theory. To first order (eq 26) dtheta = dphi_z2 + dalpha_z1 at every
//! pose of the paper's table; with LB = 0 each term is uniform on [-UB, UB] (uniform
//! magnitude, fair sign), so dtheta has variance (UB_z2^2 + UB_z1^2) / 3 and the trapezoidal
//! (triangular when the two bounds are equal, as in Table 4) density of a sum of two
//! uniforms. And the sampling law itself: magnitudes, signs, joint angles in their ranges.

mod common;

use common::{config, paper_table, table4, three_axis, three_axis_box};
use mc_verify::{ErrorBox, MonteCarlo, TurntableSampler, chunk_rng};
use std::f64::consts::TAU;
use tt_core::units::arcmin_to_rad;
use tt_kinematics::{
    FactorSpec, OrientationAxis, SignedAxis, Turntable, TurntableDescription, paper,
};

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
        ub[paper::chi_index("dphi_z2")],
        ub[paper::chi_index("dalpha_z1")],
    );
    let r = MonteCarlo::new(&paper_table(), bounds.clone(), config(SAMPLES, seed))
        .unwrap()
        .run();
    let theta = r.axis(OrientationAxis::Theta);
    let n = SAMPLES as f64;

    // moments of U(-a,a) + U(-b,b): variance s2, fourth central moment mu4
    let s2 = (a * a + b * b) / 3.0;
    let mu4 = (a.powi(4) + b.powi(4)) / 5.0 + 6.0 * (a * a / 3.0) * (b * b / 3.0);
    // mean: standard error sqrt(s2 / n)
    assert!(
        theta.mean_rad().abs() <= SIGMAS * (s2 / n).sqrt(),
        "mean {} rad",
        theta.mean_rad()
    );
    // variance: standard error of the sample variance sqrt((mu4 - s2^2) / n)
    let var = theta.variance_rad2(SAMPLES);
    let se_var = ((mu4 - s2 * s2) / n).sqrt();
    assert!(
        (var - s2).abs() <= SIGMAS * se_var,
        "variance {var} vs theory {s2} (se {se_var})"
    );
    // histogram: every bin against its binomial expectation
    let h = &theta.histogram();
    let edges = h.edges();
    let mut worst_z = 0.0_f64;
    for (j, &count) in h.counts().iter().enumerate() {
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
    ub[paper::chi_index("dphi_z2")] = 0.9;
    ub[paper::chi_index("dalpha_z1")] = 0.35;
    let b = ErrorBox::from_upper_rad(&paper_table(), ub.map(arcmin_to_rad).to_vec()).unwrap();
    theta_theory(&b, 32);
}

/// The sampling law itself (NOTES item 15): |chi_i| uniform in [LB_i, UB_i], fair signs, on
/// both tables.
#[test]
fn sampler_draws_uniform_magnitudes_in_the_box_with_fair_signs() {
    let lb8 = [0.1, 0.0, 0.2, 0.3, 0.0, 0.05, 0.1, 0.2];
    let ub8 = [0.4, 0.8, 0.4, 0.8, 0.3, 0.3, 0.4, 0.4];
    for t in [paper_table(), three_axis()] {
        let m = t.n_rotation_errors();
        let lb: Vec<f64> = (0..m).map(|i| arcmin_to_rad(lb8[i % 8])).collect();
        let ub: Vec<f64> = (0..m).map(|i| arcmin_to_rad(ub8[i % 8])).collect();
        let s = TurntableSampler::new(&ErrorBox::new(&t, lb.clone(), ub.clone()).unwrap(), &t);
        let n = 200_000;
        let mut rng = chunk_rng(5, 0);
        let mut positive = vec![0u64; m];
        let mut mag_sum = vec![0.0; m];
        for _ in 0..n {
            let (pose, chi) = s.sample(&mut rng);
            assert!(pose.angles_rad().iter().all(|a| (0.0..TAU).contains(a)));
            for i in 0..m {
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
        for i in 0..m {
            // sign: binomial(n, 1/2), sd sqrt(n)/2
            let z = (positive[i] as f64 - nf / 2.0).abs() / (nf.sqrt() / 2.0);
            assert!(z <= SIGMAS, "component {i}: sign z = {z}");
            // magnitude mean (LB + UB) / 2, sd of the mean (UB - LB) / sqrt(12 n)
            let w = ub[i] - lb[i];
            let z = (mag_sum[i] / nf - 0.5 * (lb[i] + ub[i])).abs() / (w / (12.0 * nf).sqrt());
            assert!(z <= SIGMAS, "component {i}: magnitude z = {z}");
        }
    }
}

/// Bins of the uniformity check of joint angles.
const ANGLE_BINS: usize = 20;

/// Every joint angle lies in its range and is uniform there (20 bins each within 5 sigma of
/// the binomial expectation), for full-turn joints, ranged joints (including one whose range
/// is a full turn starting at -pi, and a narrow one) and joints that cancel (drawn anyway).
#[test]
fn joint_angles_are_uniform_inside_their_ranges() {
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    let j = FactorSpec::joint;
    let e = FactorSpec::error;
    let mut d = TurntableDescription::new(vec![
        j("cancels", z),
        e("e1", x),
        j("half", y),
        e("e2", z),
        j("signed_turn", x),
        e("e3", y),
        j("narrow", z),
        e("e4", x),
        j("full", y),
    ]);
    d.joint_ranges_rad = vec![
        ("cancels".into(), [-1.0, 0.5]),
        (
            "half".into(),
            [-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2],
        ),
        (
            "signed_turn".into(),
            [-std::f64::consts::PI, std::f64::consts::PI],
        ),
        ("narrow".into(), [0.25, 0.25 + 1e-6]),
    ];
    let t = Turntable::new(&d).unwrap();
    let ranges = t.joint_ranges_rad();
    assert_eq!(ranges[4].map(f64::to_bits), [0.0, TAU].map(f64::to_bits));
    let b = ErrorBox::from_upper_rad(&t, vec![1e-4; 4]).unwrap();
    let s = TurntableSampler::new(&b, &t);
    let mut block = mc_verify::SampleBlock::new(&s);
    let mut rng = chunk_rng(8, 1);
    let n = 100_000;
    let mut counts = vec![[0u64; ANGLE_BINS]; t.n_joints()];
    let mut drawn = 0;
    while drawn < n {
        s.fill_block(&mut rng, mc_verify::BLOCK_CAPACITY, &mut block);
        for k in 0..block.len() {
            for (m, (&a, [lo, hi])) in block.pose(k).angles_rad().iter().zip(&ranges).enumerate() {
                assert!(
                    (*lo..=*hi).contains(&a),
                    "joint {m}: {a} outside [{lo}, {hi}]"
                );
                let bin = (((a - lo) / (hi - lo)) * ANGLE_BINS as f64) as usize;
                counts[m][bin.min(ANGLE_BINS - 1)] += 1;
            }
        }
        drawn += block.len();
    }
    let p = 1.0 / ANGLE_BINS as f64;
    let nf = drawn as f64;
    for (m, c) in counts.iter().enumerate() {
        for &count in c {
            let z = (count as f64 - nf * p).abs() / (nf * p * (1.0 - p)).sqrt();
            assert!(
                z <= SIGMAS,
                "joint {m}: {count} vs {} ({z:.1} sigma)",
                nf * p
            );
        }
    }
    // the run evaluates this table too (ranged joints through the table reduction), and its
    // worst samples carry every joint, the cancelling one included
    let r = MonteCarlo::new(&t, b, config(20_000, 2)).unwrap().run();
    for a in r.axes() {
        let pose = a.worst().pose().angles_rad();
        assert_eq!(pose.len(), 5);
        assert!(
            pose.iter()
                .zip(&ranges)
                .all(|(a, [lo, hi])| (*lo..=*hi).contains(a))
        );
    }
}

/// Joints that cancel are drawn like the others: the outer joint of the three-axis table
/// (before the first error) is uniform on [0, 2 pi) in the worst samples' poses and in the
/// sampler.
#[test]
fn cancelling_joints_are_drawn_uniformly() {
    let t = three_axis();
    assert_eq!(t.free_joints(), [1, 2]);
    let s = TurntableSampler::new(&three_axis_box(), &t);
    let mut rng = chunk_rng(3, 0);
    let n = 100_000;
    let mean: f64 = (0..n)
        .map(|_| s.sample(&mut rng).0.angles_rad()[0])
        .sum::<f64>()
        / f64::from(n);
    // uniform on [0, 2 pi): mean pi, sd of the mean 2 pi / sqrt(12 n)
    let z = (mean - std::f64::consts::PI).abs() / (TAU / (12.0 * f64::from(n)).sqrt());
    assert!(z <= SIGMAS, "mean {mean}: {z} sigma");
}
