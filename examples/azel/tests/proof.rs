//! The proof of issue 20 item 1 and issue 33 item 7: a model that is not a `Turntable`,
//! written once (its exact orientation error), goes through allocation (its own allocator and
//! the library's, with certificates), the exact-chain margin, the conformance suite, the Monte
//! Carlo and the schedule seam (`AtPoses`), through the public API only. Every number is
//! checked against an independent closed form.

use alloc_opt::{
    AllocationProblem, Allocator, EqualEffects, LinearErrorModel, Linearised, MethodDetails,
    SensitivityWeighted, allocate_with_exact_margin, exact_chain_check,
};
use approx::assert_relative_eq;
use azel::{AzElMount, ERROR_NAMES, UniformBound, linearised};
use std::f64::consts::{FRAC_PI_2, PI};
use tt_core::{OrientationAxis, Pose, Requirement};
use tt_kinematics::conformance::{Tolerances, cases_in, check_model_general};
use tt_kinematics::{
    AtPoses, DERIVED_FIRST_ORDER_TOLERANCE, KinematicsError, OrientationError,
    OrientationErrorModel, ScheduleErrorModel, TurntableErrors,
};

/// 1 arcmin on every angle (rad).
const I: f64 = PI / 180.0 / 60.0;

/// Relative tolerance of bounds that are closed forms evaluated in floating point, or
/// optimised by the exchange method (which ends within 1e-13 of tight, polished to
/// rounding); 1e-9 leaves room for the conic solver's last digits.
const ALLOC_REL: f64 = 1e-9;

/// Absolute tolerance (rad) for the flexure's exact effect: a few ulp of a 3x3 chain.
const EXACT_ABS_RAD: f64 = 1e-15;

/// The proven worst case of the derived linear model exceeds the grid's value by at most
/// this share (Bernstein's bound with 180 grid points per joint, `alloc_opt::Linearised`:
/// $d\sum_i h_i/2 / (1 - d\sum_i h'_i/2) \approx 2.2\%$ of the weighted coefficient maxima),
/// so the allocations are the closed forms shrunk by at most it.
const PROOF_GAP_REL: f64 = 0.025;

fn problem() -> AllocationProblem<Linearised<AzElMount>> {
    AllocationProblem::new(
        linearised().unwrap(),
        Requirement::new(I, I, I).unwrap(),
        vec![0.0; 4],
    )
    .unwrap()
}

/// `got` is `want` shrunk by the proof's gap: within `(1 - PROOF_GAP_REL) want ..= want`.
fn shrunk(got: f64, want: f64) {
    assert!(
        got <= want * (1.0 + ALLOC_REL) && got >= want * (1.0 - PROOF_GAP_REL),
        "{got} vs {want}"
    );
}

#[test]
fn the_flexure_tilts_the_platform_by_chi_cos_el_exactly() {
    // Only the flexure: Delta-R = R_y(chi cos e), so Delta-psi = sin(chi cos e) exactly and
    // the other two angles vanish, whatever the azimuth.
    let chi = 0.01;
    for (a_deg, e_deg) in [(0.0, 0.0), (37.0, 60.0), (250.0, 89.0)] {
        let pose = Pose::from_deg(&[a_deg, e_deg]).unwrap();
        let errors = TurntableErrors::new(vec![0.0, 0.0, 0.0, chi], vec![]).unwrap();
        let o = AzElMount.orientation_error(&pose, &errors).unwrap();
        let e = f64::to_radians(e_deg);
        assert_relative_eq!(
            o.delta_psi_rad,
            (chi * e.cos()).sin(),
            epsilon = EXACT_ABS_RAD
        );
        assert!(o.delta_theta_rad.abs() <= EXACT_ABS_RAD);
        assert!(o.delta_gamma_rad.abs() <= EXACT_ABS_RAD);
    }
}

