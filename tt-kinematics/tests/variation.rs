//! Errors that vary with a shaft angle (issue 22): the expansion into coefficients, the dual
//! norms of the bound sets and the exact chain at $\chi(\phi)$, each checked independently.

mod common;

use approx::assert_relative_eq;
use common::*;
use proptest::prelude::*;
use tt_kinematics::variation::{harmonic_dual_norm, sup_norm_upper};
use tt_kinematics::{
    ChainKind, ErrorVariation as V, Expansion, GroupShape, KinematicsError, Pose,
    validate_variations,
};

/// Agreement of two implementations of the same product of rotations, rad.
const INDEPENDENT_TOL: f64 = 1e-12;

/// Relative slack of the nesting const <= harmonics <= any (dimensionless): the harmonic bound
/// comes from an interior-point solve with its multipliers, exact up to a few rounding errors
/// of sums of at most a few thousand terms.
const NESTING_REL_TOL: f64 = 1e-9;

/// How far the certified harmonic dual norm may sit above a known closed-form value
/// (dimensionless): the solver's tolerance 1e-12 times the number of grid angles, with margin.
const DUAL_NORM_REL_TOL: f64 = 1e-6;

fn h(joint: &str, orders: &[u32]) -> V {
    V::Harmonics {
        joint: joint.into(),
        orders: orders.to_vec(),
    }
}

fn any(joint: &str) -> V {
    V::Any {
        joint: joint.into(),
    }
}

/// The three-axis table's 13 errors with the inner axis's wobbles and position error as
/// harmonics of `phi_i`, the middle axis's as `any` of `phi_m`, the rest constant.
fn three_axis_variations(orders: &[u32]) -> Vec<V> {
    // dphi_o, dalpha_ox, dalpha_oy, deps_om_y, deps_om_z, dphi_m, dalpha_my, dalpha_mz,
    // deps_mi_z, deps_mi_x, dphi_i, dalpha_ix, dalpha_iz
    let mut v = vec![V::Constant; 13];
    v[5] = any("phi_m");
    v[6] = any("phi_m");
    v[10] = h("phi_i", orders);
    v[11] = h("phi_i", orders);
    v[12] = h("phi_i", orders);
    v
}

fn grid_poses() -> Vec<Pose> {
    let mut poses = Vec::new();
    for a in [0.0, 90.0, 180.0, 270.0] {
        for b in [0.0, 45.0, 135.0, 225.0] {
            for c in [0.0, 60.0, 150.0, 300.0] {
                poses.push(Pose::from_deg(&[a, b, c]).unwrap());
            }
        }
    }
    poses
}

/// A table whose harmonic errors keep only the constant term is the constant model: one
/// coefficient per error, the same dual norm |s| bit for bit, and the same worst case.
#[test]
fn harmonics_with_only_the_constant_term_reproduce_the_constant_model_exactly() {
    let t = three_axis();
    let poses = grid_poses();
    let constant = Expansion::new(&t, &vec![V::Constant; 13], &poses).unwrap();
    let only_c0 = Expansion::new(
        &t,
        &three_axis_variations(&[])
            .iter()
            .map(|v| match v {
                V::Any { joint } => h(joint, &[]),
                other => other.clone(),
            })
            .collect::<Vec<_>>(),
        &poses,
    )
    .unwrap();
    assert!(constant.is_constant() && only_c0.is_constant());
    let s: Vec<f64> = (0..13).map(|i| (i as f64 - 6.3) * 0.37).collect();
    let ub: Vec<f64> = (0..13).map(|i| 1e-4 * (1.0 + i as f64)).collect();
    assert_eq!(
        constant.dual_norms(&s),
        s.iter().map(|v| v.abs()).collect::<Vec<_>>()
    );
    assert_eq!(only_c0.dual_norms(&s), constant.dual_norms(&s));
    let today: f64 = s.iter().zip(&ub).map(|(a, b)| a.abs() * b).sum();
    assert_eq!(only_c0.worst_case(&s, &ub).to_bits(), today.to_bits());
    // the chain sees chi itself at every position
    let chi: Vec<f64> = ub.iter().map(|u| -0.5 * u).collect();
    let c = only_c0.constant_coefficients(&chi).unwrap();
    let mut at = vec![0.0; 13];
    for p in 0..poses.len() {
        only_c0.chi_at(&c, p, &mut at);
        assert_eq!(at, chi);
    }
}

