//! The paper's claims about the turntable error model (§3-4, eq 17-28), one test each,
//! plus independent cross-checks of the exact chain built from the Table 3 description.

mod common;

use approx::assert_abs_diff_eq;
use common::*;
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;
use tt_kinematics::paper::{self, ClosedForm, chi_index};
use tt_kinematics::sensitivity::average_sensitivity_numerical;
use tt_kinematics::{
    ChainKind, ExactChain, LinearModel, OrientationAxis as A, OrientationErrorModel, Pose,
    TurntableErrors,
};

/// Golden values of the exact chain, computed with the independent NumPy implementation of
/// the project's Monte Carlo baseline (`shared/bench/numpy_mc_anchor.py`, its `rot` and
/// chain, the same Table 3 order) on 2026-11-22: (phi1 deg, phi2 deg, chi arcmin) ->
/// (dR13, dR21, dR32).
const GOLDEN: [(f64, f64, [f64; 8], [f64; 3]); 3] = [
    (
        30.0,
        45.0,
        [
            0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
        ],
        [
            8.224339099422905e-05,
            0.00045379901908840085,
            0.00043056922482702847,
        ],
    ),
    (
        200.0,
        310.0,
        [-7.0, 3.0, 9.5, -4.0, 6.0, -10.0, 2.5, -8.0],
        [
            -0.0030447458808896787,
            -0.0003063287062751878,
            0.007330374748149697,
        ],
    ),
    (
        -75.0,
        123.0,
        [10.0, -10.0, 10.0, 10.0, -10.0, 10.0, -10.0, 10.0],
        [
            -0.0002526250205762315,
            1.4947766769951883e-05,
            0.0019664023670860273,
        ],
    ),
];

/// Golden values are printed to 17 significant digits by NumPy; two IEEE implementations of
/// the same product may differ by a few ulps of the unit-size entries, rad.
const GOLDEN_TOL_RAD: f64 = 1e-15;

#[test]
fn exact_chain_matches_independent_numpy_golden_values() {
    let table = table3();
    for (p1, p2, chi_arcmin, expected) in GOLDEN {
        let e = ExactChain::new(&table)
            .orientation_error(
                &Pose::from_deg(&[p1, p2]).unwrap(),
                &TurntableErrors::from_arcmin(&chi_arcmin, &[0.0]).unwrap(),
            )
            .unwrap();
        for (got, want) in e.to_array().iter().zip(expected) {
            assert_abs_diff_eq!(*got, want, epsilon = GOLDEN_TOL_RAD);
        }
    }
}

/// Table 3's order built independently with nalgebra's axis-angle rotations.
fn table3_by_axis_angle(pose: &Pose, chi: &TurntableErrors) -> Matrix3<f64> {
    let r = |axis: Vector3<f64>, a: f64| {
        Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), a).into_inner()
    };
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let c = |n: &str| chi.chi_rad()[chi_index(n)];
    let [phi1, phi2] = pose.angles_rad() else {
        panic!("two joints")
    };
    let rt = r(y, *phi1)
        * r(y, c("dphi_y1"))
        * r(z, c("dalpha_z1"))
        * r(x, c("dalpha_x1"))
        * r(y, c("deps_y"))
        * r(x, c("deps_x"))
        * r(z, *phi2)
        * r(y, c("dalpha_y2"))
        * r(z, c("dphi_z2"))
        * r(x, c("dalpha_x2"));
    let rd = r(y, *phi1) * r(z, *phi2);
    rd.transpose() * rt
}

