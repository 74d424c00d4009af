//! One conformance suite for every `OrientationErrorModel` implementation (issue 2, §2):
//! the exact chain (eq 17-24, finite rotations), the printed small-angle chain and the
//! closed form (eq 26). Each property is checked for each implementation.

mod common;

use approx::assert_abs_diff_eq;
use common::*;
use proptest::prelude::*;
use tt_kinematics::{
    ClosedForm, ExactChain, OrientationError, OrientationErrorModel, Pose, ReadOut,
    SmallAngleChain, TurntableErrors,
};

/// The implementations under test with their second-order constant against eq 26.
fn implementations() -> Vec<(&'static str, Box<dyn OrientationErrorModel>, f64)> {
    vec![
        ("exact chain", Box::new(ExactChain::default()), K_EXACT),
        (
            "exact chain, rotation-vector read-out",
            Box::new(ExactChain {
                readout: ReadOut::RotationVector,
            }),
            K_EXACT,
        ),
        (
            "small-angle chain",
            Box::new(SmallAngleChain),
            K_SMALL_ANGLE,
        ),
        ("closed form (26)", Box::new(ClosedForm), 0.0),
    ]
}

fn max_abs_diff(a: &OrientationError, b: &OrientationError) -> f64 {
    a.to_array()
        .iter()
        .zip(b.to_array())
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn conformance_suite_has_every_implementation() {
    // Guard against an empty suite passing vacuously.
    assert_eq!(implementations().len(), 4);
}

#[test]
fn no_turntable_error_gives_no_orientation_error_for_every_model() {
    for (name, model, _) in implementations() {
        for (p1, p2) in [(0.0, 0.0), (33.0, 71.0), (180.0, 270.0), (-45.0, 390.0)] {
            let e =
                model.orientation_error(&Pose::from_deg(p1, p2).unwrap(), &TurntableErrors::ZERO);
            for v in e.to_array() {
                assert_abs_diff_eq!(v, 0.0, epsilon = ROUNDING_RAD);
            }
            let _ = name;
        }
    }
}

proptest! {
    /// P1 (eq 25 vs eq 26): every model agrees with the closed form (26) within
    /// K * max|chi_i|^2 for errors up to 10 arcmin (K of each model in `common`).
    #[test]
    fn every_model_agrees_with_closed_form_eq26_to_second_order(pose in pose(), chi in errors()) {
        let linear = ClosedForm.orientation_error(&pose, &chi);
        let m = chi.max_abs_rad();
        for (name, model, k) in implementations() {
            let d = max_abs_diff(&model.orientation_error(&pose, &chi), &linear);
            prop_assert!(d <= k * m * m + ROUNDING_RAD,
                "{name}: |model - eq26| = {d:e} > K m^2 = {:e}", k * m * m);
        }
    }

    /// P2 (§3.2): the orientation error does not depend on phi1, for every model. Why: the
    /// outer-axis rotation R_y(phi1) is the leftmost factor of both R_d (21) and R_t (22),
    /// so it cancels in R_d^T R_t (23).
    #[test]
    fn orientation_error_does_not_depend_on_phi1(
        pose in pose(), other_phi1 in angle(), chi in errors()
    ) {
        let moved = Pose { phi1_rad: other_phi1, ..pose };
        for (name, model, _) in implementations() {
            let d = max_abs_diff(&model.orientation_error(&pose, &chi), &model.orientation_error(&moved, &chi));
            prop_assert!(d <= ROUNDING_RAD, "{name}: phi1 changed the error by {d:e}");
        }
    }

    /// P3 (claim under eq 25): the intersection error deta has no effect on the orientation
    /// error, for every model: bit for bit, since a translation never enters the rotation
    /// block of a product of homogeneous transforms.
    #[test]
    fn intersection_error_has_no_effect_on_orientation_eq25(
        pose in pose(), chi in errors(), deta_m in -0.01..0.01_f64
    ) {
        let shifted = chi.with_deta_m(deta_m).unwrap();
        for (name, model, _) in implementations() {
            let a = model.orientation_error(&pose, &chi).to_array().map(f64::to_bits);
            let b = model.orientation_error(&pose, &shifted).to_array().map(f64::to_bits);
            prop_assert_eq!(a, b, "{}: deta changed the orientation error", name);
        }
    }

    /// Every model is odd in chi to first order: f(-chi) = -f(chi) up to the second-order
    /// term (for the linear model exactly).
    #[test]
    fn every_model_is_odd_in_chi_to_first_order(pose in pose(), chi in errors()) {
        let neg = TurntableErrors::from_rad(chi.chi_rad().map(|x| -x), chi.deta_m()).unwrap();
        let m = chi.max_abs_rad();
        for (name, model, k) in implementations() {
            let a = model.orientation_error(&pose, &chi).to_array();
            let b = model.orientation_error(&pose, &neg).to_array();
            for (x, y) in a.iter().zip(b) {
                prop_assert!((x + y).abs() <= 2.0 * k * m * m + ROUNDING_RAD, "{name}");
            }
        }
    }
}
