//! The paper's claims about the turntable error model (§3-4, eq 17-28), one test each,
//! plus independent cross-checks of the exact chain.

mod common;

use approx::{assert_abs_diff_eq, assert_relative_eq};
use common::*;
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_2_PI, TAU};
use tt_kinematics::sensitivity::{
    average_sensitivity_closed_form, average_sensitivity_numerical, exact_jacobian,
};
use tt_kinematics::{
    ChainKind, ClosedForm, ErrorComponent as C, ExactChain, LinearModel, OrientationAxis as A,
    OrientationErrorModel, Pose, TurntableErrors, delta_r,
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
    for (p1, p2, chi_arcmin, expected) in GOLDEN {
        let e = ExactChain::default().orientation_error(
            &Pose::from_deg(p1, p2).unwrap(),
            &TurntableErrors::from_arcmin(chi_arcmin, 0.0).unwrap(),
        );
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
    let rt = r(y, pose.phi1_rad)
        * r(y, chi.get(C::DphiY1))
        * r(z, chi.get(C::DalphaZ1))
        * r(x, chi.get(C::DalphaX1))
        * r(y, chi.get(C::DepsY))
        * r(x, chi.get(C::DepsX))
        * r(z, pose.phi2_rad)
        * r(y, chi.get(C::DalphaY2))
        * r(z, chi.get(C::DphiZ2))
        * r(x, chi.get(C::DalphaX2));
    let rd = r(y, pose.phi1_rad) * r(z, pose.phi2_rad);
    rd.transpose() * rt
}

proptest! {
    /// The exact chain follows Table 3's rotation order: it equals an independent
    /// composition of nalgebra axis-angle rotations in that order (this catches any swapped
    /// pair of rotations or a wrong sign in an elementary rotation).
    #[test]
    fn exact_chain_follows_table3_rotation_order(pose in pose(), chi in errors_up_to(0.2)) {
        let ours = delta_r(&pose, &chi, ChainKind::Exact);
        let reference = table3_by_axis_angle(&pose, &chi);
        prop_assert!((ours - reference).amax() <= ROUNDING_RAD);
    }

    /// P1 (eq 25 vs eq 26): the exact chain and the closed form (26) agree within
    /// K * max|chi_i|^2 for errors up to 10 arcmin, K = 33 (derivation in `common::K_EXACT`).
    #[test]
    fn p1_exact_chain_and_closed_form_eq26_agree_to_second_order(pose in pose(), chi in errors()) {
        let exact = ExactChain::default().orientation_error(&pose, &chi).to_array();
        let closed = ClosedForm.orientation_error(&pose, &chi).to_array();
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
        use tt_kinematics::rotation::skew;
        // Error generators S_k in the frame of Delta-R: R_z(-phi2) [u]x R_z(phi2) for the outer
        // and orthogonality errors, [u]x for the inner ones, in Table 3's order.
        let rz = tt_kinematics::rotation::rot(tt_kinematics::rotation::Axis::Z, pose.phi2_rad);
        let g = |v: Vector3<f64>, conj: bool| if conj { rz.transpose() * skew(&v) * rz } else { skew(&v) };
        let e = |c| chi.get(c);
        let s = [
            g(Vector3::new(0.0, e(C::DphiY1), 0.0), true),
            g(Vector3::new(0.0, 0.0, e(C::DalphaZ1)), true),
            g(Vector3::new(e(C::DalphaX1), 0.0, 0.0), true),
            g(Vector3::new(0.0, e(C::DepsY), 0.0), true),
            g(Vector3::new(e(C::DepsX), 0.0, 0.0), true),
            g(Vector3::new(0.0, e(C::DalphaY2), 0.0), false),
            g(Vector3::new(0.0, 0.0, e(C::DphiZ2)), false),
            g(Vector3::new(e(C::DalphaX2), 0.0, 0.0), false),
        ];
        let mut second = Matrix3::identity();
        for j in 0..s.len() {
            second += s[j] + 0.5 * s[j] * s[j];
            for k in (j + 1)..s.len() {
                second += s[j] * s[k];
            }
        }
        let exact = delta_r(&pose, &chi, ChainKind::Exact);
        let m = chi.max_abs_rad();
        // Third-order remainder: e^s - 1 - s - s^2/2 <= s^3/6 e^s with s <= 8m, so K3 = 88.
        const K3: f64 = 88.0;
        prop_assert!((exact - second).amax() <= K3 * m * m * m + ROUNDING_RAD);
    }

    /// P4 (eq 23): the exact Delta-R is a rotation: orthonormal and det +1 to 1e-12.
    #[test]
    fn p4_exact_delta_r_is_a_rotation(pose in pose(), chi in errors_up_to(0.5)) {
        let dr = delta_r(&pose, &chi, ChainKind::Exact);
        prop_assert!((dr.transpose() * dr - Matrix3::identity()).amax() <= ORTHONORMAL_TOL);
        prop_assert!((dr.determinant() - 1.0).abs() <= ORTHONORMAL_TOL);
    }

    /// P5 (eq 28): the analytic Jacobian of the exact chain matches central finite
    /// differences of the exact chain, at any pose and errors up to 10 arcmin.
    #[test]
    fn p5_analytic_jacobian_matches_central_differences(pose in pose(), chi in errors()) {
        let jac = exact_jacobian(&pose, &chi);
        let model = ExactChain::default();
        for c in C::ALL {
            let x = chi.get(c);
            let plus = model.orientation_error(&pose, &chi.with(c, x + FD_STEP_RAD).unwrap()).to_array();
            let minus = model.orientation_error(&pose, &chi.with(c, x - FD_STEP_RAD).unwrap()).to_array();
            for row in 0..3 {
                let fd = (plus[row] - minus[row]) / (2.0 * FD_STEP_RAD);
                prop_assert!((jac[(row, c.index())] - fd).abs() <= FD_TOL,
                    "d{}/d{}: analytic {} vs fd {}", A::ALL[row].name(), c.name(), jac[(row, c.index())], fd);
            }
        }
    }

    /// At chi = 0 the exact chain's Jacobian is the coefficient matrix of eq 26: the closed
    /// form is the first-order expansion of eq 23-24.
    #[test]
    fn jacobian_at_zero_error_is_eq26(pose in pose()) {
        let jac = exact_jacobian(&pose, &TurntableErrors::ZERO);
        let eq26 = LinearModel::paper_eq26().coefficients(pose.phi2_rad);
        prop_assert!((jac - eq26).amax() <= ROUNDING_RAD);
    }

    /// P6 (§4.3, eq 26-27): to first order Delta-theta depends only on dphi_z2 and
    /// dalpha_z1, and Delta-psi and Delta-gamma do not depend on them, at every pose.
    #[test]
    fn p6_delta_theta_depends_only_on_dphi_z2_and_dalpha_z1(pose in pose()) {
        let jac = exact_jacobian(&pose, &TurntableErrors::ZERO);
        for c in C::ALL {
            let theta_row = jac[(A::Theta.index(), c.index())];
            if matches!(c, C::DphiZ2 | C::DalphaZ1) {
                prop_assert!((theta_row - 1.0).abs() <= ROUNDING_RAD);
                prop_assert!(jac[(A::Psi.index(), c.index())].abs() <= ROUNDING_RAD);
                prop_assert!(jac[(A::Gamma.index(), c.index())].abs() <= ROUNDING_RAD);
            } else {
                prop_assert!(theta_row.abs() <= ROUNDING_RAD, "dtheta/d{} = {theta_row}", c.name());
            }
        }
    }
}

/// Midpoint-rule error of the numerical Figure 8 average with 720 steps in phi2: the kink of
/// |cos| costs O(h^2) = O((2 pi / 720)^2) ~ 1e-4 at most; the observed error is ~1e-6.
const FIGURE8_QUADRATURE_TOL: f64 = 1e-4;

/// Figure 8 (eq 28): the average sensitivities in closed form are 2/pi for every
/// sin/cos term of eq 26, 1 for every constant term, 0 elsewhere, and equal the numerical
/// average of the exact chain's Jacobian over the rotation angles.
#[test]
fn figure8_average_sensitivities_closed_form_matches_numerical_average() {
    let closed = average_sensitivity_closed_form(&LinearModel::paper_eq26());
    let numerical = average_sensitivity_numerical(8, 720);
    let expected: [[f64; 8]; 3] = [
        // dphi_y1, dphi_z2, dalpha_x1, dalpha_z1, dalpha_x2, dalpha_y2, deps_x, deps_y
        [
            FRAC_2_PI, 0.0, FRAC_2_PI, 0.0, 0.0, 1.0, FRAC_2_PI, FRAC_2_PI,
        ], // psi
        [0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0], // theta
        [
            FRAC_2_PI, 0.0, FRAC_2_PI, 0.0, 1.0, 0.0, FRAC_2_PI, FRAC_2_PI,
        ], // gamma
    ];
    for (r, row) in expected.iter().enumerate() {
        for (c, want) in row.iter().enumerate() {
            assert_relative_eq!(closed[(r, c)], *want, epsilon = 1e-15);
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
    let s = average_sensitivity_closed_form(&LinearModel::paper_eq26());
    for (axis, wobble) in [(A::Psi, C::DalphaY2), (A::Gamma, C::DalphaX2)] {
        let top = s[(axis.index(), wobble.index())];
        for c in C::ALL.into_iter().filter(|&c| c != wobble) {
            assert!(
                top > s[(axis.index(), c.index())] + 0.3,
                "{}: {} ({top}) not above {} ({})",
                axis.name(),
                wobble.name(),
                c.name(),
                s[(axis.index(), c.index())]
            );
        }
    }
}

/// eq 27: the components each angle depends on.
#[test]
fn eq27_component_sets_of_each_angle() {
    let m = LinearModel::paper_eq26();
    assert_eq!(
        m.involved(A::Gamma),
        vec![C::DphiY1, C::DalphaX1, C::DalphaX2, C::DepsX, C::DepsY]
    );
    assert_eq!(m.involved(A::Theta), vec![C::DphiZ2, C::DalphaZ1]);
    assert_eq!(
        m.involved(A::Psi),
        vec![C::DphiY1, C::DalphaX1, C::DalphaY2, C::DepsX, C::DepsY]
    );
}

fn harmonic_model() -> impl Strategy<Value = LinearModel> {
    let m = || prop::array::uniform24(-2.0..2.0_f64);
    (m(), m(), m()).prop_map(|(a, b, c)| {
        let to = |v: [f64; 24]| nalgebra::SMatrix::<f64, 3, 8>::from_row_slice(&v);
        LinearModel::new(to(a), to(b), to(c)).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The exact worst pose of a weighted coefficient sum is never below a dense grid's
    /// maximum, and exceeds it by no more than the grid can miss (Lipschitz bound).
    #[test]
    fn worst_pose_is_exact_against_a_dense_grid(
        model in harmonic_model(),
        w in prop::array::uniform8(0.0..1.0_f64),
        lo in 0.0..TAU, width in 0.0..TAU, abs in any::<bool>(),
    ) {
        let hi = lo + width;
        for axis in A::ALL {
            let best = if abs { model.max_abs_weighted(axis, &w, lo, hi) } else { model.max_signed_weighted(axis, &w, lo, hi) };
            let value = |phi: f64| -> f64 {
                C::ALL.iter().map(|&c| { let v = model.coefficient(axis, c, phi); w[c.index()] * if abs { v.abs() } else { v } }).sum()
            };
            prop_assert!(best.phi2_rad >= lo - 1e-12 && best.phi2_rad <= hi + 1e-12);
            prop_assert!((value(best.phi2_rad) - best.value).abs() <= 1e-12);
            let n = 20_000;
            let mut grid_max = f64::NEG_INFINITY;
            for i in 0..=n {
                grid_max = grid_max.max(value(lo + width * i as f64 / n as f64));
            }
            // Each |a cos + b sin + c| is Lipschitz with constant <= hypot(a, b) <= 2 sqrt 2.
            let lipschitz: f64 = w.iter().sum::<f64>() * 2.0 * 2.0_f64.sqrt();
            prop_assert!(best.value >= grid_max - 1e-12, "exact {} < grid {}", best.value, grid_max);
            prop_assert!(best.value <= grid_max + lipschitz * width / n as f64 + 1e-12);
        }
    }

    /// The closed-form average of |a cos + b sin + c| equals a fine numerical average.
    #[test]
    fn average_abs_coefficient_formula_matches_quadrature(model in harmonic_model()) {
        let closed = model.average_abs_coefficients();
        let n = 20_000;
        let mut sum = nalgebra::SMatrix::<f64, 3, 8>::zeros();
        for i in 0..n {
            sum += model.coefficients(TAU * (i as f64 + 0.5) / n as f64).abs();
        }
        prop_assert!((closed - sum / n as f64).amax() <= 1e-6);
    }
}
