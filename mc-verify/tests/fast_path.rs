//! The fast path (the compiled plan on lanes of samples) equals the plain dense-matrix chain
//! (eq 17-24 for the paper's table) to rounding, per sample, for any turntable and in every
//! evaluation tier.

mod common;

use approx::assert_abs_diff_eq;
use common::{TABLE4_ARCMIN, config, paper_table, table4, three_axis};
use mc_verify::fast::{sin_cos_reduced, sin_cos_turn};
use mc_verify::{BLOCK_CAPACITY, ErrorBox, FastChain, MonteCarlo, SampleBlock, Tier, chunk_rng};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use tt_core::units::arcmin_to_rad;
use tt_kinematics::{
    ExactChain, FactorSpec, OrientationErrorModel, Pose, SignedAxis, Turntable,
    TurntableDescription, TurntableErrors,
};

/// Fast path against the plain chain, rad: the per-sample bound. The plain chain's
/// own rounding (a dozen 3x3 products of entries near 0 and 1) is a few 1e-16.
const FAST_VS_PLAIN_ABS_RAD: f64 = 1e-15;

/// Same, for large errors (up to 0.5 rad, the `f64::sin_cos` fall-back), rad: the matrix
/// entries are no longer near 0 and 1, so the plain chain's rounding grows to ~1e-15.
const FAST_VS_PLAIN_LARGE_ABS_RAD: f64 = 4e-15;

/// `sin_cos_turn` against `f64::sin_cos` of the rounded angle (unitless): the angle itself is
/// rounded to 1/2 ulp of 2 pi (4.4e-16) plus ~2 ulp of evaluation.
const SIN_COS_TURN_ABS: f64 = 1e-15;

/// `sin_cos_reduced` against `f64::sin_cos` for |a| <= 4 pi (unitless): the remainder
/// a - j (2 pi / 256) is rounded once (up to ulp(4 pi) / 2 = 8.9e-16), the table wraps with
/// 2 pi rounded (2.4e-16 per turn, up to two turns) and the evaluation adds ~2 ulp.
const SIN_COS_REDUCED_ABS: f64 = 2e-15;

fn negative(axis: SignedAxis) -> SignedAxis {
    SignedAxis {
        negative: true,
        ..axis
    }
}

fn j(name: &str, about: SignedAxis) -> FactorSpec {
    FactorSpec::joint(name, about)
}

fn e(name: &str, about: SignedAxis) -> FactorSpec {
    FactorSpec::error(name, about)
}

fn fixed(angle_rad: f64, about: SignedAxis) -> FactorSpec {
    FactorSpec::fixed(angle_rad, about)
}

/// A table built to exercise every operation of the compiled plan: a cancelling joint with a
/// range, negative error and joint axes, two consecutive errors about the same axis (no
/// fused start), fixed rotations inside and after the chain, a ranged joint beyond 4 pi
/// (`f64::sin_cos`), a ranged joint near zero (table reduction), a trailing fixed rotation.
fn exotic_table() -> Turntable {
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    let mut d = TurntableDescription::new(vec![
        fixed(0.3, x),
        j("a", negative(z)),
        e("e1", negative(x)),
        e("e2", x),
        fixed(0.7, y),
        j("b", y),
        e("e3", z),
        j("c", negative(x)),
        e("e4", y),
        e("e5", negative(z)),
        e("e6", x),
        fixed(-1.1, z),
    ]);
    d.joint_ranges_rad = vec![
        ("a".into(), [-FRAC_PI_2, FRAC_PI_2]),
        ("b".into(), [20.0, 21.0]),
        ("c".into(), [-1.0, 2.0]),
    ];
    Turntable::new(&d).unwrap()
}

/// A table whose fused start has negative axes, with a full-turn joint about a negative axis
/// and a same-axis pair after it.
fn negative_start_table() -> Turntable {
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    Turntable::new(&TurntableDescription::new(vec![
        e("t1", negative(y)),
        e("t2", z),
        j("p", negative(z)),
        e("t3", negative(x)),
        e("t4", negative(x)),
        e("t5", y),
    ]))
    .unwrap()
}

