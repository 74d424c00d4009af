//! The claims of issue 3, each test named after what it proves (paper §2.2-2.3, eq 6-16).

use approx::{assert_abs_diff_eq, assert_relative_eq};
use calib_lsq::{
    CalibError, ErrorForm, Estimate, OrientationErrorAnalysis, OutputsAt, PAPER_OMEGA_M_DEG_PER_H,
    Reading, RequirementProblem, Schedule, calibrate, calibrate_simulated, rate_vector,
    regression_matrix, simulate_outputs,
};
use gw_model::units::{deg_per_h_to_rad_per_s, rad_per_s_to_deg_per_h};
use gw_model::{
    DeltaRKind, DriftCoefficients, OrientationAngles, SensingAxis, Site, TABLE_1_X_DEG_PER_H,
    TABLE_1_Y_DEG_PER_H,
};
use nalgebra::{DMatrix, DVector, Matrix3};
use proptest::prelude::*;
use std::sync::OnceLock;

/// Rate errors are of order 1e-7 rad/s; values that must be equal are computed from the same
/// floating-point operations up to reordering and rounding of the fit: 1e-17 rad/s is ~1e-10
/// relative.
const RATE_EQ_TOL_RAD_PER_S: f64 = 1e-17;
/// Relative equality of rate errors computed along mirrored paths: a few hundred ulps.
const RATE_EQ_REL: f64 = 1e-12;
/// Table 1 recovered by SVD least squares from exact simulated outputs (values <= 105 deg/h,
/// condition number ~5): 1e-9 deg/h is far below the printed rounding (0.001 deg/h).
const TABLE1_RECOVERY_TOL_DEG_PER_H: f64 = 1e-9;
/// The paper's rounding of eq 16: 0.027 deg means [0.0265, 0.0275) deg.
const EQ16_HALF_ROUNDING_DEG: f64 = 0.0005;
/// Requirement accuracy asked by the issue, deg.
const REQUIREMENT_ACCURACY_DEG: f64 = 1e-6;
/// Relative step outside the rectangle at which the requirement must be violated.
const OUTSIDE_STEP_REL: f64 = 1e-6;
/// Decompositions that are exact given e and g (only A and P enter): rounding, relative to the
/// error's infinity norm.
const EXACT_DECOMPOSITION_REL: f64 = 1e-6;
/// Decompositions through beta-hat-2 with outputs at the intended orientation replace
/// A A'^+ by P, an error of relative order |A' - A| ~ angle = 3.5e-4 rad at 0.02 deg.
const FIRST_ORDER_REL: f64 = 1e-3;

fn paper_requirement() -> &'static calib_lsq::OrientationRequirement {
    static R: OnceLock<calib_lsq::OrientationRequirement> = OnceLock::new();
    R.get_or_init(|| {
        RequirementProblem::paper()
            .requirement()
            .expect("paper inputs are valid")
    })
}

fn analysis(axis: SensingAxis, reading: Reading) -> OrientationErrorAnalysis {
    OrientationErrorAnalysis::new(
        DriftCoefficients::table_1().axis(axis),
        &Schedule::paper_default(),
        &Site::paper_default(),
        reading,
    )
    .unwrap()
}

