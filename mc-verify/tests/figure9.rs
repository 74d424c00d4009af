//! Paper §4.3, Figure 9: with the allocation of Table 4, random turntables meet the
//! requirement of eq 16, and the Monte Carlo maximum approaches, but never exceeds, the
//! certified worst case (the first-order worst case over the poses, Lemma 1's quantity,
//! plus the remainder bound).

mod common;

use common::{EQ16_REQUIREMENT_DEG, config, paper_table, table4, three_axis, three_axis_box};
use mc_verify::{McConfig, MonteCarlo};
use tt_kinematics::{LinearModel, OrientationAxis, Turntable};

/// Table 4's largest first-order worst case relative to eq 16 (unitless): the paper's
/// allocation uses 96.3 % of the requirement (Delta-theta = dphi_z2 + dalpha_z1, both
/// 0.78 arcmin: 1.56 arcmin = 0.0260 deg of 0.027), so "every sample inside 0.027 deg"
/// alone could not fail; the test compares the maximum with the certificate instead.
const TABLE4_WORST_OVER_REQUIREMENT: f64 = 0.963;

/// Rounding of the printed 96.3 % (unitless).
const PRINTED_PERCENT_ABS: f64 = 5e-4;

/// How close (relative, unitless) the maximum of 10^6 samples must come to the linear worst
/// case of Delta-theta: it depends on two errors only (eq 27), uniform on [-UB, UB] each,
/// so P(|theta| > (1 - e) worst) = e^2 per sample (both signs); at e = 1 % that is 1e-4,
/// 100 expected samples beyond in 10^6: a miss has probability e^-100.
const THETA_CLOSE_REL: f64 = 0.01;

/// The same for Delta-psi and Delta-gamma (unitless): each depends on five errors with
/// pose-dependent coefficients, so the maximum sits in a five-dimensional corner. Near the
/// four worst poses the chance per sample of coming within eta arcmin of the worst case is
/// about 0.14 eta^5.5 (corner volume eta^5 / (5! 2^5 prod A_i) with A_i ~ 0.3 arcmin,
/// integrated over the quadratic fall-off 0.6 delta^2 arcmin of the pose), so 10^6 samples
/// fall short by about 8 % (observed: 8.0 % and 6.4 %), and at 15 % short (eta = 0.22
/// arcmin) about 35 samples are expected beyond: a miss has probability about e^-35.
const PSI_GAMMA_CLOSE_REL: f64 = 0.15;

/// The certified worst cases of the first-order model (value, rigorous upper bound) per
/// axis, rad.
fn linear_worst_cases(t: &Turntable, ub: &[f64]) -> [(f64, f64); 3] {
    let model = LinearModel::new(t);
    OrientationAxis::ALL.map(|axis| {
        let w = model.worst_pose_certified(axis, ub, true, None).unwrap();
        (w.value(), w.upper_bound())
    })
}

/// §4.3 / Figure 9 with 10^6 turntables (the paper drew 10^4): every sample meets eq 16; the
/// maximum of every angle stays below the rigorous bound (certified linear worst case plus
/// e^S - 1 - S, the histogram range: no overflow) and comes close to the linear worst case.
#[test]
fn figure9_table4_maximum_of_a_million_samples_approaches_and_never_exceeds_the_certified_worst_case()
 {
    let t = paper_table();
    let mc = MonteCarlo::new(&t, table4(), config(1_000_000, 2017)).unwrap();
    let r = mc.run();
    let req = EQ16_REQUIREMENT_DEG.to_radians();
    let worst = linear_worst_cases(&t, table4().ub_rad());
    let bound = MonteCarlo::histogram_half_range_rad(&t, &table4()).unwrap();
    assert_eq!(r.count().samples(), 1_000_000);
    assert_eq!(r.count().meeting(), r.count().samples());
    for (a, ((value, upper), h)) in r.axes().iter().zip(worst.into_iter().zip(bound)) {
        let name = a.axis().name();
        // one free joint: the linear worst case is exact
        assert_eq!(value.to_bits(), upper.to_bits(), "{name}");
        assert!(
            a.max_abs_rad() <= h,
            "{name}: {} > bound {h}",
            a.max_abs_rad()
        );
        assert!(h < req, "{name}: the rigorous bound itself meets eq 16");
        let close = if a.axis() == OrientationAxis::Theta {
            THETA_CLOSE_REL
        } else {
            PSI_GAMMA_CLOSE_REL
        };
        assert!(
            a.max_abs_rad() >= (1.0 - close) * value,
            "{name}: max {} vs linear worst case {value}",
            a.max_abs_rad()
        );
        // the histogram range is the rigorous bound: nothing falls outside
        assert_eq!(a.histogram().hi().to_bits(), h.to_bits());
        assert_eq!(a.histogram().underflow() + a.histogram().overflow(), 0);
        assert_eq!(a.histogram().total(), r.count().samples());
    }
    assert_eq!(r.count().meeting_per_output(), [r.count().samples(); 3]);
    let theta_share = worst[1].0 / req;
    assert!((theta_share - TABLE4_WORST_OVER_REQUIREMENT).abs() < PRINTED_PERCENT_ABS);
    assert!((r.count().fraction() - 1.0).abs() < f64::EPSILON);
}

/// The same bound on a three-axis table (two free joints: the certified upper bound comes
/// from a branch and bound): no sample beyond it, no histogram overflow.
#[test]
fn three_axis_maximum_never_exceeds_the_certified_bound() {
    let t = three_axis();
    let b = three_axis_box();
    let r = MonteCarlo::new(
        &t,
        b.clone(),
        McConfig::new(300_000, 3, tt_core::Requirement::none()),
    )
    .unwrap()
    .run();
    let bound = MonteCarlo::histogram_half_range_rad(&t, &b).unwrap();
    let worst = linear_worst_cases(&t, b.ub_rad());
    for (a, ((value, upper), h)) in r.axes().iter().zip(worst.into_iter().zip(bound)) {
        assert!(value <= upper && upper < h);
        assert!(
            a.max_abs_rad() <= h,
            "{}: {} > {h}",
            a.axis().name(),
            a.max_abs_rad()
        );
        assert_eq!(a.histogram().underflow() + a.histogram().overflow(), 0);
    }
}

/// The requirement is a parameter: a requirement below the observed maxima is violated by a
/// positive fraction of samples (the count is not hard-wired to "all").
#[test]
fn a_tighter_requirement_is_violated_by_some_samples() {
    let cfg = config(200_000, 1).with_requirement(
        tt_core::Requirement::from_options([Some(tt_core::units::deg_to_rad(0.02)); 3]).unwrap(),
    );
    let r = MonteCarlo::new(&paper_table(), table4(), cfg)
        .unwrap()
        .run();
    assert!(r.count().meeting() < r.count().samples());
    assert!(r.count().meeting() > 0);
    for &within in r.count().meeting_per_output() {
        assert!(within >= r.count().meeting());
    }
}
