//! End to end with errors that vary with a shaft angle (issue 22): the constant expansion
//! reproduces today's answers exactly, the expanded linearisation agrees with the reference
//! path at small coefficients, the worst cases are ordered constant <= harmonics <= any, and
//! the Monte Carlo is deterministic.

mod common;

use calib_lsq::Reading;
use common::*;
use e2e_verify::EndToEnd;
use tt_kinematics::{ChainKind, ErrorVariation as V, Expansion, TurntableErrors};

/// Relative agreement of the first-order model with the exact reference path at coefficients
/// of 1e-7 rad (dimensionless): the remainder is second order, about 1e-7 of the effect.
const FIRST_ORDER_REL: f64 = 1e-5;

/// Relative slack of the ordering of worst cases (dimensionless): certified harmonic dual
/// norms carry the interior-point solver's rounding, far below this.
const NESTING_REL: f64 = 1e-9;

fn expansion(e2e: &EndToEnd, variations: &[V]) -> Expansion {
    Expansion::new(e2e.turntable(), variations, e2e.poses()).unwrap()
}

/// The paper's errors with the inner axis's wobbles `dalpha_x2`, `dalpha_y2` and position
/// error `dphi_z2` following `phi2` as `model`, the rest constant.
fn paper_variations(e2e: &EndToEnd, model: &dyn Fn() -> V) -> Vec<V> {
    e2e.turntable()
        .rotation_error_names()
        .iter()
        .map(|n| {
            if ["dalpha_x2", "dalpha_y2", "dphi_z2"].contains(n) {
                model()
            } else {
                V::Constant
            }
        })
        .collect()
}

/// [`paper_variations`] with harmonics 1 and 2 of `phi2`, expanded.
fn phi2_harmonics(e2e: &EndToEnd) -> Expansion {
    let harmonics = || V::Harmonics {
        joint: "phi2".into(),
        orders: vec![1, 2],
    };
    expansion(e2e, &paper_variations(e2e, &harmonics))
}

/// Coefficients drawn within `ub` from the deterministic sequence
/// u_k = ((k * multiplier) mod modulus) / modulus, k = 1, 2, ...
fn draw_within(ex: &Expansion, ub: &[f64], multiplier: u64, modulus: u64) -> Vec<f64> {
    let mut chi = vec![0.0; ex.n_coefficients()];
    let mut k = 0_u64;
    ex.draw(
        ub,
        || {
            k += 1;
            ((k * multiplier) % modulus) as f64 / modulus as f64
        },
        &mut chi,
    );
    chi
}

/// Every error constant (or harmonics with no order): the expanded linearisation is the
/// constant one bit for bit, the reduced one is |M|, and the worst case, the direct allocation
/// and the verdict are today's.
#[test]
fn constant_expansion_reproduces_the_constant_model_exactly() {
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = paper(reading);
        let lin = e2e.linearization();
        for model in [
            V::Constant,
            V::Harmonics {
                joint: "phi2".into(),
                orders: vec![],
            },
        ] {
            let ex = expansion(&e2e, &paper_variations(&e2e, &|| model.clone()));
            let al = e2e.angle().angle_linearization(&ex).unwrap();
            assert_eq!(al.expanded.matrix(), lin.matrix());
            assert_eq!(al.reduced.matrix(), &lin.matrix().abs());
            let ub = alloc_opt::paper::table4_rad();
            let today = e2e.worst_case(&lin, &ub).unwrap();
            let angle = e2e.angle().angle_worst_case(&ex, &al, &lin, &ub).unwrap();
            for (t, a) in today.outputs().iter().zip(&angle) {
                assert_eq!(t.linear_bound().to_bits(), a.linear_bound().to_bits());
                assert_eq!(
                    t.linear_bound().to_bits(),
                    a.constant_linear_bound().to_bits()
                );
                assert_eq!(t.exact_at_vertex().to_bits(), a.exact_at_vertex().to_bits());
            }
            let lb = vec![0.0; ub.len()];
            let d0 = e2e.allocate_direct(&lin, &lb).unwrap();
            let d1 = e2e.allocate_direct(&al.reduced, &lb).unwrap();
            assert_eq!(d0.upper_bounds_arcmin(), d1.upper_bounds_arcmin());
        }
    }
}