#[test]
fn the_mount_passes_the_conformance_suite_against_its_own_first_order() {
    let m = AzElMount;
    let cases = cases_in(&m.joint_ranges_rad(), 4, 0, 200, 10.0 * I);
    check_model_general(
        &m,
        &TurntableErrors::zero(4, 0),
        &cases,
        &Tolerances::default(),
    )
    .unwrap_or_else(|f| panic!("{f}"));
    // an analytic first order supplied through the hook is checked against the derived one:
    // the closed form passes, the closed form with the flexure's sign flipped does not
    let tol = Tolerances::default();
    let zero = TurntableErrors::zero(4, 0);
    check_model_general(&Analytic { flip: false }, &zero, &cases, &tol).unwrap();
    let f = check_model_general(&Analytic { flip: true }, &zero, &cases, &tol).unwrap_err();
    assert_eq!(f.check(), "derived-first-order", "{f}");
    assert!(f.detail().contains("flexure"), "{f}");
}

/// The mount with its closed-form first order supplied through the hook (`flip`: with the
/// flexure's coefficient of the wrong sign).
struct Analytic {
    flip: bool,
}

impl OrientationErrorModel for Analytic {
    fn error_names(&self) -> Vec<String> {
        AzElMount.error_names()
    }
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        AzElMount.orientation_error(pose, errors)
    }
    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<nalgebra::Matrix3<f64>, KinematicsError> {
        AzElMount.delta_r(pose, errors)
    }
    fn first_order(
        &self,
        pose: &Pose,
        _zero: &TurntableErrors,
    ) -> Result<nalgebra::DMatrix<f64>, KinematicsError> {
        let c = AzElMount::coefficients(pose.angles_rad()[0], pose.angles_rad()[1]);
        let sign = if self.flip { -1.0 } else { 1.0 };
        Ok(nalgebra::DMatrix::from_fn(3, 4, |k, j| {
            if j == 3 { sign * c[k][j] } else { c[k][j] }
        }))
    }
}

#[test]
fn the_derived_first_order_is_the_closed_form_within_its_stated_bound() {
    let mut worst = 0.0_f64;
    for ia in 0..=36 {
        for ie in 0..=9 {
            let (a, e) = (
                f64::from(ia) * 10f64.to_radians(),
                f64::from(ie) * 10f64.to_radians(),
            );
            let j = AzElMount
                .first_order(
                    &Pose::new(vec![a, e]).unwrap(),
                    &TurntableErrors::zero(4, 0),
                )
                .unwrap();
            let c = AzElMount::coefficients(a, e);
            for k in 0..3 {
                for jj in 0..4 {
                    worst = worst.max((j[(k, jj)] - c[k][jj]).abs());
                }
            }
        }
    }
    println!("az/el: derived first order within {worst:e} of the closed form");
    assert!(worst <= DERIVED_FIRST_ORDER_TOLERANCE, "{worst}");
    // a chi of the wrong size is a typed error naming both sizes, never a panic
    let e = AzElMount
        .first_order(
            &Pose::from_deg(&[0.0, 0.0]).unwrap(),
            &TurntableErrors::zero(3, 0),
        )
        .unwrap_err();
    assert_eq!(
        e,
        KinematicsError::Field(tt_core::FieldError::Length {
            field: "chi".into(),
            expected: 4,
            found: 3
        })
    );
}

#[test]
fn the_derived_linear_model_has_the_closed_form_worst_cases_and_averages_with_a_proof() {
    let m = linearised().unwrap();
    assert_eq!(
        (0..4).map(|j| m.error_name(j)).collect::<Vec<_>>(),
        ERROR_NAMES
    );
    let w = [1.0, 0.5, 0.25, 2.0];
    // psi: w0 + w1 + w3 at (90 deg, 0); theta: w0 + w2 at (0, 90 deg); gamma: w0 + w2 at 0
    let want = [w[0] + w[1] + w[3], w[0] + w[2], w[0] + w[2]];
    for (k, want) in want.iter().enumerate() {
        let row = m.worst_case(k, &w).unwrap();
        assert_relative_eq!(row.value(), *want, max_relative = 1e-9);
        assert!(!row.is_exact());
        assert!(row.upper_bound() >= row.value());
        assert!(
            row.upper_bound() <= row.value() * (1.0 + PROOF_GAP_REL),
            "{row:?}"
        );
    }
    // the involved errors: structural zeros stay zero
    assert_eq!(m.involved(0), vec![0, 1, 3]);
    assert_eq!(m.involved(1), vec![0, 2]);
    // averages of |c| (2/pi, 4/pi^2, 1, 0) by the grid's quadrature: within 1%
    let h = 2.0 / PI;
    let avg = m.average_abs_coefficients();
    let want = [h, 1.0, 0.0, h, h * h, 0.0, h, 0.0, h * h, 0.0, h, 0.0];
    for (k, row) in want.chunks(4).enumerate() {
        for (j, v) in row.iter().enumerate() {
            assert!((avg[(k, j)] - v).abs() <= 0.01 * v.max(1e-300), "{k} {j}");
        }
    }
}