proptest! {
    /// The exact chain of the Table 3 description follows Table 3's rotation order: it equals
    /// an independent composition of nalgebra axis-angle rotations in that order (this
    /// catches any swapped pair of rotations or a wrong sign in an elementary rotation).
    #[test]
    fn exact_chain_follows_table3_rotation_order(pose in pose(), chi in errors_up_to(0.2)) {
        let ours = table3().delta_r(&pose, &chi, ChainKind::Exact).unwrap();
        let reference = table3_by_axis_angle(&pose, &chi);
        prop_assert!((ours - reference).amax() <= ROUNDING_RAD);
    }

    /// The flat evaluation plan (quaternions) equals the matrix chain to rounding.
    #[test]
    fn plan_evaluation_equals_matrix_chain(pose in pose(), chi in errors_up_to(0.2)) {
        let t = table3();
        let plan = t.plan_orientation_error(&pose, &chi).unwrap();
        let chain = ExactChain::new(&t).orientation_error(&pose, &chi).unwrap().to_array();
        for k in 0..3 {
            prop_assert!((plan[k] - chain[k]).abs() <= ROUNDING_RAD);
        }
    }

    /// Eq 17-19: the general small-angle chain of the description (each run of consecutive
    /// error rotations one matrix I + [delta]x) is exactly the product of the printed link
    /// matrices.
    #[test]
    fn small_angle_chain_is_the_printed_eq17_to_19(pose in pose(), chi in errors()) {
        let general = table3().delta_r(&pose, &chi, ChainKind::SmallAngle).unwrap();
        let [p1, p2] = pose.angles_rad() else { panic!() };
        let printed = paper::printed_delta_r(*p1, *p2, &chi8(&chi));
        prop_assert!((general - printed).amax() <= ROUNDING_RAD);
    }

    /// P1 (eq 25 vs eq 26): the exact chain and the closed form (26) agree within
    /// K * max|chi_i|^2 for errors up to 10 arcmin, K = 33 (derivation in `common::K_EXACT`).
    #[test]
    fn p1_exact_chain_and_closed_form_eq26_agree_to_second_order(pose in pose(), chi in errors()) {
        let exact = ExactChain::new(&table3()).orientation_error(&pose, &chi).unwrap().to_array();
        let closed = ClosedForm.orientation_error(&pose, &chi).unwrap().to_array();
        let m = chi.max_abs_rad();
        for (a, b) in exact.iter().zip(closed) {
            prop_assert!((a - b).abs() <= K_EXACT * m * m + ROUNDING_RAD);
        }
    }

    /// The second-order term of the exact chain is the one of an ordered product of
    /// rotations: exact = I + sum S_k + sum_{j<k} S_j S_k + 1/2 sum S_k^2 + O(m^3). This pins
    /// the rotation order at second order, which P1 cannot see.
    #[test]
    fn exact_chain_second_order_term_is_the_ordered_product(pose in pose(), chi in errors()) {
        use tt_kinematics::{rotation::{rot, skew}, Axis};
        let rz = rot(Axis::Z, pose.angles_rad()[1]);
        let g = |v: Vector3<f64>, conj: bool| if conj { rz.transpose() * skew(&v) * rz } else { skew(&v) };
        let e = |n: &str| chi.chi_rad()[chi_index(n)];
        let s = [
            g(Vector3::new(0.0, e("dphi_y1"), 0.0), true),
            g(Vector3::new(0.0, 0.0, e("dalpha_z1")), true),
            g(Vector3::new(e("dalpha_x1"), 0.0, 0.0), true),
            g(Vector3::new(0.0, e("deps_y"), 0.0), true),
            g(Vector3::new(e("deps_x"), 0.0, 0.0), true),
            g(Vector3::new(0.0, e("dalpha_y2"), 0.0), false),
            g(Vector3::new(0.0, 0.0, e("dphi_z2")), false),
            g(Vector3::new(e("dalpha_x2"), 0.0, 0.0), false),
        ];
        let mut second = Matrix3::identity();
        for j in 0..s.len() {
            second += s[j] + 0.5 * s[j] * s[j];
            for k in (j + 1)..s.len() {
                second += s[j] * s[k];
            }
        }
        let exact = table3().delta_r(&pose, &chi, ChainKind::Exact).unwrap();
        let m = chi.max_abs_rad();
        // Third-order remainder: e^s - 1 - s - s^2/2 <= s^3/6 e^s with s <= 8m, so K3 = 88.
        const K3: f64 = 88.0;
        prop_assert!((exact - second).amax() <= K3 * m * m * m + ROUNDING_RAD);
    }

    /// P2 (eq 23): the orientation error does not depend on phi1: R_y(phi1) is the leftmost
    /// factor of R_d and R_t and cancels (the description's phi1 is not a free joint).
    #[test]
    fn orientation_error_does_not_depend_on_phi1(pose in pose(), other in 0.0..std::f64::consts::TAU, chi in errors()) {
        let t = table3();
        prop_assert_eq!(t.free_joints(), &[1usize][..]);
        let moved = Pose::new(vec![other, pose.angles_rad()[1]]).unwrap();
        let a = t.delta_r(&pose, &chi, ChainKind::Exact).unwrap();
        let b = t.delta_r(&moved, &chi, ChainKind::Exact).unwrap();
        prop_assert!((a - b).amax() <= ROUNDING_RAD);
    }

    /// P3 (claim under eq 25): the intersection error has no effect on the orientation,
    /// bit for bit.
    #[test]
    fn intersection_error_has_no_effect_on_orientation_eq25(pose in pose(), chi in errors(), deta in -1e-2..1e-2_f64) {
        let t = table3();
        let moved = chi.clone().with_translations_m(vec![deta]).unwrap();
        for kind in [ChainKind::Exact, ChainKind::SmallAngle] {
            prop_assert_eq!(t.delta_r(&pose, &chi, kind).unwrap(), t.delta_r(&pose, &moved, kind).unwrap());
        }
        // while the position of the platform does move
        let a = t.actual_transform(&pose, &chi).unwrap();
        let b = t.actual_transform(&pose, &moved).unwrap();
        prop_assert!(((a - b).fixed_view::<3, 1>(0, 3).norm() - (deta - chi.translations_m()[0]).abs()).abs() <= 1e-15);
    }

    /// P4 (eq 23): the exact Delta-R is a rotation: orthonormal and det +1 to 1e-12.
    #[test]
    fn p4_exact_delta_r_is_a_rotation(pose in pose(), chi in errors_up_to(0.5)) {
        let dr = table3().delta_r(&pose, &chi, ChainKind::Exact).unwrap();
        prop_assert!((dr.transpose() * dr - Matrix3::identity()).amax() <= ORTHONORMAL_TOL);
        prop_assert!((dr.determinant() - 1.0).abs() <= ORTHONORMAL_TOL);
    }

    /// P5 (eq 28): the analytic Jacobian of the exact chain matches central finite
    /// differences of the exact chain, at any pose and errors up to 10 arcmin.
    #[test]
    fn p5_analytic_jacobian_matches_central_differences(pose in pose(), chi in errors()) {
        let t = table3();
        let jac = t.jacobian(&pose, &chi).unwrap();
        let model = ExactChain::new(&t);
        for i in 0..8 {
            let x = chi.chi_rad()[i];
            let plus = model.orientation_error(&pose, &chi.clone().with_chi(i, x + FD_STEP_RAD).unwrap()).unwrap().to_array();
            let minus = model.orientation_error(&pose, &chi.clone().with_chi(i, x - FD_STEP_RAD).unwrap()).unwrap().to_array();
            for row in 0..3 {
                let fd = (plus[row] - minus[row]) / (2.0 * FD_STEP_RAD);
                prop_assert!((jac[(row, i)] - fd).abs() <= FD_TOL,
                    "d{}/d{}: analytic {} vs fd {}", A::ALL[row].name(), paper::CHI[i].0, jac[(row, i)], fd);
            }
        }
    }

    /// Eq 26 recovered from the description: at chi = 0 the exact chain's Jacobian and the
    /// description's first-order model both equal the coefficient matrix of the printed eq 26
    /// to 1e-12.
    #[test]
    fn eq26_is_recovered_from_the_table3_description(pose in pose()) {
        let t = table3();
        let jac = t.jacobian(&pose, &t.zero_errors()).unwrap();
        let lin = LinearModel::new(&t).coefficients(&pose).unwrap();
        for i in 0..8 {
            let mut chi = [0.0; 8];
            chi[i] = 1.0;
            let col = ClosedForm::eq26(pose.angles_rad()[1], &chi);
            for k in 0..3 {
                prop_assert!((jac[(k, i)] - col[k]).abs() <= RECOVER_TOL);
                prop_assert!((lin[(k, i)] - col[k]).abs() <= RECOVER_TOL);
            }
        }
    }

    /// P6 (§4.3, eq 26-27): to first order Delta-theta depends only on dphi_z2 and
    /// dalpha_z1, and Delta-psi and Delta-gamma do not depend on them, at every pose.
    #[test]
    fn p6_delta_theta_depends_only_on_dphi_z2_and_dalpha_z1(pose in pose()) {
        let t = table3();
        let jac = t.jacobian(&pose, &t.zero_errors()).unwrap();
        for (i, (name, _)) in paper::CHI.iter().enumerate() {
            let theta_row = jac[(A::Theta.index(), i)];
            if matches!(*name, "dphi_z2" | "dalpha_z1") {
                prop_assert!((theta_row - 1.0).abs() <= ROUNDING_RAD);
                prop_assert!(jac[(A::Psi.index(), i)].abs() <= ROUNDING_RAD);
                prop_assert!(jac[(A::Gamma.index(), i)].abs() <= ROUNDING_RAD);
            } else {
                prop_assert!(theta_row.abs() <= ROUNDING_RAD, "dtheta/d{name} = {theta_row}");
            }
        }
    }
}

