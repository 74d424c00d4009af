//! Errors that act only together (`Turntable::proportional_groups`): the structural detection
//! against the first-order columns sampled over the poses, on the three-axis table, the
//! paper's Table 3 (checked against eq 26) and random descriptions.

mod common;

use common::*;
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, TAU};
use tt_kinematics::paper::{self, ClosedForm};
use tt_kinematics::{FactorSpec, LinearModel, Pose, SignedAxis, Turntable, TurntableDescription};

/// Poses sampled per check of the numeric cross-check.
const SAMPLED_POSES: usize = 64;

/// Two first-order columns are "the same" when they differ by at most this at every sampled
/// pose (unitless: components of unit vectors, a few rotations' rounding of 1e-16 each).
const SAME_COLUMN: f64 = 1e-13;

/// Two columns are "different" when they differ by more than this at some sampled pose
/// (unitless): far above rounding, far below the O(1) differences of distinct rotation axes
/// over a sweep of the joints.
const DIFFERENT_COLUMN: f64 = 1e-6;

/// Deterministic pseudo-random poses in the joint ranges (a fixed LCG: no test randomness).
fn sampled_poses(t: &Turntable) -> Vec<Pose> {
    let ranges = t.joint_ranges_rad();
    let mut state: u64 = 0x2017_0611;
    (0..SAMPLED_POSES)
        .map(|_| {
            Pose::new(
                ranges
                    .iter()
                    .map(|[lo, hi]| {
                        state = state
                            .wrapping_mul(6_364_136_223_846_793_005)
                            .wrapping_add(1_442_695_040_888_963_407);
                        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
                    })
                    .collect(),
            )
            .expect("finite")
        })
        .collect()
}

/// For every pair of errors, the largest difference of their first-order columns over the
/// sampled poses, with the better of the two signs: `(max |c_a - c_b|, max |c_a + c_b|)`.
fn column_gaps(t: &Turntable) -> Vec<Vec<(f64, f64)>> {
    let lin = LinearModel::new(t);
    let n = t.n_rotation_errors();
    let mut gaps = vec![vec![(0.0f64, 0.0f64); n]; n];
    for pose in sampled_poses(t) {
        let c = lin.coefficients(&pose).expect("pose of the table");
        for a in 0..n {
            for b in 0..n {
                let (mut same, mut opposite) = (0.0f64, 0.0f64);
                for k in 0..3 {
                    same = same.max((c[(k, a)] - c[(k, b)]).abs());
                    opposite = opposite.max((c[(k, a)] + c[(k, b)]).abs());
                }
                gaps[a][b].0 = gaps[a][b].0.max(same);
                gaps[a][b].1 = gaps[a][b].1.max(opposite);
            }
        }
    }
    gaps
}

/// The structural groups agree with the sampled columns: members are equal (with their sign)
/// at every sampled pose, and every other pair differs somewhere under both signs.
fn assert_groups_match_columns(t: &Turntable) {
    let gaps = column_gaps(t);
    let groups = t.error_groups();
    let group_of = |e: usize| {
        groups
            .iter()
            .position(|g| g.errors.contains(&e))
            .expect("a partition")
    };
    let sign_of = |e: usize| {
        let g = &groups[group_of(e)];
        g.signs[g.errors.iter().position(|&x| x == e).expect("member")]
    };
    let names = t.rotation_error_names();
    for a in 0..t.n_rotation_errors() {
        for b in a + 1..t.n_rotation_errors() {
            let (same, opposite) = gaps[a][b];
            if group_of(a) == group_of(b) {
                let gap = if sign_of(a) * sign_of(b) > 0.0 {
                    same
                } else {
                    opposite
                };
                assert!(
                    gap <= SAME_COLUMN,
                    "{} and {} are grouped but their columns differ by {gap}",
                    names[a],
                    names[b]
                );
            } else {
                assert!(
                    same > DIFFERENT_COLUMN && opposite > DIFFERENT_COLUMN,
                    "{} and {} are not grouped but their columns agree (gaps {same}, {opposite})",
                    names[a],
                    names[b]
                );
            }
        }
    }
    // a partition of the errors
    let mut all: Vec<usize> = groups.iter().flat_map(|g| g.errors.clone()).collect();
    all.sort_unstable();
    assert_eq!(all, (0..t.n_rotation_errors()).collect::<Vec<_>>());
}