#[test]
fn the_library_equal_effects_allocation_is_the_closed_form_with_its_certificate() {
    // psi: x0 + x1 + x3 <= I shared equally (I/3 each); theta, gamma: x0 + x2 <= I (I/2
    // each); rule (34): x0 = min(I/3, I/2) = I/3.
    // (each shrunk by the proof's gap)
    let b = EqualEffects.allocate(&problem()).unwrap();
    let want = [I / 3.0, I / 3.0, I / 2.0, I / 3.0];
    for (got, want) in b.upper_bounds_rad().iter().zip(want) {
        shrunk(*got, want);
    }
    assert_eq!(b.error_names(), ERROR_NAMES.map(String::from).as_slice());
    let c = b.certificate();
    assert!(c.lemma1_holds() && !c.exact());
    // the proven bound is within the requirement
    for axis in OrientationAxis::ALL {
        assert!(c.get(axis).upper_bound_rad() <= I * (1.0 + ALLOC_REL));
    }
    // theta's worst case is x0 + x2 at the zenith
    let theta = c.get(OrientationAxis::Theta);
    let u = b.upper_bounds_rad();
    assert_relative_eq!(
        theta.worst_case_rad(),
        u[0] + u[2],
        max_relative = ALLOC_REL
    );
    assert_eq!(theta.worst_pose_rad(), vec![0.0, FRAC_PI_2]);
    assert_eq!(b.subproblems().len(), 3);
}

#[test]
fn the_library_sensitivity_weighted_allocation_is_the_kkt_optimum_with_its_certificate() {
    // psi's problem: min sum W_i^2/x_i^2 s.t. x0 + x1 + x3 <= I with W = 1/avg|c| =
    // (pi/2, 1, pi/2): KKT gives x_i = I W_i^(2/3) / sum_j W_j^(2/3).
    let b = SensitivityWeighted::general().allocate(&problem()).unwrap();
    let w: [f64; 3] = [FRAC_PI_2, 1.0, FRAC_PI_2];
    let sum: f64 = w.iter().map(|v| v.powf(2.0 / 3.0)).sum();
    let psi = b.subproblems().iter().find(|s| s.name() == "psi").unwrap();
    assert_eq!(psi.components(), vec![0, 1, 3]);
    // (the weights are the grid's averages, within 1% of the closed form's: 2% on the bounds)
    for (x, wi) in psi.bounds_rad().iter().zip(w) {
        assert_relative_eq!(*x, I * wi.powf(2.0 / 3.0) / sum, max_relative = 0.02);
    }
    // theta and gamma: W = (pi^2/4, pi/2) for x0, x2
    let wt: [f64; 2] = [PI * PI / 4.0, FRAC_PI_2];
    let st: f64 = wt.iter().map(|v| v.powf(2.0 / 3.0)).sum();
    let theta = b
        .subproblems()
        .iter()
        .find(|s| s.name() == "theta")
        .unwrap();
    assert_relative_eq!(
        theta.bounds_rad()[1],
        I * wt[1].powf(2.0 / 3.0) / st,
        max_relative = 0.02
    );
    // rule (34), shrunk by the proof's gap, and the certificate
    let x0 = psi.bounds_rad()[0].min(theta.bounds_rad()[0]);
    shrunk(b.upper_bounds_rad()[0], x0);
    assert!(b.certificate().lemma1_holds());
    // the paper's quarter ranges belong to a turntable, not to this model: a typed error
    let e = SensitivityWeighted::paper()
        .allocate(&problem())
        .unwrap_err();
    assert!(e.to_string().contains("does not apply"), "{e}");
}

