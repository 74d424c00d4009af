//! Which table errors the calibration estimates itself (issue 22 item 4): a joint least
//! squares of the sensor coefficients and the table errors from the same data, under the
//! user's reading. On the paper's study and the three-axis example the estimable combinations
//! are recovered by the joint estimator on the exact chain with a noiseless sensor, the
//! invisible ones are absorbed by the sensor's columns, and the allocation of the rest is what
//! their first-order effect asks.

mod common;

use approx::assert_relative_eq;
use calib_lsq::Reading;
use calib_lsq::joint::Identifiability;
use calib_lsq::joint::JointEstimability;
use common::*;
use e2e_verify::EndToEnd;
use e2e_verify::estimable::JointEstimate;
use nalgebra::{DMatrix, DVector};
use rand_chacha::rand_core::SeedableRng;

const STUDIES: [&str; 2] = ["gyrowheel-2017", "three-axis-example"];

/// Relative error of the recovered table errors when the truth lies in the estimable subspace
/// (dimensionless): Gauss-Newton on the exact model converges to rounding (about 1e-12 of
/// 1e-4 rad with central differences at 1e-7 rad).
const RECOVERED_REL: f64 = 1e-8;

/// The last Gauss-Newton step relative to the error's size (dimensionless): the steps fall
/// quadratically (1e-4, 1e-8, 1e-15 rad) to the rounding of outputs of order 1e4 deg/h.
const CONVERGED_STEP_REL: f64 = 1e-10;

/// Gauss-Newton steps allowed (it converges quadratically from 1e-4 rad in about four).
const ITERATIONS: usize = 12;

fn users(name: &str) -> EndToEnd {
    study_e2e(name, Some(Reading::USER))
}

fn project(b: &DMatrix<f64>, chi: &[f64]) -> DVector<f64> {
    b.transpose() * DVector::from_column_slice(chi)
}

/// The joint estimate from the noiseless outputs of the exact chain at the table error `chi`
/// (stopping at a step of `tol_rad`).
fn joint_from_exact_chain(
    e2e: &EndToEnd,
    est: &JointEstimability,
    chi: &[f64],
    tol_rad: f64,
) -> JointEstimate {
    let b1 = e2e
        .estimable()
        .outputs_at(chi, &e2e.estimable().true_coefficients())
        .unwrap();
    e2e.estimable()
        .joint_estimate(&b1, est, ITERATIONS, tol_rad)
        .unwrap()
}

/// A table error with a component along every error (seeded), scaled to 2-norm `s` rad.
fn generic_chi(e2e: &EndToEnd, s: f64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(22);
    let v = random_chi(&mut rng, &vec![1.0; e2e.n_errors()]);
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.iter().map(|x| s * x / n).collect()
}

/// The joint estimator recovers a simulated table error in the estimable subspace on the exact
/// chain with a noiseless sensor: the Gauss-Newton iterates converge (the last step is
/// rounding) to the true value.
#[test]
fn joint_estimator_recovers_estimable_table_errors_on_the_exact_chain() {
    for name in STUDIES {
        let e2e = users(name);
        let est = e2e.estimable().estimability().unwrap();
        let e = est.estimable_basis();
        assert!(est.table_rank() > 0, "{name}");
        let z = DVector::from_fn(e.ncols(), |i, _| 1e-4 * (1.0 - 0.3 * i as f64));
        let chi: Vec<f64> = (e * &z).iter().copied().collect();
        let j = joint_from_exact_chain(&e2e, &est, &chi, 1e-15);
        let err: f64 = j
            .chi_rad()
            .iter()
            .zip(&chi)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let size = z.norm();
        assert!(
            err <= RECOVERED_REL * size,
            "{name}: error {err:e} of {size:e}"
        );
        assert!(
            *j.steps_rad().last().unwrap() <= CONVERGED_STEP_REL * size,
            "{name}: the iterates did not converge: {:?}",
            j.steps_rad()
        );
        // the coefficients too
        for (bh, b) in j
            .coefficients()
            .iter()
            .zip(e2e.estimable().true_coefficients())
        {
            assert!(
                (bh - &b).amax() <= RECOVERED_REL * b.amax().max(1.0),
                "{name}"
            );
        }
    }
}