/// The largest component difference of two columns (unitless).
fn max_gap(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn combinations(t: &Turntable) -> Vec<String> {
    let names = t.rotation_error_names();
    t.proportional_groups()
        .iter()
        .map(|g| g.combination(&names))
        .collect()
}

/// The three-axis table: every pair of rotations about one axis with only errors (and
/// translations) between them, and every wobble about the next joint's axis with that
/// joint's errors about it (R_x(a) R_x(phi) = R_x(phi + a)), act as one rotation. The three
/// pairs of issue 19 are among them; the structural result is confirmed against the sampled
/// columns (every other pair differs).
#[test]
fn three_axis_groups_are_the_rotations_about_one_axis_with_no_joint_turning_it_between() {
    let t = three_axis();
    assert_eq!(
        combinations(&t),
        [
            "dphi_o + deps_om_z",
            "dalpha_ox + dphi_m + deps_mi_x",
            "dalpha_oy + deps_om_y",
            "dalpha_my + dphi_i",
            "dalpha_mz + deps_mi_z",
        ]
    );
    let issue_pairs = [
        ("dalpha_oy", "deps_om_y"),
        ("dphi_o", "deps_om_z"),
        ("dphi_m", "deps_mi_x"),
    ];
    let names = t.rotation_error_names();
    for (a, b) in issue_pairs {
        assert!(
            t.proportional_groups().iter().any(|g| {
                let n = g.names(&names);
                n.contains(&a) && n.contains(&b)
            }),
            "{a} and {b} must be one group"
        );
    }
    assert_groups_match_columns(&t);
}

/// §3.2, eq 26: Table 3 has three groups, and eq 26 prints them: Δφ_y1 and Δε_y enter every
/// angle with the same coefficient (cos φ2, 0, sin φ2), Δα_x1 and Δε_x with (−sin φ2, 0,
/// cos φ2), Δφ_z2 and Δα_z1 with (0, 1, 0); Δα_x2 and Δα_y2 act alone.
#[test]
fn eq26_table3_has_three_groups_that_eq26_prints_with_equal_coefficients() {
    let t = paper::table3();
    assert_eq!(
        combinations(&t),
        [
            "dphi_y1 + deps_y",
            "dphi_z2 + dalpha_z1",
            "dalpha_x1 + deps_x"
        ]
    );
    assert_groups_match_columns(&t);
    // eq 26's columns: the closed form at a unit vector of chi
    let column = |phi2: f64, name: &str| {
        let mut chi = [0.0; 8];
        chi[paper::chi_index(name)] = 1.0;
        ClosedForm::eq26(phi2, &chi)
    };
    let names = t.rotation_error_names();
    for g in t.proportional_groups() {
        let members = g.names(&names);
        for k in 0..=16 {
            let phi2 = TAU * f64::from(k) / 16.0;
            let first = column(phi2, members[0]);
            for m in &members[1..] {
                assert!(
                    max_gap(column(phi2, m), first) <= SAME_COLUMN,
                    "eq 26: {m} vs {}",
                    members[0]
                );
            }
        }
    }
    // the errors outside the groups differ from every other in eq 26 at phi2 = 90 deg or 0
    for lone in ["dalpha_x2", "dalpha_y2"] {
        for other in paper::CHI.map(|(n, _)| n) {
            if other != lone {
                assert!(
                    max_gap(column(0.0, lone), column(0.0, other)) > DIFFERENT_COLUMN
                        || max_gap(column(FRAC_PI_2, lone), column(FRAC_PI_2, other))
                            > DIFFERENT_COLUMN
                );
            }
        }
    }
}

/// Negative axes give a negative sign, fixed rotations carry an axis into another, a joint
/// about the error's axis is passed, and a joint range of any positive width keeps errors
/// apart that its rotation moves.
#[test]
fn signs_fixed_rotations_and_narrow_ranges_are_handled_exactly() {
    let j = FactorSpec::joint;
    let e = FactorSpec::error;
    let neg_z = SignedAxis::parse("-z").expect("axis");
    let mut d = TurntableDescription::new(vec![
        e("tilt", SignedAxis::Y),
        j("outer", SignedAxis::Z),
        e("a_z", SignedAxis::Z),
        e("b_negz", neg_z),
        FactorSpec::Fixed {
            angle_rad: FRAC_PI_2,
            about: SignedAxis::X,
        },
        e("c_y", SignedAxis::Y), // R_x(90)^T z = y: one rotation with a_z and b_negz
        j("inner", SignedAxis::X),
        e("d_x", SignedAxis::X),
    ]);
    let t = Turntable::new(&d).expect("valid");
    assert_eq!(combinations(&t), ["a_z - b_negz + c_y"]);
    assert_groups_match_columns(&t);
    // a narrow range of the outer joint still separates the tilt from a_z
    d.joint_ranges_rad = vec![("outer".into(), [0.1, 0.1 + 1e-3])];
    let t = Turntable::new(&d).expect("valid");
    assert_eq!(combinations(&t), ["a_z - b_negz + c_y"]);
}

fn axis() -> impl Strategy<Value = SignedAxis> {
    prop::sample::select(vec!["x", "y", "z", "-x", "-y", "-z"])
        .prop_map(|s| SignedAxis::parse(s).expect("axis"))
}

/// One factor of a random description: 0 joint, 1-3 error, 4 translation, 5 fixed rotation
/// (a quarter turn or an arbitrary angle).
fn factor() -> impl Strategy<Value = (u8, SignedAxis, u8)> {
    (0u8..6, axis(), 0u8..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// On random descriptions (joints, errors, translations, fixed rotations in any order),
    /// the structural groups are exactly the sets of errors whose sampled first-order columns
    /// agree up to sign: nothing proportional is missed, nothing else is grouped.
    #[test]
    fn structural_groups_equal_the_proportional_columns_on_random_tables(
        spec in prop::collection::vec(factor(), 2..12)
    ) {
        let mut factors = vec![FactorSpec::Joint { name: "j0".into(), about: SignedAxis::Z }];
        for (i, (kind, about, angle)) in spec.into_iter().enumerate() {
            factors.push(match kind {
                0 => FactorSpec::Joint { name: format!("j{}", i + 1), about },
                1..=3 => FactorSpec::Error { name: format!("e{i}"), about },
                4 => FactorSpec::Translation { name: format!("t{i}"), along: about },
                _ => FactorSpec::Fixed {
                    angle_rad: if angle == 4 { 0.7 } else { FRAC_PI_2 * f64::from(angle) },
                    about,
                },
            });
        }
        let t = Turntable::new(&TurntableDescription::new(factors)).expect("valid");
        prop_assume!(t.n_rotation_errors() >= 2);
        assert_groups_match_columns(&t);
    }
}