#[test]
fn our_own_allocator_reuses_the_public_finishing_step() {
    // one bound for all: u = min(I/3, I/2, I/2) = I/3; psi uses all of I, theta 2/3 of it
    // (u from the proven bound: I/3 shrunk by the proof's gap)
    let b = UniformBound.allocate(&problem()).unwrap();
    assert_eq!(b.method(), "uniform-bound");
    let u = b.upper_bounds_rad()[0];
    shrunk(u, I / 3.0);
    for v in b.upper_bounds_rad() {
        assert_relative_eq!(*v, u, max_relative = ALLOC_REL);
    }
    let c = b.certificate();
    assert!(c.lemma1_holds());
    assert_relative_eq!(
        c.get(OrientationAxis::Psi).worst_case_rad(),
        3.0 * u,
        max_relative = ALLOC_REL
    );
    assert_relative_eq!(
        c.get(OrientationAxis::Theta).worst_case_rad(),
        2.0 * u,
        max_relative = ALLOC_REL
    );
    assert!(matches!(b.details(), MethodDetails::External { .. }));
    // J = sum_k sum_i W_ki^2 / u^2 with W = 1/avg|c| (psi: pi/2, 1, pi/2; theta and gamma:
    // pi^2/4, pi/2)
    let w2: f64 =
        2.0 * (PI / 2.0).powi(2) + 1.0 + 2.0 * ((PI * PI / 4.0).powi(2) + (PI / 2.0).powi(2));
    // (with the grid's averages: within 2%)
    assert_relative_eq!(b.objective(), w2 / (u * u), max_relative = 0.02);
    // the same allocator on a problem with only psi constrained: theta and gamma's own
    // errors (non_perp) get no bound
    let p = AllocationProblem::with_limits(
        linearised().unwrap(),
        vec![Some(I), None, None],
        vec![0.0; 4],
    )
    .unwrap();
    let b = UniformBound.allocate(&p).unwrap();
    assert_eq!(b.unconstrained(), &[2]);
    assert!(b.upper_bounds_rad()[2].is_infinite());
}

#[test]
fn the_model_at_a_schedule_of_poses_is_a_schedule_error_model() {
    let poses: Vec<Pose> = [(0.0, 0.0), (90.0, 30.0), (180.0, 60.0), (270.0, 90.0)]
        .iter()
        .map(|&(a, e)| Pose::from_deg(&[a, e]).unwrap())
        .collect();
    let s = AtPoses::of(AzElMount, poses.clone());
    assert_eq!((s.n_errors(), s.n_positions()), (4, 4));
    let chi = [2e-4, -1e-4, 3e-4, 5e-4];
    let mut dr = vec![nalgebra::Matrix3::identity(); 4];
    s.delta_r_into(&chi, &mut dr).unwrap();
    for (i, p) in poses.iter().enumerate() {
        let (a, e) = (p.angles_rad()[0], p.angles_rad()[1]);
        // the schedule's first order is the closed form (derived, within its bound)
        let j = s.first_order(i).unwrap();
        let c = AzElMount::coefficients(a, e);
        for k in 0..3 {
            for (jj, want) in c[k].iter().enumerate() {
                assert!((j[(k, jj)] - want).abs() <= DERIVED_FIRST_ORDER_TOLERANCE);
            }
        }
        // and Delta-R is the model's, within second order of the linear prediction
        let lin: Vec<f64> = (0..3)
            .map(|k| (0..4).map(|jj| c[k][jj] * chi[jj]).sum())
            .collect();
        let o = tt_core::OrientationError::from_matrix_elements(&dr[i]).to_array();
        let s1: f64 = chi.iter().map(|v| v.abs()).sum();
        for k in 0..3 {
            assert!((o[k] - lin[k]).abs() <= s1 * s1, "position {i} angle {k}");
        }
    }
}

/// The exact chain's worst case over the allocated box, hunted on the mount's own exact
/// orientation error, exceeds the linear one by second order only; the margin keeps it within
/// the requirement.
#[test]
fn the_exact_chain_margin_keeps_the_mounts_exact_worst_case_within_the_requirement() {
    let p = problem();
    let b = EqualEffects.allocate(&p).unwrap();
    let check = exact_chain_check(&p, &b).unwrap();
    let s: f64 = b.upper_bounds_rad().iter().sum();
    for c in &check {
        // 2^4 sign vertices at the worst pose and on the scan grid
        assert!(c.evaluations() >= 16, "{c:?}");
        assert!(
            (c.exact_worst_rad() - c.linear_worst_rad()).abs() <= s * s,
            "{c:?}"
        );
    }
    let safe = allocate_with_exact_margin(&EqualEffects, &p).unwrap();
    for c in safe.check() {
        assert!(c.exact_worst_rad() <= I, "{c:?}");
        assert!(c.excess_rad().unwrap() <= 0.0);
    }
    assert!(
        safe.margin() >= 0.0 && safe.margin() < 0.01,
        "{}",
        safe.margin()
    );
}