fn tables() -> Vec<(&'static str, Turntable)> {
    vec![
        ("paper", paper_table()),
        ("three-axis", three_axis()),
        ("exotic", exotic_table()),
        ("negative start", negative_start_table()),
    ]
}

/// `Pose` strategy over the joint ranges of `t`.
fn pose_in(t: &Turntable) -> impl Strategy<Value = Pose> + use<> {
    t.joint_ranges_rad()
        .into_iter()
        .map(|[lo, hi]| lo..hi)
        .collect::<Vec<_>>()
        .prop_map(|a| Pose::new(a).unwrap())
}

fn errors_of(t: &Turntable, max_rad: f64) -> impl Strategy<Value = TurntableErrors> + use<> {
    let n_tr = t.n_translation_errors();
    prop::collection::vec(-max_rad..=max_rad, t.n_rotation_errors())
        .prop_map(move |chi| TurntableErrors::new(chi, vec![0.0; n_tr]).unwrap())
}

fn assert_close(
    fast: [f64; 3],
    plain: [f64; 3],
    tol: f64,
    what: &str,
) -> Result<(), TestCaseError> {
    for k in 0..3 {
        prop_assert!(
            (fast[k] - plain[k]).abs() <= tol,
            "{what} axis {k}: fast {} plain {}",
            fast[k],
            plain[k]
        );
    }
    Ok(())
}

proptest! {
    /// Issue 5: "It must equal the exact chain to 1e-15 rad per sample", for errors up to
    /// 10 arcmin (beyond Table 4's 0.78) and any pose, on every table.
    #[test]
    fn fast_chain_equals_plain_exact_chain_within_1e_15_rad_up_to_10_arcmin(
        (k, pose, errors) in (0..4usize).prop_flat_map(|k| {
            let t = tables()[k].1.clone();
            (Just(k), pose_in(&t), errors_of(&t, arcmin_to_rad(10.0)))
        }),
    ) {
        let (name, t) = &tables()[k];
        let plain = ExactChain::new(t).orientation_error(&pose, &errors).unwrap().to_array();
        let fast = FastChain::new(t).orientation_error(&pose, &errors).unwrap().to_array();
        assert_close(fast, plain, FAST_VS_PLAIN_ABS_RAD, name)?;
    }

    /// Large errors take the `f64::sin_cos` branch and still agree.
    #[test]
    fn fast_chain_equals_plain_exact_chain_for_large_errors(
        (k, pose, errors) in (0..4usize).prop_flat_map(|k| {
            let t = tables()[k].1.clone();
            (Just(k), pose_in(&t), errors_of(&t, 0.5))
        }),
    ) {
        let (name, t) = &tables()[k];
        let plain = ExactChain::new(t).orientation_error(&pose, &errors).unwrap().to_array();
        let fast = FastChain::new(t).orientation_error(&pose, &errors).unwrap().to_array();
        assert_close(fast, plain, FAST_VS_PLAIN_LARGE_ABS_RAD, name)?;
    }

    /// The table-based sine and cosine of the full-turn grid agree with `f64::sin_cos`.
    #[test]
    fn sin_cos_turn_matches_std_sin_cos(w in any::<u32>()) {
        let phi = f64::from(w) * (TAU / 4_294_967_296.0);
        let (s, c) = sin_cos_turn(w);
        let (s_ref, c_ref) = phi.sin_cos();
        prop_assert!((s - s_ref).abs() <= SIN_COS_TURN_ABS, "w {w}: sin {s} vs {s_ref}");
        prop_assert!((c - c_ref).abs() <= SIN_COS_TURN_ABS, "w {w}: cos {c} vs {c_ref}");
    }

    /// The table reduction of ranged joint angles agrees with `f64::sin_cos` for |a| <= 4 pi.
    #[test]
    fn sin_cos_reduced_matches_std_sin_cos(a in -2.0 * TAU..=2.0 * TAU) {
        let (s, c) = sin_cos_reduced(a);
        let (s_ref, c_ref) = a.sin_cos();
        prop_assert!((s - s_ref).abs() <= SIN_COS_REDUCED_ABS, "a {a}: sin {s} vs {s_ref}");
        prop_assert!((c - c_ref).abs() <= SIN_COS_REDUCED_ABS, "a {a}: cos {c} vs {c_ref}");
    }
}