/// The expanded linearisation is the first-order model of the exact chain with the errors at
/// chi(phi_i): at coefficients of 1e-7 rad, max_i |(M_c c)_{ki}| equals Delta omega_k of the
/// reference path (plain matrix chain per position, calib-lsq's analysis) to first order, and
/// the fast path (segmented chain per position) equals the reference path.
#[test]
fn expanded_linearization_is_the_first_order_model_of_the_exact_chain() {
    let e2e = paper(Reading::USER);
    let harm = || V::Harmonics {
        joint: "phi2".into(),
        orders: vec![1, 2, 3],
    };
    let mut variations = paper_variations(&e2e, &harm);
    let i = e2e.turntable().rotation_error_index("dphi_z2").unwrap();
    variations[i] = V::Any {
        joint: "phi2".into(),
    };
    let ex = expansion(&e2e, &variations);
    let lin = e2e.angle().linearization_expanded(&ex).unwrap();
    let c: Vec<f64> = (0..ex.n_coefficients())
        .map(|k| 1e-7 * (((k * 7919) % 13) as f64 / 6.0 - 1.0))
        .collect();
    let mc = lin.matrix() * nalgebra::DVector::from_vec(c.clone());
    let n = e2e.len();
    let dr: Vec<_> = e2e
        .poses()
        .iter()
        .enumerate()
        .map(|(p, pose)| {
            let errors: TurntableErrors = ex.errors_at(&c, p, &[0.0]).unwrap();
            e2e.turntable()
                .delta_r(pose, &errors, ChainKind::Exact)
                .unwrap()
        })
        .collect();
    let reference = e2e.run_with_delta_r(&dr).unwrap().delta_omega();
    let mut work = e2e.work();
    e2e.angle()
        .delta_omega_expanded(&ex, &c, &mut work)
        .unwrap();
    for k in 0..e2e.n_outputs() {
        let linear = (0..n).map(|p| mc[k * n + p].abs()).fold(0.0, f64::max);
        approx::assert_relative_eq!(reference[k], linear, max_relative = FIRST_ORDER_REL);
        approx::assert_relative_eq!(work.delta_omega[k], reference[k], max_relative = 1e-9);
    }
}

/// For the same bounds (Table 4) the worst case of every output is ordered: constant <=
/// harmonics <= any, on the paper's study and on the three-axis example.
#[test]
fn worst_case_under_any_is_at_least_harmonics_which_is_at_least_constant_end_to_end() {
    for (e2e, ub) in [
        (paper(Reading::USER), alloc_opt::paper::table4_rad()),
        (
            study_e2e("three-axis-example", Some(Reading::USER)),
            vec![tt_core::units::arcmin_to_rad(0.3); 13],
        ),
    ] {
        let lin = e2e.linearization();
        let free = e2e.turntable().free_joints().to_vec();
        let names: Vec<String> = e2e
            .turntable()
            .joint_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        // every error after a free joint follows the last joint before it
        let follow = |model: &dyn Fn(String) -> V| -> Vec<V> {
            e2e.turntable()
                .rotation_errors()
                .iter()
                .map(|er| {
                    let last = e2e
                        .turntable()
                        .joints()
                        .iter()
                        .enumerate()
                        .filter(|(j, jt)| jt.factor < er.factor && free.contains(j))
                        .map(|(j, _)| names[j].clone())
                        .next_back();
                    last.map_or(V::Constant, model)
                })
                .collect()
        };
        let wc = |v: Vec<V>| {
            let ex = expansion(&e2e, &v);
            let al = e2e.angle().angle_linearization(&ex).unwrap();
            e2e.angle()
                .angle_worst_case(&ex, &al, &lin, &ub)
                .unwrap()
                .iter()
                .map(|o| o.linear_bound())
                .collect::<Vec<_>>()
        };
        let c = wc(follow(&|_| V::Constant));
        let h = wc(follow(&|j| V::Harmonics {
            joint: j,
            orders: vec![1, 2],
        }));
        let a = wc(follow(&|j| V::Any { joint: j }));
        for k in 0..c.len() {
            assert!(
                c[k] <= h[k] * (1.0 + NESTING_REL),
                "output {k}: {} > {}",
                c[k],
                h[k]
            );
            assert!(
                h[k] <= a[k] * (1.0 + NESTING_REL),
                "output {k}: {} > {}",
                h[k],
                a[k]
            );
        }
    }
}