/// Relative tolerance of a Monte Carlo standard deviation from 200,000 draws against its
/// closed form: the sampling error of a standard deviation is about 1/sqrt(2n) times a
/// kurtosis factor (~0.3% here); 2% leaves room and still fails a wrong coefficient.
const MC_STD_REL: f64 = 0.02;

#[test]
fn the_monte_carlo_of_the_mount_matches_the_closed_form_moments() {
    use mc_verify::{ErrorBox, McConfig, MonteCarlo};
    let u = I;
    let b = ErrorBox::with_names(AzElMount.error_names(), vec![0.0; 4], vec![u; 4]).unwrap();
    let cfg = McConfig::new(200_000, 2026, Requirement::new(I, I, I).unwrap());
    let mc = MonteCarlo::for_model(AzElMount, AzElMount.joint_ranges_rad(), b, cfg).unwrap();
    // the histogram range comes from the model's own first order: psi's worst case is
    // u0 + u1 + u3 = 3u at (90 deg, 0), on the grid; plus the remainder e^S - 1 - S
    let s: f64 = 4.0 * u;
    let rem = s.exp_m1() - s;
    // (the derived first order: within its stated bound, 1e-8 rad per rad)
    assert_relative_eq!(
        mc.half_range_rad()[0],
        1.05 * 3.0 * u + rem,
        max_relative = 1e-8
    );
    let r = mc.try_run().unwrap();
    assert_eq!(r.count().samples(), 200_000);
    // chi uniform on [-u, u] (E chi^2 = u^2/3), a uniform on a turn (E sin^2 = 1/2), e
    // uniform on [0, 90 deg] (E cos^2 = E sin^2 = 1/2): Var psi = (u^2/3)(1/2 + 1 + 1/2),
    // Var theta = Var gamma = (u^2/3)(1/4 + 1/2) to first order
    let std = r.std_rad();
    assert_relative_eq!(
        std[0],
        u * (2.0_f64 / 3.0).sqrt(),
        max_relative = MC_STD_REL
    );
    assert_relative_eq!(std[1], u / 2.0, max_relative = MC_STD_REL);
    assert_relative_eq!(std[2], u / 2.0, max_relative = MC_STD_REL);
    for k in 0..3 {
        let h = &r.axes()[k].histogram();
        assert_eq!(h.overflow() + h.underflow(), 0);
    }
    // every draw within the box's worst case (psi: 3u, theta and gamma: 2u) plus remainder
    let m = r.max_abs_rad();
    assert!(m[0] <= 3.0 * u + rem && m[1] <= 2.0 * u + rem && m[2] <= 2.0 * u + rem);
    // same seed, same answer
    assert_eq!(
        mc.try_run().unwrap().max_abs_rad().map(f64::to_bits),
        m.map(f64::to_bits)
    );
}

/// A box of the wrong size for the mount is a typed error naming both sizes (it panicked with
/// an index out of bounds before the model owned its error count).
#[test]
fn a_box_of_the_wrong_size_for_the_mount_is_a_typed_error() {
    use mc_verify::{ErrorBox, McConfig, McError, MonteCarlo};
    let names: Vec<String> = ERROR_NAMES[..3].iter().map(|n| n.to_string()).collect();
    let b = ErrorBox::with_names(names, vec![0.0; 3], vec![I; 3]).unwrap();
    let cfg = McConfig::new(1_000, 1, Requirement::new(I, I, I).unwrap());
    let e = MonteCarlo::for_model(AzElMount, AzElMount.joint_ranges_rad(), b, cfg).unwrap_err();
    assert!(
        matches!(
            e,
            McError::ModelErrorCount {
                expected: 4,
                found: 3,
                ..
            }
        ),
        "{e}"
    );
}