/// Orientation errors up to 0.1 deg, the scale of Figure 4.
fn small_angle() -> impl Strategy<Value = f64> {
    (-0.1..0.1f64).prop_map(f64::to_radians)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Claim (1), §2.2: $\Delta\omega_x$ is not affected by $\Delta\gamma$ and $\Delta\omega_y$
    /// not by $\Delta\psi$ (default reading, eq 7).
    #[test]
    fn claim1_x_error_ignores_delta_gamma_and_y_error_ignores_delta_psi(
        psi in small_angle(), theta in small_angle(), gamma in small_angle(), other in small_angle(),
    ) {
        let k = DeltaRKind::SmallAngle;
        let x = analysis(SensingAxis::X, Reading::PAPER);
        let y = analysis(SensingAxis::Y, Reading::PAPER);
        let a = OrientationAngles::new(psi, theta, gamma).unwrap();
        let x_other = OrientationAngles::new(psi, theta, other).unwrap();
        let y_other = OrientationAngles::new(other, theta, gamma).unwrap();
        assert_abs_diff_eq!(
            x.delta_omega_for_angles(&a, k).unwrap(),
            x.delta_omega_for_angles(&x_other, k).unwrap(),
            epsilon = RATE_EQ_TOL_RAD_PER_S
        );
        assert_abs_diff_eq!(
            y.delta_omega_for_angles(&a, k).unwrap(),
            y.delta_omega_for_angles(&y_other, k).unwrap(),
            epsilon = RATE_EQ_TOL_RAD_PER_S
        );
    }

    /// Claim (2), §2.2: $\Gamma_1$ is symmetric about $\Delta\psi = 0$ and $\Delta\theta = 0$,
    /// $\Gamma_2$ about $\Delta\theta = 0$ and $\Delta\gamma = 0$ (even functions).
    #[test]
    fn claim2_rate_errors_are_even_in_each_plane_angle(u in small_angle(), v in small_angle()) {
        let p = RequirementProblem::paper();
        for axis in SensingAxis::ALL {
            let plane = p.plane(axis).unwrap();
            let f = plane.rate_error(u, v).unwrap();
            assert_relative_eq!(f, plane.rate_error(-u, v).unwrap(), max_relative = RATE_EQ_REL);
            assert_relative_eq!(f, plane.rate_error(u, -v).unwrap(), max_relative = RATE_EQ_REL);
        }
    }

    /// Claim (3), §2.2: $\Delta\omega$ rises with the magnitude of each plane angle (the other
    /// held fixed) and along every ray from the origin.
    #[test]
    fn claim3_rate_errors_rise_with_angle_magnitude(
        u in small_angle(), v in small_angle(), grow in 1.01..3.0f64,
    ) {
        let p = RequirementProblem::paper();
        for axis in SensingAxis::ALL {
            let plane = p.plane(axis).unwrap();
            let f = plane.rate_error(u, v).unwrap();
            prop_assert!(plane.rate_error(grow * u, grow * v).unwrap() > f);
            prop_assert!(plane.rate_error(grow * u, v).unwrap() >= f);
            prop_assert!(plane.rate_error(u, grow * v).unwrap() >= f);
        }
    }

    /// The estimate of eq 6 does not depend on the order of the positions.
    #[test]
    fn estimate_is_invariant_under_position_permutation(seed in any::<u64>()) {
        let schedule = Schedule::paper_default();
        let site = Site::paper_default();
        let truth = DriftCoefficients::table_1();
        // Fisher-Yates with a SplitMix64 stream from the proptest seed.
        let mut state = seed;
        let mut next = || { state = state.wrapping_add(0x9E37_79B9_7F4A_7C15); let mut z = state; z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9); z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB); z ^ (z >> 31) };
        let mut order: Vec<usize> = (0..schedule.len()).collect();
        for i in (1..order.len()).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            order.swap(i, j);
        }
        let permuted = schedule.permuted(&order).unwrap();
        // A fixed, non-trivial orientation error so the fit has residuals.
        let dr = vec![OrientationAngles::from_deg(0.02, -0.03, 0.01).unwrap().delta_r(DeltaRKind::Exact); schedule.len()];
        for axis in SensingAxis::ALL {
            let b1 = simulate_outputs(truth.axis(axis), &schedule, &site, &dr).unwrap();
            let b1_perm: Vec<f64> = order.iter().map(|&k| b1[k]).collect();
            let c = calibrate(axis, &schedule, &site, b1.as_slice()).unwrap();
            let cp = calibrate(axis, &permuted, &site, &b1_perm).unwrap();
            for (a, b) in c.coefficients.deg_per_h().iter().zip(cp.coefficients.deg_per_h()) {
                assert_abs_diff_eq!(*a, b, epsilon = TABLE1_RECOVERY_TOL_DEG_PER_H);
            }
        }
    }
}