/// The harmonic dual norm at known values: a point evaluation of a polynomial bounded by one
/// is at most one (attained by the constant 1), the first cosine coefficient of a degree-1
/// polynomial bounded by one is at most one (|c0| + sqrt(a1^2 + b1^2) <= 1), and the bracket
/// [lower, upper] always contains the value.
#[test]
fn harmonic_dual_norm_matches_closed_forms_and_brackets_them() {
    let phi0 = 0.7_f64;
    let point = [
        1.0,
        phi0.cos(),
        phi0.sin(),
        (2.0 * phi0).cos(),
        (2.0 * phi0).sin(),
    ];
    let d = harmonic_dual_norm(&[1, 2], &point, &[phi0]);
    assert!(d.lower <= 1.0 + 1e-12 && d.upper >= 1.0, "{d:?}");
    assert_relative_eq!(d.upper, 1.0, max_relative = DUAL_NORM_REL_TOL);
    let a1 = [0.0, 1.0, 0.0];
    let d = harmonic_dual_norm(&[1], &a1, &[]);
    assert!(d.lower <= 1.0 + 1e-12 && d.upper >= 1.0, "{d:?}");
    assert_relative_eq!(d.upper, 1.0, max_relative = DUAL_NORM_REL_TOL);
    // a difference of two point values, 180 deg apart, of a first harmonic: 2 (cos phi)
    let diff = [0.0, 2.0, 0.0];
    let d = harmonic_dual_norm(&[1], &diff, &[0.0, std::f64::consts::PI]);
    assert_relative_eq!(d.upper, 2.0, max_relative = DUAL_NORM_REL_TOL);
    // with a third harmonic, p(0) - p(pi) = 2 a1 + 2 a3: still 2 (two point evaluations)
    let diff3 = [0.0, 2.0, 0.0, 2.0, 0.0];
    let d = harmonic_dual_norm(&[1, 3], &diff3, &[0.0, std::f64::consts::PI]);
    assert_relative_eq!(d.upper, 2.0, max_relative = DUAL_NORM_REL_TOL);
}

/// The certified sup norm of a trigonometric polynomial is never below its value anywhere
/// (checked on a grid 97 times finer and off the certificate's grid).
#[test]
fn sup_norm_upper_bound_is_never_below_the_polynomial() {
    let orders = [1, 2, 5];
    let c = [0.1, -0.4, 0.3, 0.25, -0.6, 0.05, 0.2];
    let sup = sup_norm_upper(&orders, &c);
    let dense = (0..640 * 97)
        .map(|i| {
            let phi = std::f64::consts::TAU * (i as f64 + 0.5) / (640.0 * 97.0);
            tt_kinematics::variation::harmonic_value(&orders, &c, phi).abs()
        })
        .fold(0.0, f64::max);
    assert!(sup >= dense, "{sup} < {dense}");
    assert!(sup <= dense / (1.0 - std::f64::consts::PI / 128.0) * (1.0 + 1e-12));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// For the same bounds, the worst case of any linear functional of the errors at the
    /// schedule's positions is ordered: constant <= harmonics <= any (the bound sets are
    /// nested). The functional is a random combination of the errors' values at the test
    /// positions, built from the expansion's basis (what every downstream quantity is).
    #[test]
    fn worst_case_under_any_is_at_least_harmonics_which_is_at_least_constant(
        weights in prop::collection::vec(-1.0..1.0_f64, 64 * 13),
        ub in prop::collection::vec(1e-6..1e-3_f64, 13),
        orders in prop::sample::subsequence(vec![1_u32, 2, 3, 4], 1..=3),
    ) {
        let t = three_axis();
        let poses = grid_poses();
        let n = poses.len();
        let mk = |f: &dyn Fn(usize) -> V| {
            Expansion::new(&t, &(0..13).map(f).collect::<Vec<_>>(), &poses).unwrap()
        };
        let joint = |j: usize| ["phi_o", "phi_m", "phi_i"][if j < 5 { 0 } else if j < 10 { 1 } else { 2 }];
        let cst = mk(&|_| V::Constant);
        let har = mk(&|j| h(joint(j), &orders));
        let anyv = mk(&|j| any(joint(j)));
        // s = sum_p sum_j w[p, j] chi_j(phi_p): functional on each expansion's coefficients
        let functional = |e: &Expansion| {
            let mut s = vec![0.0; e.n_coefficients()];
            for g in e.groups() {
                for (ci, b) in g.basis.iter().enumerate() {
                    s[g.first + ci] = (0..n).map(|p| weights[p * 13 + g.error] * b[p]).sum();
                }
            }
            s
        };
        let (wc, wh, wa) = (
            cst.worst_case(&functional(&cst), &ub),
            har.worst_case(&functional(&har), &ub),
            anyv.worst_case(&functional(&anyv), &ub),
        );
        prop_assert!(wc <= wh * (1.0 + NESTING_REL_TOL), "constant {wc} > harmonics {wh}");
        prop_assert!(wh <= wa * (1.0 + NESTING_REL_TOL), "harmonics {wh} > any {wa}");
    }
}