/// Midpoint-rule error of the numerical Figure 8 average with 720 steps in phi2: the kink of
/// |cos| costs O(h^2) = O((2 pi / 720)^2) ~ 1e-4 at most; the observed error is ~1e-6.
const FIGURE8_QUADRATURE_TOL: f64 = 1e-4;

/// Figure 8 (eq 28): the average sensitivities of the description's first-order model are
/// 2/pi for every sin/cos term of eq 26, 1 for every constant term, 0 elsewhere (to 1e-12),
/// and equal the numerical average of the exact chain's Jacobian over the rotation angles.
#[test]
fn figure8_average_sensitivities_closed_form_matches_numerical_average() {
    let t = table3();
    let closed = LinearModel::new(&t).average_abs_coefficients();
    let numerical = average_sensitivity_numerical(&t, 720);
    for (r, row) in paper::figure8_expected().iter().enumerate() {
        for (c, want) in row.iter().enumerate() {
            assert_abs_diff_eq!(closed[(r, c)], *want, epsilon = RECOVER_TOL);
            assert_abs_diff_eq!(numerical[(r, c)], *want, epsilon = FIGURE8_QUADRATURE_TOL);
        }
    }
}

/// P7 (§4.3 and conclusion 1): the inner-axis wobble terms have the largest average
/// sensitivity: dalpha_y2 strictly dominates every other component of Delta-psi and
/// dalpha_x2 every other component of Delta-gamma (Figure 8). In the Delta-theta row
/// dphi_z2 and dalpha_z1 tie at 1, but they are the only terms of that row.
#[test]
fn p7_inner_axis_wobble_has_largest_average_sensitivity() {
    let s = LinearModel::new(&table3()).average_abs_coefficients();
    for (axis, wobble) in [(A::Psi, "dalpha_y2"), (A::Gamma, "dalpha_x2")] {
        let w = chi_index(wobble);
        let top = s[(axis.index(), w)];
        for i in (0..8).filter(|&i| i != w) {
            assert!(
                top > s[(axis.index(), i)] + 0.3,
                "{}: {wobble} ({top}) not above {} ({})",
                axis.name(),
                paper::CHI[i].0,
                s[(axis.index(), i)]
            );
        }
    }
}

