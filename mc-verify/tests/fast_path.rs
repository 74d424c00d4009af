//! The fast quaternion path equals the plain dense-matrix chain (eq 17-24) to rounding.

mod common;

use approx::assert_abs_diff_eq;
use common::table4;
use mc_verify::fast::sin_cos_turn;
use mc_verify::{ErrorBox, FastChain, McConfig, MonteCarlo, fast_delta_rad};
use proptest::prelude::*;
use tt_kinematics::units::{arcmin_to_rad, deg_to_rad};
use tt_kinematics::{ExactChain, OrientationErrorModel, Pose, TurntableErrors};

/// Fast path against the plain chain, rad: the per-sample bound. The plain chain's
/// own rounding (ten 3x3 products of entries near 1) is a few 1e-16.
const FAST_VS_PLAIN_ABS_RAD: f64 = 1e-15;

/// Same, for large errors (up to 0.5 rad, the `f64::sin_cos` fall-back): the matrix entries
/// are no longer near 0 and 1, so the plain chain's rounding grows to ~1e-15.
const FAST_VS_PLAIN_LARGE_ABS_RAD: f64 = 4e-15;

/// `sin_cos_turn` against `f64::sin_cos` of the rounded angle: the angle itself is rounded
/// to 1/2 ulp of 2 pi (4.4e-16) plus ~2 ulp of evaluation.
const SIN_COS_TURN_ABS: f64 = 1e-15;

fn chi_strategy(max_arcmin: f64) -> impl Strategy<Value = [f64; 8]> {
    proptest::array::uniform8(-max_arcmin..=max_arcmin).prop_map(|a| a.map(arcmin_to_rad))
}

proptest! {
    /// Issue 5: "It must equal the exact chain to 1e-15 rad per sample", for errors up to
    /// 10 arcmin (beyond Table 4's 0.78) and any pose.
    #[test]
    fn fast_chain_equals_plain_exact_chain_within_1e_15_rad_up_to_10_arcmin(
        chi in chi_strategy(10.0),
        phi1 in 0.0..std::f64::consts::TAU,
        phi2 in 0.0..std::f64::consts::TAU,
    ) {
        let pose = Pose::new(phi1, phi2).unwrap();
        let errors = TurntableErrors::from_rad(chi, 0.0).unwrap();
        let plain = ExactChain::default().orientation_error(&pose, &errors).to_array();
        let fast = FastChain.orientation_error(&pose, &errors).to_array();
        for k in 0..3 {
            prop_assert!((plain[k] - fast[k]).abs() <= FAST_VS_PLAIN_ABS_RAD,
                "axis {k}: plain {} fast {}", plain[k], fast[k]);
        }
    }

    /// Large errors take the `f64::sin_cos` branch and still agree.
    #[test]
    fn fast_chain_equals_plain_exact_chain_for_large_errors(
        chi in proptest::array::uniform8(-0.5f64..=0.5),
        phi2 in -10.0f64..10.0,
    ) {
        let pose = Pose::new(0.3, phi2).unwrap();
        let errors = TurntableErrors::from_rad(chi, 0.0).unwrap();
        let plain = ExactChain::default().orientation_error(&pose, &errors).to_array();
        let fast = fast_delta_rad(phi2, &chi);
        for k in 0..3 {
            prop_assert!((plain[k] - fast[k]).abs() <= FAST_VS_PLAIN_LARGE_ABS_RAD,
                "axis {k}: plain {} fast {}", plain[k], fast[k]);
        }
    }

    /// The table-based sine and cosine of the pose grid agree with `f64::sin_cos`.
    #[test]
    fn sin_cos_turn_matches_std_sin_cos(w in any::<u32>()) {
        let phi = f64::from(w) * (std::f64::consts::TAU / 4_294_967_296.0);
        let (s, c) = sin_cos_turn(w);
        let (s_ref, c_ref) = phi.sin_cos();
        prop_assert!((s - s_ref).abs() <= SIN_COS_TURN_ABS, "w {w}: sin {s} vs {s_ref}");
        prop_assert!((c - c_ref).abs() <= SIN_COS_TURN_ABS, "w {w}: cos {c} vs {c_ref}");
    }
}