#[test]
fn sin_cos_turn_is_exact_at_quarter_turns_and_table_boundaries() {
    for (w, phi) in [
        (0u32, 0.0),
        (1 << 30, FRAC_PI_2),
        (1 << 31, PI),
        (3 << 30, 3.0 * FRAC_PI_2),
        (u32::MAX, TAU * (1.0 - 1.0 / 4_294_967_296.0)),
        (
            (1 << 23) - 1,
            TAU * f64::from((1u32 << 23) - 1) / 4_294_967_296.0,
        ),
        (1 << 23, PI / 256.0),
    ] {
        let (s, c) = sin_cos_turn(w);
        assert_abs_diff_eq!(s, phi.sin(), epsilon = SIN_COS_TURN_ABS);
        assert_abs_diff_eq!(c, phi.cos(), epsilon = SIN_COS_TURN_ABS);
    }
}

/// One box per tier for table `t`: zero lower bounds within the short range (tangent tier),
/// non-zero lower bounds there, up to 10 arcmin (medium series) and up to 1 degree
/// (`f64::sin_cos`).
fn tier_boxes(t: &Turntable) -> Vec<(Tier, ErrorBox)> {
    let n = t.n_rotation_errors();
    let ub: Vec<f64> = (0..n).map(|i| TABLE4_ARCMIN[i % 8]).collect();
    let lb = [0.1, 0.2, 0.0, 0.3, 0.05, 0.1, 0.2, 0.1];
    let lb: Vec<f64> = (0..n).map(|i| lb[i % 8]).collect();
    vec![
        (
            Tier::Tangent,
            ErrorBox::from_arcmin(t, vec![0.0; n], ub.clone()).unwrap(),
        ),
        (Tier::Short, ErrorBox::from_arcmin(t, lb, ub).unwrap()),
        (
            Tier::Medium,
            ErrorBox::from_arcmin(t, vec![2.0; n], vec![10.0; n]).unwrap(),
        ),
        (
            Tier::Any,
            ErrorBox::from_upper_rad(t, vec![1.0_f64.to_radians(); n]).unwrap(),
        ),
    ]
}

/// Every sample of a run, as `run` evaluates it (`chunk_values_rad`), against the plain chain
/// on the same draws (`chunk_rng`, `fill_block`), within `tol` rad; then the whole run against
/// `run_model(ExactChain)`: same extremes (to `tol`), worst samples, histograms and yields.
fn fast_run_matches_plain_run(t: &Turntable, b: ErrorBox, samples: u64, tol: f64) {
    let mut cfg = config(samples, 11);
    cfg.chunk_size = 3_000;
    let mc = MonteCarlo::new(t, b, cfg).unwrap();
    let chain = ExactChain::new(t);
    let n_tr = t.n_translation_errors();
    let mut block = SampleBlock::new(mc.sampler());
    for chunk in 0..mc.chunks() {
        let values = mc.chunk_values_rad(chunk);
        let mut rng = chunk_rng(cfg.seed, chunk);
        for (start, part) in values.chunks(BLOCK_CAPACITY).enumerate() {
            mc.sampler().fill_block(&mut rng, part.len(), &mut block);
            for (k, fast) in part.iter().enumerate() {
                let errors = TurntableErrors::new(block.chi_rad(k), vec![0.0; n_tr]).unwrap();
                let plain = chain.orientation_error(&block.pose(k), &errors).unwrap();
                for (axis, (f, p)) in fast.iter().zip(plain.to_array()).enumerate() {
                    assert!(
                        (f - p).abs() <= tol,
                        "chunk {chunk} sample {}: axis {axis}: fast {f} plain {p}",
                        start * BLOCK_CAPACITY + k
                    );
                }
            }
        }
    }
    let fast = mc.run();
    let plain = mc.run_model(&chain).unwrap();
    assert_eq!(fast.count().samples(), plain.count().samples());
    for (f, p) in fast.axes().iter().zip(plain.axes()) {
        assert_abs_diff_eq!(f.max_abs_rad(), p.max_abs_rad(), epsilon = tol);
        assert_eq!(f.worst().index(), p.worst().index(), "{:?}", f.axis());
        assert_eq!(f.worst().chi_rad(), p.worst().chi_rad());
        assert_eq!(f.worst().pose(), p.worst().pose());
        assert_abs_diff_eq!(f.mean_rad(), p.mean_rad(), epsilon = tol);
        assert_eq!(f.histogram().counts(), p.histogram().counts());
    }
    assert_eq!(fast.count(), plain.count());
}