/// eq 27: the components each angle depends on, found from the description.
#[test]
fn eq27_component_sets_of_each_angle() {
    let m = LinearModel::new(&table3());
    let names = |v: Vec<usize>| v.into_iter().map(|i| paper::CHI[i].0).collect::<Vec<_>>();
    assert_eq!(
        names(m.involved(A::Gamma)),
        ["dphi_y1", "dalpha_x1", "dalpha_x2", "deps_x", "deps_y"]
    );
    assert_eq!(names(m.involved(A::Theta)), ["dphi_z2", "dalpha_z1"]);
    assert_eq!(
        names(m.involved(A::Psi)),
        ["dphi_y1", "dalpha_x1", "dalpha_y2", "deps_x", "deps_y"]
    );
}

/// The Table 3 description's first-order harmonics in phi2 are eq 26's exactly (0, +-1).
#[test]
#[allow(clippy::float_cmp)] // the claim is exact equality: structural zeros and unit coefficients
fn table3_harmonics_in_phi2_are_eq26_exactly() {
    let m = LinearModel::new(&table3());
    for axis in A::ALL {
        let h = m.single_joint_harmonics(axis).unwrap();
        for (i, [a, b, c]) in h.iter().enumerate() {
            let mut chi = [0.0; 8];
            chi[i] = 1.0;
            let at0 = ClosedForm::eq26(0.0, &chi)[axis.index()];
            let at90 = ClosedForm::eq26(std::f64::consts::FRAC_PI_2, &chi)[axis.index()];
            let at180 = ClosedForm::eq26(std::f64::consts::PI, &chi)[axis.index()];
            // exact structural values: every harmonic part is 0 or +-1
            for v in [a, b, c] {
                assert!(*v == 0.0 || v.abs() == 1.0, "{v}");
            }
            assert_abs_diff_eq!(a + c, at0, epsilon = 1e-15);
            assert_abs_diff_eq!(b + c, at90, epsilon = 1e-15);
            assert_abs_diff_eq!(c - a, at180, epsilon = 1e-15);
        }
    }
}
