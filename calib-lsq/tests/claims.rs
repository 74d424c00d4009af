//! The paper's claims of §2.2-2.3 (eq 6-16), each test named after what it proves, on the
//! paper's sensor described as data; plus the general sensor machinery.

use approx::{assert_abs_diff_eq, assert_relative_eq};
use calib_lsq::{
    CalibError, Calibration, ErrorForm, Estimate, OrientationErrorAnalysis, OrientationRequirement,
    OutputsAt, Position, Reading, RequirementProblem, Schedule, design_matrix, known_vector, paper,
    simulate_outputs,
};
use gw_model::Site;
use gw_model::paper::{TABLE_1_X_DEG_PER_H, TABLE_1_Y_DEG_PER_H};
use nalgebra::{DMatrix, DVector, Matrix3};
use proptest::prelude::*;
use std::sync::OnceLock;
use tt_core::units::deg_per_h_to_rad_per_s;
use tt_core::{DeltaRKind, FieldError, OrientationError};

/// Rate errors are of order 1e-2 deg/h and come from cancelling outputs of up to ~100 deg/h
/// (Table 1), so values that must be equal agree to a few ulps of 100 deg/h: 3e-12 deg/h
/// (1e-17 rad/s), ~1e-10 relative.
const RATE_EQ_TOL_DEG_PER_H: f64 = 3e-12;
/// Table 1 recovered by least squares from exact simulated outputs (values <= 105 deg/h,
/// condition number ~5): 1e-9 deg/h is far below the printed rounding (0.001 deg/h).
const TABLE1_RECOVERY_TOL_DEG_PER_H: f64 = 1e-9;
/// The paper's rounding of eq 16: 0.027 deg means [0.0265, 0.0275) deg.
const EQ16_HALF_ROUNDING_DEG: f64 = 0.0005;
/// Requirement accuracy asked by the issue, deg.
const REQUIREMENT_ACCURACY_DEG: f64 = 1e-6;
/// Relative step outside the rectangle at which the requirement must be violated.
const OUTSIDE_STEP_REL: f64 = 1e-6;
/// The requirement is linear in the accuracy (the paper's reading with eq 7's small-angle
/// matrix makes the error vector linear in the angles): computed at two accuracies its ratio
/// equals theirs to this, dimensionless. Measured: at most 3e-9 across the scale at which the
/// search switches to the scaled reference box (`calib_lsq::RequirementParams::linear_regime_rad`), exact to
/// rounding below it and along the direct search above it.
const REQUIREMENT_SCALING_REL: f64 = 1e-8;
/// Decompositions that are exact given e and g (only A and P enter): rounding, relative to the
/// error's infinity norm.
const EXACT_DECOMPOSITION_REL: f64 = 1e-6;
/// Decompositions through beta-hat-2 with outputs at the intended orientation replace
/// A A'^+ by P, an error of relative order |A' - A| ~ angle = 3.5e-4 rad at 0.02 deg.
const FIRST_ORDER_REL: f64 = 1e-3;

fn paper_calibration() -> Calibration {
    Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &paper::schedule(),
    )
    .unwrap()
}

fn paper_problem() -> RequirementProblem {
    RequirementProblem::new(paper_calibration(), Reading::PAPER, DeltaRKind::SmallAngle)
}

fn paper_requirement() -> &'static OrientationRequirement {
    static R: OnceLock<OrientationRequirement> = OnceLock::new();
    R.get_or_init(|| {
        paper_problem()
            .requirement()
            .expect("paper inputs are valid")
    })
}

fn deg(r: &OrientationRequirement) -> [f64; 3] {
    r.requirement()
        .deg()
        .map(|d| d.expect("every angle constrained"))
}

fn analysis(k: usize, reading: Reading) -> OrientationErrorAnalysis {
    OrientationErrorAnalysis::new(&paper_calibration(), k, reading).unwrap()
}

/// Orientation errors up to 0.1 deg, the scale of Figure 4.
fn small_angle() -> impl Strategy<Value = f64> {
    (-0.1..0.1f64).prop_map(f64::to_radians)
}