fn tier_case(table: usize, tier: Tier, samples: u64) {
    let (name, t) = &tables()[table];
    let (box_tier, b) = tier_boxes(t).into_iter().find(|c| c.0 == tier).unwrap();
    assert_eq!(Tier::for_box(&b), box_tier, "{name}");
    fast_run_matches_plain_run(t, b, samples, FAST_VS_PLAIN_ABS_RAD);
}

#[test]
fn fast_run_matches_plain_chain_run_with_table4_box_short_series() {
    fast_run_matches_plain_run(&paper_table(), table4(), 20_000, FAST_VS_PLAIN_ABS_RAD);
}

#[test]
fn fast_run_matches_plain_chain_run_with_nonzero_lower_bounds_short_series() {
    tier_case(0, Tier::Short, 20_000);
}

#[test]
fn fast_run_matches_plain_chain_run_with_10_arcmin_box_medium_series() {
    tier_case(0, Tier::Medium, 20_000);
}

#[test]
fn fast_run_matches_plain_chain_run_with_1_deg_box_libm_branch() {
    tier_case(0, Tier::Any, 5_000);
}

#[test]
fn fast_run_matches_plain_chain_run_on_the_three_axis_table_in_every_tier() {
    for tier in [Tier::Tangent, Tier::Short, Tier::Medium, Tier::Any] {
        tier_case(1, tier, 10_000);
    }
}

/// Negative axes, fixed rotations, ranged joints (table reduction and `f64::sin_cos`), a
/// cancelling joint, same-axis pairs: every operation of the plan, in every tier.
#[test]
fn fast_run_matches_plain_chain_run_on_tables_with_every_kind_of_step() {
    for table in [2, 3] {
        for tier in [Tier::Tangent, Tier::Short, Tier::Medium, Tier::Any] {
            tier_case(table, tier, 5_000);
        }
    }
}

/// The reported worst sample is a real sample: evaluating its chi and pose with the plain
/// chain gives back the reported value, which is the reported maximum.
#[test]
fn worst_sample_reproduces_its_maximum_through_the_plain_chain() {
    for (t, b) in [
        (paper_table(), table4()),
        (three_axis(), common::three_axis_box()),
    ] {
        let r = MonteCarlo::new(&t, b, config(50_000, 5)).unwrap().run();
        for a in r.axes() {
            let errors = TurntableErrors::new(
                a.worst().chi_rad().to_vec(),
                vec![0.0; t.n_translation_errors()],
            )
            .unwrap();
            let v = ExactChain::new(&t)
                .orientation_error(a.worst().pose(), &errors)
                .unwrap()
                .get(a.axis());
            assert_abs_diff_eq!(v, a.worst().value(), epsilon = FAST_VS_PLAIN_ABS_RAD);
            assert_eq!(a.worst().value().abs().to_bits(), a.max_abs_rad().to_bits());
            assert!(a.worst().index() < 50_000);
            assert_eq!(a.worst().pose().len(), t.n_joints());
        }
    }
}