#[test]
fn sin_cos_turn_is_exact_at_quarter_turns_and_table_boundaries() {
    for (w, phi) in [
        (0u32, 0.0),
        (1 << 30, std::f64::consts::FRAC_PI_2),
        (1 << 31, std::f64::consts::PI),
        (3 << 30, 3.0 * std::f64::consts::FRAC_PI_2),
        (
            u32::MAX,
            std::f64::consts::TAU * (1.0 - 1.0 / 4_294_967_296.0),
        ),
        (
            (1 << 23) - 1,
            std::f64::consts::TAU * f64::from((1u32 << 23) - 1) / 4_294_967_296.0,
        ),
        (1 << 23, std::f64::consts::PI / 256.0),
    ] {
        let (s, c) = sin_cos_turn(w);
        assert_abs_diff_eq!(s, phi.sin(), epsilon = SIN_COS_TURN_ABS);
        assert_abs_diff_eq!(c, phi.cos(), epsilon = SIN_COS_TURN_ABS);
    }
}

/// The whole run: the fast path (one series tier per box) and the generic path with the plain
/// chain see the same samples and give the same extremes, worst samples and histograms.
fn fast_run_matches_plain_run(bounds: ErrorBox, samples: u64) {
    let mc = MonteCarlo::new(bounds, McConfig::new(samples, 11)).unwrap();
    let fast = mc.run();
    let plain = mc.run_model(&ExactChain::default()).unwrap();
    assert_eq!(fast.samples, plain.samples);
    for (f, p) in fast.axes.iter().zip(&plain.axes) {
        assert_abs_diff_eq!(
            f.max_abs_rad,
            p.max_abs_rad,
            epsilon = FAST_VS_PLAIN_ABS_RAD
        );
        assert_eq!(f.worst.index, p.worst.index, "{:?}", f.axis);
        assert_eq!(
            f.worst.chi_rad.map(f64::to_bits),
            p.worst.chi_rad.map(f64::to_bits)
        );
        assert_eq!(f.worst.pose, p.worst.pose);
        assert_abs_diff_eq!(f.mean_rad, p.mean_rad, epsilon = FAST_VS_PLAIN_ABS_RAD);
        assert_eq!(f.histogram.counts, p.histogram.counts);
        assert_eq!(f.within_requirement, p.within_requirement);
    }
}

#[test]
fn fast_run_matches_plain_chain_run_with_table4_box_short_series() {
    fast_run_matches_plain_run(table4(), 20_000);
}

#[test]
fn fast_run_matches_plain_chain_run_with_nonzero_lower_bounds_short_series() {
    let lb = [0.1, 0.2, 0.0, 0.3, 0.05, 0.1, 0.2, 0.1];
    let b = ErrorBox::from_arcmin(lb, common::TABLE4_ARCMIN).unwrap();
    fast_run_matches_plain_run(b, 20_000);
}

#[test]
fn fast_run_matches_plain_chain_run_with_10_arcmin_box_medium_series() {
    let b = ErrorBox::from_arcmin([2.0; 8], [10.0; 8]).unwrap();
    fast_run_matches_plain_run(b, 20_000);
}

#[test]
fn fast_run_matches_plain_chain_run_with_1_deg_box_libm_branch() {
    let ub = [deg_to_rad(1.0); 8];
    fast_run_matches_plain_run(ErrorBox::from_upper_rad(ub).unwrap(), 5_000);
}

/// The reported worst sample is a real sample: evaluating its chi and pose with the plain
/// chain gives back the reported value, which is the reported maximum.
#[test]
fn worst_sample_reproduces_its_maximum_through_the_plain_chain() {
    let r = MonteCarlo::new(table4(), McConfig::new(50_000, 5))
        .unwrap()
        .run();
    for a in &r.axes {
        let errors = TurntableErrors::from_rad(a.worst.chi_rad, 0.0).unwrap();
        let v = ExactChain::default()
            .orientation_error(&a.worst.pose, &errors)
            .get(a.axis);
        assert_abs_diff_eq!(v, a.worst.value_rad, epsilon = FAST_VS_PLAIN_ABS_RAD);
        assert_eq!(a.worst.value_rad.abs().to_bits(), a.max_abs_rad.to_bits());
        assert!(a.worst.index < 50_000);
    }
}