/// Claim (4), eq 16: with Table 1 and $\omega_m = 0.01$ deg/h the requirement is 0.027 deg for
/// all three angles (unrounded 0.026938 deg with the default schedule at Harbin).
#[test]
fn claim4_requirement_is_0_027_deg_for_all_three_angles_eq16() {
    let r = paper_requirement();
    for i in r.deg() {
        assert!((i - 0.027).abs() < EQ16_HALF_ROUNDING_DEG, "{i}");
        assert_abs_diff_eq!(i, 0.026_938, epsilon = 1e-6);
    }
}

/// The lead behind claim (4): in the default reading $\Delta\omega_x = \max_i|\omega_{y,i}
/// \Delta\theta - \omega_{z,i}\Delta\psi|$ (earth-rate perturbation only), so with
/// earth-rate directions covering the circle the region is the disc of radius
/// $\omega_m/\omega_e$ and the best square has half-side $\omega_m/(\sqrt2\,\omega_e)$ =
/// 0.0269357 deg. A discrete schedule's polygon circumscribes the disc, so its requirement is
/// no smaller; the default schedule's is within 0.01 % of the disc value.
#[test]
fn requirement_is_close_to_disc_bound_omega_m_over_sqrt2_omega_e() {
    let disc = (deg_per_h_to_rad_per_s(PAPER_OMEGA_M_DEG_PER_H)
        / (std::f64::consts::SQRT_2 * Site::paper_default().earth_rate_rad_per_s()))
    .to_degrees();
    assert_abs_diff_eq!(disc, 0.026_935_7, epsilon = 1e-7);
    for i in paper_requirement().deg() {
        assert!(i >= disc - REQUIREMENT_ACCURACY_DEG);
        assert!(i <= disc * 1.0001, "{i} vs {disc}");
    }
}