/// The three-axis chain written independently (`common::three_axis_by_axis_angle`) with each
/// error evaluated from its own harmonic formula at the pose's joint angle, against the
/// library's exact chain at the expansion's chi(phi).
#[test]
fn exact_chain_with_angle_dependent_errors_matches_an_independent_evaluation() {
    let t = three_axis();
    let poses = grid_poses();
    let e = Expansion::new(&t, &three_axis_variations(&[1, 2]), &poses).unwrap();
    // coefficients: constants 1e-4 * (j+1) / 3, harmonics (c0, a1, b1, a2, b2) per inner error,
    // any values per middle angle
    let mut c = vec![0.0; e.n_coefficients()];
    let harm = [
        [2e-4, 1e-4, -3e-4, 0.5e-4, 0.2e-4],
        [-1e-4, 0.0, 2e-4, -1e-4, 0.0],
        [0.0, 3e-4, 3e-4, 0.0, -2e-4],
    ];
    let mid_angles = [0.0_f64, 45.0, 135.0, 225.0];
    let mid_values = [[1e-4, -2e-4, 3e-4, -4e-4], [2e-4, 2e-4, -1e-4, 0.0]];
    for g in e.groups() {
        let slot = &mut c[g.first..g.first + g.len()];
        match (&g.shape, g.error) {
            (GroupShape::Constant, j) => slot[0] = 1e-4 * (j as f64 + 1.0) / 3.0,
            (GroupShape::Harmonics { .. }, j) => slot.copy_from_slice(&harm[j - 10]),
            (GroupShape::Any { angles_rad, .. }, j) => {
                for (v, a) in slot.iter_mut().zip(angles_rad) {
                    let k = mid_angles
                        .iter()
                        .position(|m| (m.to_radians() - a).abs() < 1e-12)
                        .unwrap();
                    *v = mid_values[j - 5][k];
                }
            }
        }
    }
    for (p, pose) in poses.iter().enumerate() {
        let a = pose.angles_rad();
        // the errors at this pose, from the formulas
        let mut chi: Vec<f64> = (0..13).map(|j| 1e-4 * (j as f64 + 1.0) / 3.0).collect();
        let k = mid_angles
            .iter()
            .position(|m| (m.to_radians() - a[1]).abs() < 1e-12)
            .unwrap();
        chi[5] = mid_values[0][k];
        chi[6] = mid_values[1][k];
        for (i, hc) in harm.iter().enumerate() {
            chi[10 + i] = hc[0]
                + hc[1] * a[2].cos()
                + hc[2] * a[2].sin()
                + hc[3] * (2.0 * a[2]).cos()
                + hc[4] * (2.0 * a[2]).sin();
        }
        let reference = three_axis_by_axis_angle(a, &chi);
        let errors = e.errors_at(&c, p, &[0.0, 0.0]).unwrap();
        let ours = t.delta_r(pose, &errors, ChainKind::Exact).unwrap();
        assert!((ours - reference).amax() <= INDEPENDENT_TOL, "position {p}");
    }
}