/// The Monte Carlo of angle-dependent turntables is seeded and deterministic, never exceeds
/// the certified worst case, and its draws stay inside the bounds.
#[test]
fn angle_yield_is_deterministic_and_within_the_worst_case() {
    let e2e = paper(Reading::USER);
    let ex = phi2_harmonics(&e2e);
    let ub = alloc_opt::paper::table4_rad();
    let a = e2e.angle().angle_yield(&ex, &ub, 3000, 7).unwrap();
    let b = e2e.angle().angle_yield(&ex, &ub, 3000, 7).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.count().samples(), 3000);
    let lin = e2e.linearization();
    let al = e2e.angle().angle_linearization(&ex).unwrap();
    let wc = e2e.angle().angle_worst_case(&ex, &al, &lin, &ub).unwrap();
    let acc = e2e.accuracies();
    let bound = wc
        .iter()
        .map(|o| {
            (o.linear_bound() + o.second_order_bound().unwrap_or(o.linear_bound()))
                / acc[o.output()]
        })
        .fold(0.0, f64::max);
    assert!(a.worst_ratio() <= bound, "{} > {bound}", a.worst_ratio());
}

/// A magnitude bound sqrt(a^2 + b^2) <= w lies between the square of side w/sqrt(2) inside it
/// and the square of side w around it: its worst case is between theirs, for constant and for
/// angle-dependent errors (three-axis example, every wobble pair as a disc).
#[test]
fn disc_bounds_lie_between_the_inscribed_and_the_circumscribed_squares() {
    let e2e = study_e2e("three-axis-example", Some(Reading::USER));
    let t = e2e.turntable();
    let idx = |n: &str| t.rotation_error_index(n).unwrap();
    let w = tt_core::units::arcmin_to_rad(0.05);
    let pairs = [
        ("dalpha_ox", "dalpha_oy"),
        ("dalpha_my", "dalpha_mz"),
        ("dalpha_ix", "dalpha_iz"),
    ];
    let discs: Vec<([usize; 2], f64)> = pairs.iter().map(|(a, b)| ([idx(a), idx(b)], w)).collect();
    let square = vec![tt_core::units::arcmin_to_rad(0.08); t.n_rotation_errors()];
    let with = |side: f64| {
        let mut u = square.clone();
        for ([a, b], _) in &discs {
            u[*a] = side;
            u[*b] = side;
        }
        u
    };
    for v in [
        vec![V::Constant; t.n_rotation_errors()],
        tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() }),
    ] {
        let ex = expansion(&e2e, &v);
        let lin = e2e.angle().linearization_expanded(&ex).unwrap();
        let worst = |u: &[f64]| e2e_verify::angle::disc_worst_case(&ex, &lin, u, &[]);
        let disc = e2e_verify::angle::disc_worst_case(&ex, &lin, &with(w), &discs);
        let (outer, inner) = (worst(&with(w)), worst(&with(w / 2f64.sqrt())));
        for k in 0..disc.len() {
            assert!(
                disc[k] <= outer[k] * (1.0 + NESTING_REL),
                "{k}: {} > {}",
                disc[k],
                outer[k]
            );
            assert!(
                disc[k] >= inner[k] * (1.0 - NESTING_REL),
                "{k}: {} < {}",
                disc[k],
                inner[k]
            );
        }
        assert!(
            (0..disc.len()).any(|k| disc[k] < outer[k] * (1.0 - 1e-6)),
            "the disc is tighter somewhere"
        );
    }
}

/// Compensation (issue 22): with the measured errors equal to the true ones (zero
/// uncertainty) the calibration error of the compensated chain vanishes, although the same
/// errors uncompensated miss nothing of their effect.
#[test]
fn compensation_with_an_exact_measurement_removes_the_errors_contribution() {
    let e2e = paper(Reading::USER);
    let ex = phi2_harmonics(&e2e);
    let ub = alloc_opt::paper::table4_rad();
    let chi = draw_within(&ex, &ub, 2654435761, 1000);
    let uncompensated = {
        let mut w = e2e.work();
        e2e.angle().delta_omega_expanded(&ex, &chi, &mut w).unwrap();
        w.delta_omega
    };
    let compensated = e2e
        .angle()
        .delta_omega_compensated(&ex, &chi, &chi)
        .unwrap();
    for o in 0..e2e.n_outputs() {
        assert!(uncompensated[o] > 1e3 * e2e.precisions()[o]);
        assert!(compensated[o] <= e2e.precisions()[o], "{}", compensated[o]);
    }
}