/// The plane of each output (x: psi, theta; y: theta, gamma) as angle indices.
const PLANES: [[usize; 2]; 2] = [[0, 1], [1, 2]];

fn plane_point(k: usize, u: f64, v: f64) -> [f64; 3] {
    let mut d = [0.0; 3];
    d[PLANES[k][0]] = u;
    d[PLANES[k][1]] = v;
    d
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Claim (1), §2.2: $\Delta\omega_x$ is not affected by $\Delta\gamma$ and $\Delta\omega_y$
    /// not by $\Delta\psi$ (paper reading, eq 7).
    #[test]
    fn claim1_x_error_ignores_delta_gamma_and_y_error_ignores_delta_psi(
        psi in small_angle(), theta in small_angle(), gamma in small_angle(), other in small_angle(),
    ) {
        let k = DeltaRKind::SmallAngle;
        let x = analysis(0, Reading::PAPER);
        let y = analysis(1, Reading::PAPER);
        let a = OrientationError::new(psi, theta, gamma).unwrap();
        let x_other = OrientationError::new(psi, theta, other).unwrap();
        let y_other = OrientationError::new(other, theta, gamma).unwrap();
        assert_abs_diff_eq!(x.delta_omega_for_angles(&a, k).unwrap(), x.delta_omega_for_angles(&x_other, k).unwrap(), epsilon = RATE_EQ_TOL_DEG_PER_H);
        assert_abs_diff_eq!(y.delta_omega_for_angles(&a, k).unwrap(), y.delta_omega_for_angles(&y_other, k).unwrap(), epsilon = RATE_EQ_TOL_DEG_PER_H);
    }

    /// Claim (2), §2.2: $\Gamma_1$ is symmetric about $\Delta\psi = 0$ and $\Delta\theta = 0$,
    /// $\Gamma_2$ about $\Delta\theta = 0$ and $\Delta\gamma = 0$ (even functions).
    #[test]
    fn claim2_rate_errors_are_even_in_each_plane_angle(u in small_angle(), v in small_angle()) {
        let p = paper_problem();
        for k in 0..2 {
            let r = p.region(k).unwrap();
            let f = r.rate_error(plane_point(k, u, v)).unwrap();
            assert_abs_diff_eq!(f, r.rate_error(plane_point(k, -u, v)).unwrap(), epsilon = RATE_EQ_TOL_DEG_PER_H);
            assert_abs_diff_eq!(f, r.rate_error(plane_point(k, u, -v)).unwrap(), epsilon = RATE_EQ_TOL_DEG_PER_H);
        }
    }

    /// Claim (3), §2.2: $\Delta\omega$ rises with the magnitude of each plane angle (the other
    /// held fixed) and along every ray from the origin.
    #[test]
    fn claim3_rate_errors_rise_with_angle_magnitude(u in small_angle(), v in small_angle(), grow in 1.01..3.0f64) {
        let p = paper_problem();
        for k in 0..2 {
            let r = p.region(k).unwrap();
            let f = r.rate_error(plane_point(k, u, v)).unwrap();
            prop_assert!(r.rate_error(plane_point(k, grow * u, grow * v)).unwrap() > f);
            prop_assert!(r.rate_error(plane_point(k, grow * u, v)).unwrap() >= f);
            prop_assert!(r.rate_error(plane_point(k, u, grow * v)).unwrap() >= f);
        }
    }

    /// The estimate of eq 6 does not depend on the order of the positions.
    #[test]
    fn estimate_is_invariant_under_position_permutation(seed in any::<u64>()) {
        let schedule = paper::schedule();
        let site = gw_model::paper::site();
        let sensor = gw_model::paper::gyrowheel();
        let mut state = seed;
        let mut next = || { state = state.wrapping_add(0x9E37_79B9_7F4A_7C15); let mut z = state; z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9); z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB); z ^ (z >> 31) };
        let mut order: Vec<usize> = (0..schedule.len()).collect();
        for i in (1..order.len()).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            order.swap(i, j);
        }
        let permuted = schedule.permuted(&order).unwrap();
        let dr = vec![OrientationError::from_deg(0.02, -0.03, 0.01).unwrap().delta_r(DeltaRKind::Exact); schedule.len()];
        let cal = Calibration::new(&sensor, &site, &schedule).unwrap();
        let calp = Calibration::new(&sensor, &site, &permuted).unwrap();
        let actual = schedule.actual_inputs(&site, &dr).unwrap();
        for k in 0..2 {
            let b1 = simulate_outputs(&sensor.outputs()[k], &actual);
            let b1_perm: Vec<f64> = order.iter().map(|&i| b1[i]).collect();
            let c = cal.calibrate(k, b1.as_slice()).unwrap();
            let cp = calp.calibrate(k, &b1_perm).unwrap();
            for (a, b) in c.solution().beta().iter().zip(cp.solution().beta().iter()) {
                assert_abs_diff_eq!(*a, *b, epsilon = TABLE1_RECOVERY_TOL_DEG_PER_H);
            }
        }
    }
}