/// Eq 15 / Figure 5: the requirement is met everywhere on each rectangle's boundary and
/// violated just outside its corners.
#[test]
fn requirement_met_on_rectangle_boundary_and_violated_just_outside() {
    let p = RequirementProblem::paper();
    let r = paper_requirement();
    let omega_m = p.omega_m_rad_per_s;
    for (axis, rect) in [(SensingAxis::X, r.x_plane), (SensingAxis::Y, r.y_plane)] {
        let plane = p.plane(axis).unwrap();
        assert!(rect.boundary_max_rad_per_s <= omega_m);
        let (a, b) = (rect.half_u_rad, rect.half_v_rad);
        for i in 0..=20 {
            let s = -1.0 + 0.1 * f64::from(i);
            for (u, v) in [(s * a, b), (s * a, -b), (a, s * b), (-a, s * b)] {
                assert!(plane.rate_error(u, v).unwrap() <= omega_m);
            }
        }
        let out = 1.0 + OUTSIDE_STEP_REL;
        let worst_corner = [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
            .iter()
            .map(|(su, sv)| plane.rate_error(su * a * out, sv * b * out).unwrap())
            .fold(0.0, f64::max);
        assert!(worst_corner > omega_m);
        // A larger-area rectangle is not admissible: growing either side alone breaks it.
        let grow_u = plane
            .rate_error(a * out, b)
            .unwrap()
            .max(plane.rate_error(-a * out, b).unwrap());
        let grow_v = plane
            .rate_error(a, b * out)
            .unwrap()
            .max(plane.rate_error(a, -b * out).unwrap());
        assert!(grow_u > omega_m || grow_v > omega_m);
    }
}

/// Eq 6: with no orientation error, least squares recovers Table 1 exactly (to rounding), and
/// reports full rank, a small condition number and zero residuals.
#[test]
fn least_squares_recovers_table_1_without_orientation_error_eq6() {
    let schedule = Schedule::paper_default();
    let site = Site::paper_default();
    let ident = vec![Matrix3::identity(); schedule.len()];
    let [x, y] =
        calibrate_simulated(&DriftCoefficients::table_1(), &schedule, &site, &ident).unwrap();
    for (c, table) in [(&x, TABLE_1_X_DEG_PER_H), (&y, TABLE_1_Y_DEG_PER_H)] {
        for (got, want) in c.coefficients.deg_per_h().iter().zip(table) {
            assert_abs_diff_eq!(*got, want, epsilon = TABLE1_RECOVERY_TOL_DEG_PER_H);
        }
        assert_eq!(c.solution.rank, 7);
        assert!(
            c.solution.condition_number < 10.0,
            "{}",
            c.solution.condition_number
        );
        assert!(rad_per_s_to_deg_per_h(c.solution.rms_residual()) < TABLE1_RECOVERY_TOL_DEG_PER_H);
    }
}

/// A schedule with $\phi_2$ only at multiples of 90° has $a_x a_y = 0$ at every position:
/// the typed error names $D(x)_{xy}$ (and nothing else).
#[test]
fn rank_deficient_schedule_is_rejected_naming_d_x_xy() {
    let mut pairs = Vec::new();
    for p1 in [0.0, 90.0, 180.0, 270.0] {
        for p2 in [0.0, 90.0, 180.0, 270.0] {
            pairs.push((p1, p2));
        }
    }
    match Schedule::from_deg(&pairs) {
        Err(CalibError::Unidentifiable {
            axis,
            coefficients,
            rank,
            positions,
        }) => {
            assert_eq!(axis, SensingAxis::X);
            assert_eq!(coefficients, vec!["D(x)_xy"]);
            assert_eq!(rank, 6);
            assert_eq!(positions, 16);
        }
        other => panic!("expected Unidentifiable, got {other:?}"),
    }
    // phi1 at three values gives only two values of a_z: F, z and zz cannot be separated.
    let err = Schedule::grid_deg(120.0, 45.0).unwrap_err();
    assert!(
        matches!(err, CalibError::Unidentifiable { ref coefficients, .. }
        if coefficients == &vec!["D(x)_F", "D(x)_z", "D(x)_zz"]),
        "{err}"
    );
    assert!(err.to_string().contains("D(x)_F, D(x)_z, D(x)_zz"));
}

/// Eq 13 readings, first order: with $\mathbf e = \mathbf b_2' - \mathbf b_2$,
/// $\mathbf g = (\mathbf A' - \mathbf A)\boldsymbol\beta$, $\mathbf P = \mathbf A\mathbf A^+$,
/// each reading's error vector is the combination documented in `calib_lsq::analysis`.
#[test]
fn readings_match_their_first_order_decomposition() {
    let schedule = Schedule::paper_default();
    let site = Site::paper_default();
    let angles = OrientationAngles::from_deg(0.02, -0.015, 0.01).unwrap();
    let dr = vec![angles.delta_r(DeltaRKind::SmallAngle); schedule.len()];
    for axis in SensingAxis::ALL {
        let truth = DriftCoefficients::table_1();
        let beta = DVector::from_column_slice(&truth.axis(axis).rad_per_s());
        let nominal = schedule.inputs(&site);
        let actual = calib_lsq::actual_inputs(&schedule, &site, &dr).unwrap();
        let a = regression_matrix(axis, &nominal);
        let e = rate_vector(axis, &actual) - rate_vector(axis, &nominal);
        let g = (regression_matrix(axis, &actual) - &a) * &beta;
        let q = a.clone().qr().q();
        let p: DMatrix<f64> = &q * q.transpose();
        let i = DMatrix::<f64>::identity(a.nrows(), a.nrows());
        let expected: Vec<(Reading, DVector<f64>, f64)> = vec![
            (Reading::PAPER, -&e, EXACT_DECOMPOSITION_REL),
            (
                Reading {
                    outputs: OutputsAt::Actual,
                    estimate: Estimate::Beta2,
                    form: ErrorForm::ActualRegressorsNominalRate,
                },
                e.clone(),
                EXACT_DECOMPOSITION_REL,
            ),
            (Reading::AS_PRINTED, g.clone(), EXACT_DECOMPOSITION_REL),
            (
                Reading::USER,
                (&i - &p) * &g - &p * &e,
                EXACT_DECOMPOSITION_REL,
            ),
            (
                Reading {
                    outputs: OutputsAt::Actual,
                    estimate: Estimate::Beta1,
                    form: ErrorForm::NominalRate,
                },
                (&i - &p) * (&g + &e),
                EXACT_DECOMPOSITION_REL,
            ),
            (
                Reading {
                    outputs: OutputsAt::Intended,
                    estimate: Estimate::Beta2,
                    form: ErrorForm::Printed,
                },
                &p * &g - (&i - &p) * &e,
                FIRST_ORDER_REL,
            ),
            (
                Reading {
                    outputs: OutputsAt::Actual,
                    estimate: Estimate::Beta1,
                    form: ErrorForm::DeltaBeta,
                },
                &p * (&g + &e),
                EXACT_DECOMPOSITION_REL,
            ),
        ];
        for (reading, want, tol) in expected {
            let got = analysis(axis, reading).analyze(&dr).unwrap().error_vector;
            let scale = want.amax();
            assert!(scale > 0.0);
            assert!(
                (&got - &want).amax() <= tol * scale,
                "{reading}: {got} vs {want}"
            );
        }
    }
}

/// Eq 7-14 with $\Delta\mathbf R = \mathbf I$ at every position: no error in any reading, and
/// $\hat{\boldsymbol\beta}_1 = \hat{\boldsymbol\beta}_2 = \boldsymbol\beta$.
#[test]
fn no_orientation_error_gives_no_rate_error_in_every_reading() {
    let n = Schedule::paper_default().len();
    for reading in Reading::all() {
        for axis in SensingAxis::ALL {
            let r = analysis(axis, reading)
                .analyze(&vec![Matrix3::identity(); n])
                .unwrap();
            assert!(
                rad_per_s_to_deg_per_h(r.delta_omega_rad_per_s) < 1e-12,
                "{reading}"
            );
            assert!(rad_per_s_to_deg_per_h(r.delta_beta.amax()) < 1e-10);
        }
    }
}

/// Every reading's name parses back to it, and unknown names are a typed error.
#[test]
fn reading_names_round_trip() {
    let all = Reading::all();
    assert_eq!(all.len(), 18);
    assert_eq!(all[0], Reading::PAPER);
    assert_eq!(Reading::PAPER.to_string(), "intended/beta1/printed");
    for r in all {
        assert_eq!(r.to_string().parse::<Reading>().unwrap(), r);
    }
    assert!(matches!(
        "intended/beta3/printed".parse::<Reading>(),
        Err(CalibError::UnknownReading { .. })
    ));
}

/// Figure 4 grid data equals point evaluations; Figure 5 boundary points have
/// $\Delta\omega = \omega_m$.
#[test]
fn surfaces_and_boundary_lines_agree_with_point_evaluation() {
    let p = RequirementProblem::paper();
    let plane = p.plane(SensingAxis::Y).unwrap();
    let s = plane.surface(0.05f64.to_radians(), 5).unwrap();
    assert_eq!(s.angle_names, ["delta_theta", "delta_gamma"]);
    assert_eq!(s.delta_omega_rad_per_s.len(), 5);
    assert_abs_diff_eq!(
        s.delta_omega_rad_per_s[2][2],
        0.0,
        epsilon = RATE_EQ_TOL_RAD_PER_S
    );
    assert_abs_diff_eq!(
        s.delta_omega_rad_per_s[4][1],
        plane.rate_error(s.u_rad[1], s.v_rad[4]).unwrap(),
        epsilon = RATE_EQ_TOL_RAD_PER_S
    );
    for [u, v] in plane.boundary(12).unwrap() {
        assert_relative_eq!(
            plane.rate_error(u, v).unwrap(),
            p.omega_m_rad_per_s,
            max_relative = 1e-6
        );
    }
    assert!(matches!(
        plane.surface(0.0, 5),
        Err(CalibError::BadGrid { .. })
    ));
}

/// Calibration input errors are typed and name the offending value.
#[test]
fn calibrate_rejects_bad_outputs_with_named_errors() {
    let s = Schedule::paper_default();
    let site = Site::paper_default();
    let mut b1 = vec![0.0; s.len()];
    assert!(matches!(
        calibrate(SensingAxis::X, &s, &site, &b1[..3]),
        Err(CalibError::LengthMismatch {
            what: "outputs",
            expected: 32,
            found: 3
        })
    ));
    b1[3] = f64::NAN;
    match calibrate(SensingAxis::X, &s, &site, &b1) {
        Err(CalibError::NonFinite { field, .. }) => assert_eq!(field, "outputs[3]"),
        other => panic!("{other:?}"),
    }
}

/// Sensitivity to latitude, in closed form: with the default schedule ($\phi_1$ in 90° steps)
/// the earth-rate directions $(\sin(\phi_1+\lambda), \cos(\phi_1+\lambda))$ sit at
/// $\lambda \bmod 90°$ from the axes, the region is an octagon and the best rectangle is the
/// square of half-side $\omega_m / (\sqrt2\,\omega_e \cos(\lambda' - 45°))$,
/// $\lambda' = \lambda \bmod 90°$. At Harbin that is 0.026938 deg; it rounds to 0.027 deg for
/// latitudes within about 11.6° of 45°.
#[test]
fn requirement_follows_closed_form_in_latitude_for_default_schedule() {
    let omega_m = deg_per_h_to_rad_per_s(PAPER_OMEGA_M_DEG_PER_H);
    for lat in [0.0, 30.0, 45.75, 60.0, 80.0] {
        let site = Site::from_deg(lat, Site::paper_default().earth_rate_rad_per_s()).unwrap();
        let p = RequirementProblem {
            site,
            ..RequirementProblem::paper()
        };
        let offset = (lat % 90.0 - 45.0_f64).to_radians();
        let want = (omega_m
            / (std::f64::consts::SQRT_2 * site.earth_rate_rad_per_s() * offset.cos()))
        .to_degrees();
        for got in p.requirement().unwrap().deg() {
            assert_abs_diff_eq!(got, want, epsilon = REQUIREMENT_ACCURACY_DEG);
        }
    }
}

/// The per-position interface (issue 7 feeds the exact turntable $\Delta\mathbf R$ of eq 23 per
/// position) agrees with the fixed-angle one, and the exact rotation changes the requirement by
/// less than $10^{-8}$ deg (second order).
#[test]
fn per_position_delta_r_and_exact_rotation_agree_with_small_angle_analysis() {
    let x = analysis(SensingAxis::X, Reading::USER);
    let angles = OrientationAngles::from_deg(0.01, 0.02, -0.03).unwrap();
    let n = Schedule::paper_default().len();
    let per_position = x
        .analyze(&vec![angles.delta_r(DeltaRKind::Exact); n])
        .unwrap();
    let fixed = x.analyze_angles(&angles, DeltaRKind::Exact).unwrap();
    assert_abs_diff_eq!(
        per_position.delta_omega_rad_per_s,
        fixed.delta_omega_rad_per_s,
        epsilon = RATE_EQ_TOL_RAD_PER_S
    );
    let exact = RequirementProblem {
        delta_r_kind: DeltaRKind::Exact,
        ..RequirementProblem::paper()
    }
    .requirement()
    .unwrap();
    for (e, s) in exact.deg().iter().zip(paper_requirement().deg()) {
        assert_abs_diff_eq!(*e, s, epsilon = 1e-8);
    }
}