/// Bad error models name the key: an unknown joint, a joint the error does not ride on (the
/// error comes before it in the chain), a zero or repeated order, one too large.
#[test]
fn bad_variations_name_the_key() {
    let t = three_axis();
    let key = |v: Vec<V>| match validate_variations(&t, &v) {
        Err(KinematicsError::Description { key, .. }) => key,
        other => panic!("expected a description error, got {other:?}"),
    };
    let with = |j: usize, v: V| {
        let mut all = vec![V::Constant; 13];
        all[j] = v;
        all
    };
    let f = |j: usize| t.rotation_errors()[j].factor;
    assert_eq!(
        key(with(10, h("phi_x", &[1]))),
        format!("factors[{}].of", f(10))
    );
    // dphi_o (error 0) comes after phi_o only; phi_i is after it
    assert_eq!(key(with(0, any("phi_i"))), format!("factors[{}].of", f(0)));
    assert_eq!(
        key(with(10, h("phi_i", &[1, 0]))),
        format!("factors[{}].harmonics[1]", f(10))
    );
    assert_eq!(
        key(with(10, h("phi_i", &[2, 2]))),
        format!("factors[{}].harmonics[1]", f(10))
    );
    assert_eq!(
        key(with(10, h("phi_i", &[65]))),
        format!("factors[{}].harmonics[0]", f(10))
    );
    assert!(validate_variations(&t, &with(10, h("phi_i", &[1, 64]))).is_ok());
}

/// The functional of the calibration of a schedule at the `angles` (rad) with weights `w`:
/// $s = \mathbf B_D^T w$ over the coefficients of `orders`.
fn schedule_functional(orders: &[u32], angles: &[f64], w: &[f64]) -> Vec<f64> {
    let mut s = vec![0.0; 1 + 2 * orders.len()];
    for (&phi, &wa) in angles.iter().zip(w) {
        s[0] += wa;
        for (i, &k) in orders.iter().enumerate() {
            let (sn, c) = (f64::from(k) * phi).sin_cos();
            s[1 + 2 * i] += wa * c;
            s[2 + 2 * i] += wa * sn;
        }
    }
    s
}

/// The dual-norm work is bounded by a count whatever the orders (issue 32: a study with
/// `harmonics = [1, ..., 64]` ran past 120 s in `check-turntable`, `end-to-end` and
/// `allocate`, one program of 8,200 rows and 129 coefficients per row of the calibration):
/// the shipped first and second harmonics stay on the program (their answers unchanged);
/// orders 1 to 64 are bounded through the schedule's eight angles, where they alias, by the
/// `any` dual norm, which is rigorous (above the program's value where both are computed).
#[test]
fn the_harmonic_dual_norm_work_is_bounded_by_a_count_for_every_order() {
    use tt_kinematics::variation::{MAX_PROGRAM_WORK, harmonic_program_work, schedule_dual_bound};
    let angles: Vec<f64> = (0..8).map(|a| f64::from(a) * 45f64.to_radians()).collect();
    // the schedule repeats its angles (four positions each): counted once
    let schedule: Vec<f64> = angles.iter().cycle().take(32).copied().collect();
    let shipped = harmonic_program_work(&[1, 2], &schedule);
    assert_eq!(shipped, (256 + 8) * 25);
    assert!(shipped <= MAX_PROGRAM_WORK);
    let all: Vec<u32> = (1..=tt_kinematics::variation::MAX_HARMONIC_ORDER).collect();
    assert_eq!(
        harmonic_program_work(&all, &schedule),
        (8192 + 8) * 129 * 129
    );
    assert!(harmonic_program_work(&all, &schedule) > MAX_PROGRAM_WORK);
    let w = [0.3, -1.2, 0.7, 0.05, -0.4, 2.0, -0.9, 0.6];
    let any: f64 = w.iter().map(|v: &f64| v.abs()).sum();
    // orders 1..64: not the program; the bound is the schedule's, the `any` norm
    let s = schedule_functional(&all, &angles, &w);
    let d = harmonic_dual_norm(&all, &s, &schedule);
    // the same bits: the schedule's bound, not the program
    assert_eq!(
        d.upper.to_bits(),
        schedule_dual_bound(&all, &s, &schedule).to_bits()
    );
    assert_relative_eq!(d.upper, any, max_relative = NESTING_REL_TOL);
    assert!(d.lower <= d.upper && d.lower >= s[0].abs());
    // rigorous: above the program's certified value where the program is solved
    for orders in [&[1u32, 2][..], &[1, 2, 3, 4], &[2, 5]] {
        assert!(harmonic_program_work(orders, &schedule) <= MAX_PROGRAM_WORK);
        let s = schedule_functional(orders, &angles, &w);
        let program = harmonic_dual_norm(orders, &s, &schedule);
        let bound = schedule_dual_bound(orders, &s, &schedule);
        assert!(
            bound >= program.lower * (1.0 - NESTING_REL_TOL),
            "{orders:?}: {bound} below the reached {}",
            program.lower
        );
    }
}