/// Claim (4), eq 16: with Table 1 and $\omega_m = 0.01$ deg/h the requirement is 0.027 deg for
/// all three angles (unrounded 0.0269380 deg with the default schedule at Harbin), recovered
/// by the general largest-box criterion from the sensor described as data.
#[test]
fn claim4_requirement_is_0_027_deg_for_all_three_angles_eq16() {
    let r = paper_requirement();
    for i in deg(r) {
        assert!((i - 0.027).abs() < EQ16_HALF_ROUNDING_DEG, "{i}");
        assert_abs_diff_eq!(i, 0.026_938_0, epsilon = 1e-7);
    }
    // x depends on (psi, theta), y on (theta, gamma): the paper's two rectangles
    assert_eq!(r.boxes().len(), 2);
    assert!(r.boxes()[0].half_rad()[2].is_none() && r.boxes()[1].half_rad()[0].is_none());
    for ratio in r.combined_corner_ratio() {
        assert!(*ratio <= 1.0 + 1e-9, "{ratio}");
    }
}

/// The lead behind claim (4): in the paper's reading $\Delta\omega_x = \max_i|\omega_{y,i}
/// \Delta\theta - \omega_{z,i}\Delta\psi|$ (earth-rate perturbation only), so with
/// earth-rate directions covering the circle the region is the disc of radius
/// $\omega_m/\omega_e$ and the best square has half-side $\omega_m/(\sqrt2\,\omega_e)$ =
/// 0.0269357 deg. A discrete schedule's polygon circumscribes the disc, so its requirement is
/// no smaller; the default schedule's is within 0.01 % of the disc value.
#[test]
fn requirement_is_close_to_disc_bound_omega_m_over_sqrt2_omega_e() {
    let disc = (deg_per_h_to_rad_per_s(gw_model::paper::OMEGA_M_DEG_PER_H)
        / (std::f64::consts::SQRT_2 * gw_model::paper::site().earth_rate_rad_per_s()))
    .to_degrees();
    assert_abs_diff_eq!(disc, 0.026_935_7, epsilon = 1e-7);
    for i in deg(paper_requirement()) {
        assert!(i >= disc - REQUIREMENT_ACCURACY_DEG);
        assert!(i <= disc * 1.0001, "{i} vs {disc}");
    }
}