/// With any table error (components in the invisible subspace too) the estimate of the
/// estimable part converges to the true value as the error shrinks: its error is second order,
/// relative error at most `SECOND_ORDER` times the size in rad.
#[test]
fn estimate_of_the_estimable_part_converges_as_the_table_error_shrinks() {
    /// Relative error per rad of table error (1/rad): a second-order remainder of rotations
    /// by a few errors, with the weak directions' amplification (smallest singular value of
    /// the table part about 0.04 of the reference on the paper's study).
    const SECOND_ORDER: f64 = 100.0;
    for name in STUDIES {
        let e2e = users(name);
        let est = e2e.estimable().estimability().unwrap();
        let e = est.estimable_basis();
        let mut errs = Vec::new();
        for s in [1e-3, 1e-4, 1e-5] {
            let chi = generic_chi(&e2e, s);
            let j = joint_from_exact_chain(&e2e, &est, &chi, 1e-17);
            let err = (project(e, j.chi_rad()) - project(e, &chi)).norm() / s;
            assert!(
                err <= SECOND_ORDER * s,
                "{name}: s {s:e} relative error {err:e}"
            );
            errs.push(err);
        }
        // and it shrinks in proportion (second order): a tenth per decade, within 1%
        for w in errs.windows(2) {
            assert_relative_eq!(w[1], 0.1 * w[0], max_relative = 0.01);
        }
    }
}

/// The invisible combinations are invisible on the exact chain: the change of the outputs a
/// table error along one of them causes is taken up by the sensor's columns (its residual
/// after the ordinary least squares is second order), while every estimable direction leaves
/// a first-order residual of at least its singular value.
#[test]
fn invisible_combinations_lie_in_the_sensors_columns_on_the_exact_chain() {
    /// Residual per unit of first-order effect (dimensionless) at 1e-5 rad: second order,
    /// about 1e-5 of the effect.
    const ABSORBED_REL: f64 = 1e-3;
    let s = 1e-5;
    for name in STUDIES {
        let e2e = users(name);
        let est = e2e.estimable().estimability().unwrap();
        let acc = e2e.accuracies();
        let beta = e2e.estimable().true_coefficients();
        let zero = e2e
            .estimable()
            .outputs_at(&vec![0.0; e2e.n_errors()], &beta)
            .unwrap();
        let residual = |v: &[f64]| -> f64 {
            let chi: Vec<f64> = v.iter().map(|x| s * x).collect();
            let b1 = e2e.estimable().outputs_at(&chi, &beta).unwrap();
            e2e.calibration()
                .outputs()
                .iter()
                .enumerate()
                .map(|(k, oc)| {
                    let db = &b1[k] - &zero[k];
                    let a = oc.regression().matrix();
                    let r = &db - a * (oc.regression().pinv() * &db);
                    (r / acc[k]).norm_squared()
                })
                .sum::<f64>()
                .sqrt()
                / (s * est.reference())
        };
        let n = est.invisible_basis();
        assert_eq!(n.ncols() + est.table_rank(), e2e.n_errors(), "{name}");
        for c in 0..n.ncols() {
            let v: Vec<f64> = n.column(c).iter().copied().collect();
            let r = residual(&v);
            assert!(r <= ABSORBED_REL, "{name}: invisible {c} leaves {r:e}");
        }
        let e = est.estimable_basis();
        for c in 0..e.ncols() {
            let v: Vec<f64> = e.column(c).iter().copied().collect();
            let r = residual(&v);
            let sigma = est.singular_values()[c] / est.reference();
            assert!(r >= 0.5 * sigma, "{name}: estimable {c} leaves only {r:e}");
        }
    }
}

/// Every error of the paper's study and of the three-axis example is estimable in
/// combination: the invisible combinations are exactly the differences within the groups of
/// errors that act only together (eq 26's equal coefficients), so the rank is the number of
/// coefficients plus the number of groups, and the joint estimator leaves no first-order
/// effect: the direct allocation needs no bound.
#[test]
fn only_errors_acting_together_are_invisible_and_the_joint_allocation_needs_no_bound() {
    for (name, groups) in [("gyrowheel-2017", 5), ("three-axis-example", 7)] {
        let e2e = users(name);
        let est = e2e.estimable().estimability().unwrap();
        assert_eq!(est.table_rank(), groups, "{name}");
        assert_eq!(est.rank(), est.coefficients() + groups, "{name}");
        let combined = est.identifiability();
        assert!(!combined.contains(&Identifiability::Invisible), "{name}");
        for c in est.invisible_combinations() {
            assert_eq!(c.terms.len(), 2, "{name}: {c}");
            assert!((c.terms[0].1 + c.terms[1].1).abs() < 1e-9, "{name}: {c}");
        }
        let lb = vec![0.0; e2e.n_errors()];
        let plain = e2e.allocate_direct(&e2e.linearization(), &lb).unwrap();
        assert!(!plain.no_bound_needed(), "{name}");
        let joint = e2e
            .allocate_direct(&e2e.estimable().linearization_joint(&est).unwrap(), &lb)
            .unwrap();
        assert!(joint.no_bound_needed(), "{name}");
    }
}

