//! Joint least squares of coefficients and extra parameters: rank, estimable and invisible
//! combinations, and the one-sided Jacobi SVD they rest on.

use approx::assert_relative_eq;
use calib_lsq::Regression;
use calib_lsq::joint::{Identifiability, JointBlock, JointEstimability, jacobi_svd, joint_step};
use nalgebra::{DMatrix, DVector};

/// Reconstruction of a matrix from its singular values and vectors (relative to its largest
/// entry; dimensionless): one-sided Jacobi is backward stable to a few ulps per sweep.
const SVD_REL: f64 = 1e-13;

/// A bias-only output at four positions: a constant effect is absorbed by the bias
/// (invisible), an alternating one is seen; two parameters with the same alternating effect
/// are estimable only as their sum.
fn bias_example() -> (Regression, DMatrix<f64>) {
    let a = DMatrix::from_element(4, 1, 1.0);
    let reg = Regression::new("y", vec!["bias".into()], a).unwrap();
    let d = DMatrix::from_row_slice(
        4,
        3,
        &[
            1.0, 1.0, 1.0, //
            1.0, -1.0, -1.0, //
            1.0, 1.0, 1.0, //
            1.0, -1.0, -1.0,
        ],
    );
    (reg, d)
}

#[test]
fn jacobi_svd_reconstructs_the_matrix_and_its_singular_values_match() {
    let m = DMatrix::from_fn(7, 4, |i, j| {
        ((i * 5 + j * 3) % 7) as f64 - 2.5 + 0.1 * j as f64
    });
    let (s, v) = jacobi_svd(&m);
    assert!(s.windows(2).all(|w| w[0] >= w[1]));
    assert_relative_eq!(
        (v.transpose() * &v - DMatrix::identity(4, 4)).amax(),
        0.0,
        epsilon = SVD_REL
    );
    // M V has orthogonal columns of norms s
    let mv = &m * &v;
    for (j, sj) in s.iter().enumerate() {
        assert_relative_eq!(mv.column(j).norm(), *sj, max_relative = SVD_REL);
    }
    assert_eq!(calib_lsq::jacobi_singular_values(&m), s);
}

#[test]
fn joint_rank_counts_what_the_coefficients_do_not_absorb() {
    let (reg, d) = bias_example();
    let names: Vec<String> = ["c", "a1", "a2"].iter().map(|s| s.to_string()).collect();
    let est = JointEstimability::new(
        &names,
        &[JointBlock {
            regression: &reg,
            effects: &d,
            weight: 2.0,
        }],
    )
    .unwrap();
    assert_eq!(est.rank(), 2);
    assert_eq!(est.columns(), 4);
    assert_eq!(est.table_rank(), 1);
    assert_eq!(
        est.identifiability(),
        vec![
            Identifiability::Invisible,
            Identifiability::Combined,
            Identifiability::Combined
        ]
    );
    let e = est.estimable_combinations();
    assert_eq!(e.len(), 1);
    assert_eq!(e[0].to_string(), "0.71 a1 + 0.71 a2");
    let n: Vec<String> = est
        .invisible_combinations()
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(n, vec!["1.00 c", "0.71 a1 - 0.71 a2"]);
    // the projector leaves the invisible part: a1 + a2 direction removed
    let p = est.invisible_projector();
    let x = p * DVector::from_vec(vec![0.0, 1.0, 1.0]);
    assert_relative_eq!(x.amax(), 0.0, epsilon = 1e-15);
}

#[test]
fn joint_step_solves_the_stacked_least_squares_and_refuses_a_rank_deficient_one() {
    let (reg, d) = bias_example();
    // estimable coordinate: a1 + a2 (column 1 of D); data from bias 3 and a1 + a2 = 0.5
    let dz = d.columns(1, 1).clone_owned();
    let r = reg.matrix() * DVector::from_vec(vec![3.0]) + &dz * DVector::from_vec(vec![0.5]);
    let (db, z) = joint_step(&[(reg.matrix(), &dz, 1.0)], std::slice::from_ref(&r)).unwrap();
    assert_relative_eq!(db[0][0], 3.0, max_relative = 1e-14);
    assert_relative_eq!(z[0], 0.5, max_relative = 1e-14);
    // the constant effect is the bias's column: not identifiable together
    let dc = d.columns(0, 1).clone_owned();
    assert!(matches!(
        joint_step(&[(reg.matrix(), &dc, 1.0)], &[r]),
        Err(calib_lsq::CalibError::Unidentifiable { .. })
    ));
}

#[test]
fn joint_estimability_names_a_bad_weight_and_a_wrong_shape() {
    let (reg, d) = bias_example();
    let names: Vec<String> = ["c", "a1", "a2"].iter().map(|s| s.to_string()).collect();
    let bad = JointEstimability::new(
        &names,
        &[JointBlock {
            regression: &reg,
            effects: &d,
            weight: f64::NAN,
        }],
    )
    .unwrap_err();
    assert!(bad.to_string().contains("joint.blocks[0].weight"), "{bad}");
    let short = d.columns(0, 2).clone_owned();
    let bad = JointEstimability::new(
        &names,
        &[JointBlock {
            regression: &reg,
            effects: &short,
            weight: 1.0,
        }],
    )
    .unwrap_err();
    assert!(bad.to_string().contains("joint.blocks[0].effects"), "{bad}");
}

/// Fewer rows than unknowns: a typed error, not an out-of-bounds index into the triangular
/// factor.
#[test]
fn joint_step_with_fewer_rows_than_unknowns_is_unidentifiable() {
    let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
    let d = DMatrix::from_row_slice(2, 1, &[1.0, -1.0]);
    let r = DVector::from_vec(vec![1.0, 2.0]);
    assert!(matches!(
        joint_step(&[(&a, &d, 1.0)], &[r]),
        Err(calib_lsq::CalibError::Unidentifiable {
            rank: 2,
            columns: 3,
            ..
        })
    ));
}