/// The paper's sensor with every term value multiplied by `values` and every accuracy set to
/// `omega_m` (its unit): the requirement of eq 15-16 on the default schedule, paper's reading.
fn scaled_requirement(values: f64, omega_m: f64) -> [f64; 3] {
    let outputs = gw_model::paper::gyrowheel()
        .outputs()
        .iter()
        .map(|o| {
            let mut o = o.clone();
            o.accuracy = omega_m;
            for t in &mut o.terms {
                t.value *= values;
            }
            o
        })
        .collect();
    let sensor = gw_model::SensorModel::new(outputs).unwrap();
    let cal = Calibration::new(&sensor, &gw_model::paper::site(), &paper::schedule()).unwrap();
    deg(
        &RequirementProblem::new(cal, Reading::PAPER, DeltaRKind::SmallAngle)
            .requirement()
            .unwrap(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Eq 15-16 is linear in the accuracy: requirement(k omega_m) = k requirement(omega_m) for
    /// omega_m from 1e-12 (the smallest accepted accuracy) to 1e3 output units. The sensor's
    /// term values are 1000 times Table 1's (within the accepted 1e6), so the requirement stays
    /// below the search limit (0.5 rad) up to 1e3: 2.7 deg there, 2.7e-15 deg at 1e-12.
    /// (The search used to start at 1e-4 rad and stop at 1e-12 rad absolute: +14% at 1e-10,
    /// 0 deg at 1e-12 for Table 1's values.)
    #[test]
    fn requirement_scales_linearly_with_the_accuracy_from_1e_minus_12_to_1e3(
        log_w in -12.0..3.0f64,
        log_k in -15.0..15.0f64,
    ) {
        let w = 10f64.powf(log_w);
        let kw = 10f64.powf((log_w + log_k).clamp(-12.0, 3.0));
        let (a, b) = (scaled_requirement(1e3, w), scaled_requirement(1e3, kw));
        for j in 0..3 {
            prop_assert!(
                ((b[j] / a[j]) / (kw / w) - 1.0).abs() <= REQUIREMENT_SCALING_REL,
                "angle {j}: {} at {w:e}, {} at {kw:e}", a[j], b[j]
            );
        }
    }
}

/// The same for Table 1's own values over the accuracies whose requirement lies within the
/// search limit, at the points of the issue: 2.69380 deg per deg/h at 1e-12, 1e-11, 1e-10,
/// 1e-8, 0.01 and 3 deg/h.
#[test]
fn paper_requirement_per_unit_accuracy_is_the_same_from_1e_minus_12_to_3_deg_per_h() {
    let per = |w: f64| scaled_requirement(1.0, w).map(|d| d / w);
    let reference = per(0.01);
    for w in [1e-12, 1e-11, 1e-10, 1e-8, 3.0] {
        for (a, b) in per(w).iter().zip(&reference) {
            assert_relative_eq!(*a, *b, max_relative = REQUIREMENT_SCALING_REL);
        }
    }
    assert_relative_eq!(reference[0], 2.693_805, max_relative = 1e-6);
}

/// Eq 15 / Figure 5: the requirement is met everywhere on each rectangle's boundary and
/// violated just outside its corners.
#[test]
fn requirement_met_on_rectangle_boundary_and_violated_just_outside() {
    let p = paper_problem();
    let r = paper_requirement();
    for (k, [i0, i1]) in PLANES.into_iter().enumerate() {
        let region = p.region(k).unwrap();
        let omega_m = region.accuracy();
        let b = &r.boxes()[k];
        assert!(b.boundary_max_ratio() <= 1.0);
        let (a, c) = (b.half_rad()[i0].unwrap(), b.half_rad()[i1].unwrap());
        let at = |u, v| region.rate_error(plane_point(k, u, v)).unwrap();
        for i in 0..=20 {
            let s = -1.0 + 0.1 * f64::from(i);
            for (u, v) in [(s * a, c), (s * a, -c), (a, s * c), (-a, s * c)] {
                assert!(at(u, v) <= omega_m);
            }
        }
        let out = 1.0 + OUTSIDE_STEP_REL;
        let worst_corner = [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
            .iter()
            .map(|(su, sv)| at(su * a * out, sv * c * out))
            .fold(0.0, f64::max);
        assert!(worst_corner > omega_m);
        let grow_u = at(a * out, c).max(at(-a * out, c));
        let grow_v = at(a, c * out).max(at(a, -c * out));
        assert!(grow_u > omega_m || grow_v > omega_m);
    }
}

/// Eq 6: with no orientation error, least squares recovers Table 1 exactly (to rounding), and
/// reports full rank, a small condition number and zero residuals.
#[test]
fn least_squares_recovers_table_1_without_orientation_error_eq6() {
    let cal = paper_calibration();
    let results = cal
        .calibrate_simulated(&vec![Matrix3::identity(); 32])
        .unwrap();
    for (c, table) in results
        .iter()
        .zip([TABLE_1_X_DEG_PER_H, TABLE_1_Y_DEG_PER_H])
    {
        for (got, want) in c.solution().beta().iter().zip(table) {
            assert_abs_diff_eq!(*got, want, epsilon = TABLE1_RECOVERY_TOL_DEG_PER_H);
        }
        assert_eq!(c.solution().conditioning().rank(), 7);
        assert!(
            c.solution().conditioning().condition_number() < 10.0,
            "{}",
            c.solution().conditioning().condition_number()
        );
        assert!(c.solution().rms_residual() < TABLE1_RECOVERY_TOL_DEG_PER_H);
    }
}

/// The condition number comes from singular values of R (Jacobi SVD), not from the
/// eigenvalues of R^T R: it equals the ratio of the singular values of an independent
/// reference (the square roots of the eigenvalues of A^T A computed in a well-conditioned
/// case) and, for a matrix with condition number 1e10, is accurate where squaring would
/// not be.
#[test]
fn condition_number_is_accurate_for_ill_conditioned_matrices() {
    let cal = paper_calibration();
    let a = cal.outputs()[0].regression().matrix().clone();
    let eig = (a.transpose() * &a).symmetric_eigenvalues();
    let mut sv: Vec<f64> = eig.iter().map(|l| l.sqrt()).collect();
    sv.sort_by(|x, y| y.total_cmp(x));
    let ours = cal.outputs()[0].regression().singular_values();
    for (x, y) in ours.iter().zip(&sv) {
        assert_relative_eq!(*x, *y, max_relative = 1e-12);
    }
    // diag(1, 1e-10) rotated: singular values exactly 1 and 1e-10
    let (c, s) = (0.6, 0.8);
    let q = DMatrix::from_row_slice(3, 2, &[c, -s, s, c, 0.0, 0.0]);
    let m = q * DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1e-10]);
    let r = calib_lsq::Regression::new("t", vec!["p".into(), "q".into()], m).unwrap();
    assert_relative_eq!(r.condition_number(), 1e10, max_relative = 1e-6);
}

/// A schedule with $\phi_2$ only at multiples of 90° has $a_x a_y = 0$ at every position:
/// the typed error names output x and $D(x)_{xy}$ (and nothing else).
#[test]
fn rank_deficient_schedule_is_rejected_naming_d_x_xy() {
    let s = paper::grid(&[0.0, 90.0, 180.0, 270.0], &[0.0, 90.0, 180.0, 270.0]).unwrap();
    match Calibration::new(&gw_model::paper::gyrowheel(), &gw_model::paper::site(), &s) {
        Err(CalibError::Unidentifiable {
            output,
            coefficients,
            rank,
            columns,
            positions,
        }) => {
            assert_eq!(output, "x");
            assert_eq!(coefficients, vec!["dx_xy"]);
            assert_eq!((rank, columns, positions), (6, 7, 16));
        }
        other => panic!("expected Unidentifiable, got {other:?}"),
    }
    // phi1 at three values gives only two values of a_z: F, z and zz cannot be separated.
    let s = paper::grid(
        &[0.0, 120.0, 240.0],
        &[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0],
    )
    .unwrap();
    let err =
        Calibration::new(&gw_model::paper::gyrowheel(), &gw_model::paper::site(), &s).unwrap_err();
    assert!(
        err.to_string().contains("dx_f, dx_z, dx_zz of output `x`"),
        "{err}"
    );
}

/// Eq 13 readings, first order: with $\mathbf e = \mathbf b_2' - \mathbf b_2$,
/// $\mathbf g = (\mathbf A' - \mathbf A)\boldsymbol\beta$, $\mathbf P = \mathbf A\mathbf A^+$,
/// each reading's error vector is the combination documented in `calib_lsq::analysis`.
#[test]
fn readings_match_their_first_order_decomposition() {
    let cal = paper_calibration();
    let site = gw_model::paper::site();
    let schedule = paper::schedule();
    let angles = OrientationError::from_deg(0.02, -0.015, 0.01).unwrap();
    let dr = vec![angles.delta_r(DeltaRKind::SmallAngle); schedule.len()];
    let nominal = schedule.inputs(&site);
    let actual = schedule.actual_inputs(&site, &dr).unwrap();
    for (k, o) in cal.sensor().outputs().iter().enumerate() {
        let beta = DVector::from_vec(o.estimated_values());
        let a = design_matrix(o, &nominal);
        let e = known_vector(o, &actual) - known_vector(o, &nominal);
        let g = (design_matrix(o, &actual) - &a) * &beta;
        let q = a.clone().qr().q();
        let p: DMatrix<f64> = &q * q.transpose();
        let i = DMatrix::<f64>::identity(a.nrows(), a.nrows());
        let r = |outputs, estimate, form| Reading {
            outputs,
            estimate,
            form,
        };
        let expected: Vec<(Reading, DVector<f64>, f64)> = vec![
            (Reading::PAPER, -&e, EXACT_DECOMPOSITION_REL),
            (
                r(
                    OutputsAt::Actual,
                    Estimate::Beta2,
                    ErrorForm::ActualRegressorsNominalRate,
                ),
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
                r(OutputsAt::Actual, Estimate::Beta1, ErrorForm::NominalRate),
                (&i - &p) * (&g + &e),
                EXACT_DECOMPOSITION_REL,
            ),
            (
                r(OutputsAt::Intended, Estimate::Beta2, ErrorForm::Printed),
                &p * &g - (&i - &p) * &e,
                FIRST_ORDER_REL,
            ),
            (
                r(OutputsAt::Actual, Estimate::Beta1, ErrorForm::DeltaBeta),
                &p * (&g + &e),
                EXACT_DECOMPOSITION_REL,
            ),
        ];
        for (reading, want, tol) in expected {
            let got = analysis(k, reading)
                .analyze(&dr)
                .unwrap()
                .error_vector()
                .clone();
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
    for reading in Reading::all() {
        for k in 0..2 {
            let r = analysis(k, reading)
                .analyze(&vec![Matrix3::identity(); 32])
                .unwrap();
            assert!(r.delta_omega() < 1e-12, "{reading}");
            assert!(r.delta_beta().amax() < 1e-10);
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
    let p = paper_problem();
    let region = p.region(1).unwrap();
    assert_eq!(region.sensitive_angles(), &[1, 2]);
    let s = region.surface([1, 2], 0.05f64.to_radians(), 5).unwrap();
    assert_eq!(s.delta_omega().len(), 5);
    assert_abs_diff_eq!(s.delta_omega()[2][2], 0.0, epsilon = RATE_EQ_TOL_DEG_PER_H);
    assert_abs_diff_eq!(
        s.delta_omega()[4][1],
        region
            .rate_error([0.0, s.u_rad()[1], s.v_rad()[4]])
            .unwrap(),
        epsilon = RATE_EQ_TOL_DEG_PER_H
    );
    for [u, v] in region.boundary([1, 2], 12).unwrap() {
        assert_relative_eq!(
            region.rate_error([0.0, u, v]).unwrap(),
            region.accuracy(),
            max_relative = 1e-6
        );
    }
    assert!(matches!(
        region.surface([1, 2], 0.0, 5),
        Err(CalibError::BadGrid { .. })
    ));
}

/// Calibration input errors are typed and name the offending value.
#[test]
fn calibrate_rejects_bad_outputs_with_named_errors() {
    let cal = paper_calibration();
    let mut b1 = vec![0.0; 32];
    assert!(matches!(
        cal.calibrate(0, &b1[..3]),
        Err(CalibError::Field(FieldError::Length {
            ref field,
            expected: 32,
            found: 3
        })) if field == "outputs"
    ));
    b1[3] = f64::NAN;
    match cal.calibrate(0, &b1) {
        Err(CalibError::Field(FieldError::NonFinite { field, .. })) => {
            assert_eq!(field, "outputs[3]")
        }
        other => panic!("{other:?}"),
    }
    assert!(Position::new(Matrix3::identity() * f64::NAN, vec![0.0]).is_err());
    assert!(Schedule::new(vec![]).is_err());
}

/// Sensitivity to latitude, in closed form: with the default schedule ($\phi_1$ in 90° steps)
/// the earth-rate directions $(\sin(\phi_1+\lambda), \cos(\phi_1+\lambda))$ sit at
/// $\lambda \bmod 90°$ from the axes, the region is an octagon and the best rectangle is the
/// square of half-side $\omega_m / (\sqrt2\,\omega_e \cos(\lambda' - 45°))$,
/// $\lambda' = \lambda \bmod 90°$. At Harbin that is 0.026938 deg; it rounds to 0.027 deg for
/// latitudes within about 11.6° of 45°.
#[test]
fn requirement_follows_closed_form_in_latitude_for_default_schedule() {
    let omega_m = deg_per_h_to_rad_per_s(gw_model::paper::OMEGA_M_DEG_PER_H);
    let we = gw_model::paper::site().earth_rate_rad_per_s();
    for lat in [0.0, 30.0, 45.75, 60.0, 80.0] {
        let site = Site::from_deg(lat, we).unwrap();
        let cal =
            Calibration::new(&gw_model::paper::gyrowheel(), &site, &paper::schedule()).unwrap();
        let p = RequirementProblem::new(cal, Reading::PAPER, DeltaRKind::SmallAngle);
        let offset = (lat % 90.0 - 45.0_f64).to_radians();
        let want = (omega_m / (std::f64::consts::SQRT_2 * we * offset.cos())).to_degrees();
        for got in deg(&p.requirement().unwrap()) {
            assert_abs_diff_eq!(got, want, epsilon = REQUIREMENT_ACCURACY_DEG);
        }
    }
}

/// The per-position interface (end to end feeds the exact turntable $\Delta\mathbf R$ of eq 23
/// per position) agrees with the fixed-angle one, and the exact rotation changes the
/// requirement by less than $10^{-8}$ deg (second order).
#[test]
fn per_position_delta_r_and_exact_rotation_agree_with_small_angle_analysis() {
    let x = analysis(0, Reading::USER);
    let angles = OrientationError::from_deg(0.01, 0.02, -0.03).unwrap();
    let per_position = x
        .analyze(&vec![angles.delta_r(DeltaRKind::Exact); 32])
        .unwrap();
    let fixed = x.analyze_angles(&angles, DeltaRKind::Exact).unwrap();
    assert_abs_diff_eq!(
        per_position.delta_omega(),
        fixed.delta_omega(),
        epsilon = RATE_EQ_TOL_DEG_PER_H
    );
    let exact = RequirementProblem::new(paper_calibration(), Reading::PAPER, DeltaRKind::Exact)
        .requirement()
        .unwrap();
    for (e, s) in deg(&exact).iter().zip(deg(paper_requirement())) {
        assert_abs_diff_eq!(*e, s, epsilon = 1e-8);
    }
}

/// A given requirement is compared with the computed one axis by axis: equal values agree, a
/// relative change above `DISAGREE_REL` on one axis names that axis alone with both values.
#[test]
fn a_given_requirement_disagrees_with_the_computed_one_only_on_the_axes_that_differ() {
    use calib_lsq::{AxisDisagreement, DISAGREE_REL};
    use tt_core::OrientationAxis;
    let r = paper_requirement();
    let computed = r.requirement().to_array().map(|v| v.expect("constrained"));
    assert!(r.disagreement(computed).is_empty());
    // within the threshold: agrees
    let mut close = computed;
    close[0] *= 1.0 + 0.5 * DISAGREE_REL;
    assert!(r.disagreement(close).is_empty());
    let mut given = computed;
    given[1] *= 1.01;
    assert_eq!(
        r.disagreement(given),
        [AxisDisagreement::Differs {
            axis: OrientationAxis::ALL[1],
            given_rad: given[1],
            computed_rad: computed[1],
        }]
    );
}