/// Second-order agreement of the compensated chain with the uncompensated chain of the
/// residual (dimensionless): the residual is 1e-7 rad, the measured errors up to Table 4
/// (about 2.3e-4 rad), so the difference is about 2.3e-4 of the effect; 1e-2 is the margin.
const COMPENSATED_REL: f64 = 1e-2;

/// With an uncertainty: the compensated calibration error of a table whose true errors differ
/// from the measured ones by a residual e is the uncompensated error of e (to second order),
/// so the analysis of the compensated table is the analysis of the uncertainty box.
#[test]
fn compensation_with_an_uncertainty_is_the_analysis_of_the_uncertainty_box() {
    let e2e = paper(Reading::USER);
    let ex = phi2_harmonics(&e2e);
    let ub = alloc_opt::paper::table4_rad();
    let m = draw_within(&ex, &ub, 40503, 997);
    let e: Vec<f64> = (0..m.len())
        .map(|i| 1e-7 * (((i * 31) % 7) as f64 / 3.0 - 1.0))
        .collect();
    let chi: Vec<f64> = m.iter().zip(&e).map(|(a, b)| a + b).collect();
    let compensated = e2e.angle().delta_omega_compensated(&ex, &m, &chi).unwrap();
    let mut w = e2e.work();
    e2e.angle().delta_omega_expanded(&ex, &e, &mut w).unwrap();
    for (c, u) in compensated.iter().zip(&w.delta_omega) {
        approx::assert_relative_eq!(*c, *u, max_relative = COMPENSATED_REL);
    }
    let u: Vec<Option<f64>> = (0..ub.len())
        .map(|j| (j % 2 == 0).then_some(1e-6))
        .collect();
    let boxed = e2e_verify::angle::compensated_box(&ub, &u);
    for (j, (b, u)) in boxed.iter().zip(&ub).enumerate() {
        let want = if j % 2 == 0 { 1e-6 } else { *u };
        assert_eq!(b.to_bits(), want.to_bits(), "error {j}");
    }
}

/// The allocation after compensation holds the measured errors at their uncertainty and keeps
/// every row of the first-order model within its accuracy; an uncertainty that alone exceeds
/// an accuracy leaves no room (named output), not a bad allocation.
#[test]
fn compensated_allocation_holds_measured_errors_at_their_uncertainty_and_meets_every_row() {
    /// Relative slack of a row at its accuracy (dimensionless): the solver's tolerance.
    const ROW_REL: f64 = 1e-7;
    let e2e = paper(Reading::USER);
    let lin = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let u = 3.0 / 60.0 * tt_core::units::RAD_PER_ARCMIN;
    let mut fixed = vec![None; e2e.n_errors()];
    fixed[0] = Some(u);
    fixed[6] = Some(u);
    let d = e2e
        .angle()
        .allocate_direct_compensated(&lin, &lb, &fixed)
        .unwrap()
        .unwrap();
    assert_eq!(d.upper_bounds_rad()[0].to_bits(), u.to_bits());
    assert_eq!(d.upper_bounds_rad()[6].to_bits(), u.to_bits());
    assert!(
        d.upper_bounds_rad()
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    );
    let rows = lin.row_worst_cases(d.upper_bounds_rad());
    let acc = e2e.accuracies();
    let n = e2e.len();
    for (r, v) in rows.iter().enumerate() {
        assert!(*v <= acc[r / n] * (1.0 + ROW_REL), "row {r}: {v}");
    }
    let mut huge = vec![None; e2e.n_errors()];
    huge[0] = Some(600.0 * tt_core::units::RAD_PER_ARCMIN);
    let blocked = e2e
        .angle()
        .allocate_direct_compensated(&lin, &lb, &huge)
        .unwrap()
        .unwrap_err();
    assert!(!blocked.is_empty());
}