/// On the exact chain the joint estimator's rate error at the paper's Table 4 worst turntable
/// (user's reading) is second order: far below the ordinary calibration's 0.0159 deg/h.
#[test]
fn joint_estimator_removes_table4s_first_order_error_on_the_exact_chain() {
    let e2e = users("gyrowheel-2017");
    let est = e2e.estimable().estimability().unwrap();
    let ub = alloc_opt::paper::table4_rad();
    let wc = e2e.worst_case(&e2e.linearization(), &ub).unwrap();
    for o in wc.outputs() {
        let plain = e2e.delta_omega(o.worst_chi_rad()).unwrap();
        let joint = e2e
            .estimable()
            .joint_delta_omega(o.worst_chi_rad(), &est, ITERATIONS)
            .unwrap();
        assert!(joint[o.output()] < 0.01 * plain[o.output()]);
    }
}

/// Agreement of two computations of the same first-order matrix by different paths
/// (dimensionless, relative to the matrix's largest entry).
const SAME_MATRIX_REL: f64 = 1e-12;

/// Issue 32 item 1: the joint estimation under a study's angle-dependent model. With every
/// error constant the expanded path is the constant one (same rank, same joint model); with
/// the harmonic-errors study's model the joint estimator recovers coefficients in the
/// estimable subspace on the exact chain with a noiseless sensor.
#[test]
fn joint_estimation_of_harmonic_coefficients_recovers_them_and_reduces_to_the_constant_case() {
    let name = "gyrowheel-2017-harmonic-errors";
    let s = study(name);
    let e2e = users(name);
    let constant = tt_kinematics::Expansion::new(
        e2e.turntable(),
        &vec![tt_kinematics::ErrorVariation::Constant; e2e.n_errors()],
        e2e.poses(),
    )
    .unwrap();
    let est = e2e.estimable().estimability().unwrap();
    let est_c = e2e.estimable().estimability_expanded(&constant).unwrap();
    assert_eq!(est_c.rank(), est.rank());
    assert_eq!(est_c.table_rank(), est.table_rank());
    let joint = e2e.estimable().linearization_joint(&est).unwrap();
    let joint_c = e2e
        .estimable()
        .linearization_joint_expanded(&constant, &est_c)
        .unwrap();
    let scale = joint
        .matrix()
        .amax()
        .max(e2e.linearization().matrix().amax());
    assert!(
        (joint_c.reduced.matrix() - joint.matrix().abs()).amax() <= SAME_MATRIX_REL * scale,
        "the constant expansion's joint model differs from the constant one"
    );
    let ex = tt_kinematics::Expansion::new(e2e.turntable(), &s.variations, e2e.poses()).unwrap();
    let est_h = e2e.estimable().estimability_expanded(&ex).unwrap();
    assert_eq!(est_h.names().len(), ex.n_coefficients());
    assert!(est_h.table_rank() > est.table_rank());
    let e = est_h.estimable_basis();
    let z = DVector::from_fn(e.ncols(), |i, _| 1e-5 * (1.0 - 0.03 * i as f64));
    let c: Vec<f64> = (e * &z).iter().copied().collect();
    let b1 = e2e
        .estimable()
        .outputs_at_expanded(&ex, &c, &e2e.estimable().true_coefficients())
        .unwrap();
    let j = e2e
        .estimable()
        .joint_estimate_expanded(&ex, &b1, &est_h, ITERATIONS, 1e-15)
        .unwrap();
    let err = j
        .chi_rad()
        .iter()
        .zip(&c)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        err <= RECOVERED_REL * z.norm(),
        "error {err:e} of {:e}",
        z.norm()
    );
    // at that turntable the joint calibration leaves rounding, the ordinary one does not
    let dw = e2e
        .estimable()
        .joint_delta_omega_expanded(&ex, &c, &est_h, ITERATIONS)
        .unwrap();
    for (k, d) in dw.iter().enumerate() {
        assert!(*d <= 1e-6 * e2e.accuracies()[k], "output {k}: {d:e}");
    }
}
