//! Magnitude (disc) bounds (issue 22): a vendor's wobble or perpendicularity bounds the
//! magnitude of a two-component tilt, sqrt(a^2 + b^2) <= w. Its worst case is the Euclidean
//! norm of the pair's coefficients; the allocation gives a pair one radius and is never tighter
//! than the square's; the Monte Carlo draws stay in the disc and do not depend on the thread
//! count; a harmonic pair's bound lies between the constant disc's and the square's.

mod common;

use approx::assert_relative_eq;
use calib_lsq::Reading;
use common::*;
use e2e_verify::EndToEnd;
use e2e_verify::disc::{Pair, PairShape, disc_dual};
use std::path::Path;
use tt_kinematics::{ErrorVariation as V, Expansion};

/// Relative agreement of two evaluations of the same closed form in floating point
/// (dimensionless): a handful of rounded operations on each side.
const CLOSED_FORM_REL: f64 = 1e-12;

/// Relative slack of a comparison between two allocations or of a box against its accuracy
/// (dimensionless): the power-cone solver meets its constraints to about 1e-9 of the
/// accuracy.
const SOLVER_REL: f64 = 1e-7;

/// Slack of a draw against its disc, relative to the radius (dimensionless): the draw's
/// trigonometric products round at 1e-16.
const DRAW_REL: f64 = 1e-12;

/// Relative slack of the ordering of dual norms (dimensionless): the harmonic dual norms are
/// certified with the interior-point solver's rounding, far below this.
const NESTING_REL: f64 = 1e-9;

fn expansion(e2e: &EndToEnd, variations: &[V]) -> Expansion {
    Expansion::new(e2e.turntable(), variations, e2e.poses()).unwrap()
}

/// The three-axis example under the user's reading and the discs of its vendor sheet
/// (`studies/tolerances/three-axis-vendor-sheet.toml`: three wobbles, two perpendicularities).
fn three_axis_with_sheet() -> (EndToEnd, study::Tolerances) {
    let e2e = study_e2e("three-axis-example", Some(Reading::USER));
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../studies/tolerances/three-axis-vendor-sheet.toml");
    let tol = study::Tolerances::load(&path, e2e.turntable()).unwrap();
    assert_eq!(
        tol.discs.len(),
        5,
        "three wobbles and two perpendicularities"
    );
    (e2e, tol)
}

fn pairs(tol: &study::Tolerances, shape: PairShape) -> Vec<Pair> {
    tol.discs
        .iter()
        .map(|d| Pair {
            errors: d.errors,
            shape,
        })
        .collect()
}

/// With constant errors the worst case over a disc of radius w on two errors is
/// w max_r ||(M_ra, M_rb)||_2, the row's Euclidean norm, computed here from the constant
/// linearisation directly.
#[test]
fn disc_worst_case_of_constant_errors_is_the_euclidean_norm_of_the_pair() {
    let (e2e, tol) = three_axis_with_sheet();
    let n_err = e2e.n_errors();
    let ex = expansion(&e2e, &vec![V::Constant; n_err]);
    let model = e2e.angle().pair_model(&ex).unwrap();
    let lin = e2e.linearization();
    let n = e2e.len();
    for d in &tol.discs {
        let [a, b] = d.errors;
        let w = d.bound_rad;
        let pair = Pair {
            errors: d.errors,
            shape: PairShape::Disc,
        };
        let (upper, lower) = model.worst_case(&vec![0.0; n_err], &[(pair, w)]);
        for k in 0..e2e.n_outputs() {
            let closed = (0..n)
                .map(|i| {
                    let m = lin.matrix();
                    w * m[(k * n + i, a)].hypot(m[(k * n + i, b)])
                })
                .fold(0.0, f64::max);
            assert_relative_eq!(upper[k], closed, max_relative = CLOSED_FORM_REL);
            assert_relative_eq!(lower[k], closed, max_relative = CLOSED_FORM_REL);
        }
    }
}

/// The vendor sheet's five pairs allocated as discs and as squares (one tolerance per pair
/// either way), for constant errors and for the sheet's model (every error any function of its
/// shaft): the disc's J is never above the square's and strictly below it (the discs bind),
/// every pair's radius is at least the square's half side, and the disc box meets every
/// accuracy on the first-order worst case with the discs.
#[test]
fn disc_allocation_is_looser_than_the_square_allocation_and_meets_every_accuracy() {
    let (e2e, tol) = three_axis_with_sheet();
    let t = e2e.turntable();
    let lb = vec![0.0; e2e.n_errors()];
    let acc = e2e.accuracies();
    for v in [
        vec![V::Constant; e2e.n_errors()],
        tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() }),
    ] {
        let ex = expansion(&e2e, &v);
        let model = e2e.angle().pair_model(&ex).unwrap();
        let disc_pairs = pairs(&tol, PairShape::Disc);
        let square_pairs = pairs(&tol, PairShape::Square);
        let disc = e2e
            .angle()
            .allocate_direct_paired(&model.merged(&disc_pairs), &lb, &disc_pairs, None)
            .unwrap();
        let square = e2e
            .angle()
            .allocate_direct_paired(&model.merged(&square_pairs), &lb, &square_pairs, None)
            .unwrap();
        assert!(
            disc.objective() <= square.objective() * (1.0 + SOLVER_REL),
            "disc J {} > square J {}",
            disc.objective(),
            square.objective()
        );
        assert!(
            disc.objective() < square.objective() * (1.0 - 1e-3),
            "the discs bind: J {} vs {}",
            disc.objective(),
            square.objective()
        );
        for p in &disc_pairs {
            let [a, b] = p.errors;
            // one radius per pair, bit for bit
            assert_eq!(
                disc.upper_bounds_rad()[a].to_bits(),
                disc.upper_bounds_rad()[b].to_bits()
            );
            assert_eq!(
                square.upper_bounds_rad()[a].to_bits(),
                square.upper_bounds_rad()[b].to_bits()
            );
        }
        // every row of the disc box within its accuracy, first order, discs as discs
        let with_radius: Vec<(Pair, f64)> = disc_pairs
            .iter()
            .map(|p| (*p, disc.upper_bounds_rad()[p.errors[0]]))
            .collect();
        let (worst, _) = model.worst_case(disc.upper_bounds_rad(), &with_radius);
        for (k, w) in worst.iter().enumerate() {
            assert!(
                *w <= acc[k] * (1.0 + SOLVER_REL),
                "output {k}: {w} > {}",
                acc[k]
            );
        }
        // the square box, read as discs, is feasible for the disc problem: the disc optimum
        // is at most its J (checked above) and the square's worst case is above the disc's
        let sq_radius: Vec<(Pair, f64)> = square_pairs
            .iter()
            .map(|p| (*p, square.upper_bounds_rad()[p.errors[0]]))
            .collect();
        let (sq_worst, _) = model.worst_case(square.upper_bounds_rad(), &sq_radius);
        let as_disc: Vec<(Pair, f64)> = sq_radius
            .iter()
            .map(|(p, w)| {
                (
                    Pair {
                        errors: p.errors,
                        shape: PairShape::Disc,
                    },
                    *w,
                )
            })
            .collect();
        let (sq_as_disc, _) = model.worst_case(square.upper_bounds_rad(), &as_disc);
        for k in 0..acc.len() {
            assert!(sq_as_disc[k] <= sq_worst[k] * (1.0 + NESTING_REL));
            assert!(sq_worst[k] <= acc[k] * (1.0 + SOLVER_REL));
        }
    }
}

/// The certified allocation with discs: its box is certified on the exact chain (linear bound
/// with the discs plus the second-order bound at sqrt(2) times each radius within every
/// accuracy) and its J is at most the certified square's.
#[test]
fn certified_disc_allocation_meets_every_accuracy_with_the_second_order_bound() {
    let (e2e, tol) = three_axis_with_sheet();
    let lb = vec![0.0; e2e.n_errors()];
    let ex = expansion(&e2e, &vec![V::Constant; e2e.n_errors()]);
    let model = e2e.angle().pair_model(&ex).unwrap();
    let params = e2e_verify::CertifyParams::default();
    let disc_pairs = pairs(&tol, PairShape::Disc);
    let square_pairs = pairs(&tol, PairShape::Square);
    let disc = e2e
        .angle()
        .allocate_direct_paired(&model.merged(&disc_pairs), &lb, &disc_pairs, Some(&params))
        .unwrap();
    let square = e2e
        .angle()
        .allocate_direct_paired(
            &model.merged(&square_pairs),
            &lb,
            &square_pairs,
            Some(&params),
        )
        .unwrap();
    assert!(disc.objective() <= square.objective() * (1.0 + SOLVER_REL));
    let with_radius: Vec<(Pair, f64)> = disc_pairs
        .iter()
        .map(|p| (*p, disc.upper_bounds_rad()[p.errors[0]]))
        .collect();
    let (worst, _) = model.worst_case(disc.upper_bounds_rad(), &with_radius);
    // the l1 size of the disc box: sqrt(2) r per pair, UB for the rest
    let mut in_pair = vec![false; e2e.n_errors()];
    let mut s = 0.0;
    for (p, r) in &with_radius {
        in_pair[p.errors[0]] = true;
        in_pair[p.errors[1]] = true;
        s += std::f64::consts::SQRT_2 * r;
    }
    s += disc
        .upper_bounds_rad()
        .iter()
        .zip(&in_pair)
        .filter(|(u, p)| !**p && u.is_finite())
        .map(|(u, _)| u)
        .sum::<f64>();
    for (k, w) in worst.iter().enumerate() {
        let tau = e2e.second_order_bound(k, s).unwrap().unwrap();
        assert!(
            w + tau <= e2e.accuracies()[k] * (1.0 + SOLVER_REL),
            "output {k}: {w} + {tau} > {}",
            e2e.accuracies()[k]
        );
    }
}

/// Draws with discs stay in their discs: at every test position for constant and `any`
/// errors, and on a fine grid of the shaft angle for harmonic pairs (same joint and orders).
#[test]
fn disc_draws_stay_inside_the_disc() {
    let (e2e, tol) = three_axis_with_sheet();
    let t = e2e.turntable();
    let discs: Vec<([usize; 2], f64)> = tol.discs.iter().map(|d| (d.errors, d.bound_rad)).collect();
    let models = [
        vec![V::Constant; e2e.n_errors()],
        tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() }),
        tt_kinematics::on_shafts(t, |j| V::Harmonics {
            joint: j.into(),
            orders: vec![1, 2],
        }),
    ];
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for v in &models {
        let ex = expansion(&e2e, v);
        let mut c = vec![0.0; ex.n_coefficients()];
        let mut chi = vec![0.0; e2e.n_errors()];
        let mut largest = 0.0_f64;
        for _ in 0..2000 {
            ex.draw_with_discs(&tol.ub_rad, &discs, &mut uniform, &mut c);
            for p in 0..e2e.len() {
                ex.chi_at(&c, p, &mut chi);
                for &([a, b], w) in &discs {
                    let r = chi[a].hypot(chi[b]);
                    assert!(r <= w * (1.0 + DRAW_REL), "{r} > {w}");
                    largest = largest.max(r / w);
                }
            }
            for &([a, b], w) in &discs {
                let (ga, gb) = (&ex.groups()[a], &ex.groups()[b]);
                if let tt_kinematics::GroupShape::Harmonics { orders, .. } = &ga.shape {
                    let ca = &c[ga.first..ga.first + ga.len()];
                    let cb = &c[gb.first..gb.first + gb.len()];
                    for i in 0..720 {
                        let phi = std::f64::consts::TAU * f64::from(i) / 720.0;
                        let va = tt_kinematics::variation::harmonic_value(orders, ca, phi);
                        let vb = tt_kinematics::variation::harmonic_value(orders, cb, phi);
                        assert!(va.hypot(vb) <= w * (1.0 + DRAW_REL));
                    }
                }
            }
        }
        // the law fills the disc, not a small part of it
        assert!(largest > 0.9, "largest draw {largest} of the radius");
    }
}

/// The Monte Carlo with discs: the same answer on one thread and on two, today's answer with
/// no disc, and a different one with the discs (the pairs are drawn in the disc).
#[test]
fn disc_monte_carlo_is_identical_for_one_and_two_threads() {
    let (e2e, tol) = three_axis_with_sheet();
    let t = e2e.turntable();
    let ex = expansion(
        &e2e,
        &tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() }),
    );
    let discs: Vec<([usize; 2], f64)> = tol.discs.iter().map(|d| (d.errors, d.bound_rad)).collect();
    let run = |threads: usize, discs: &[([usize; 2], f64)]| {
        common::on_threads(threads, || {
            e2e.angle()
                .angle_yield_with_discs(&ex, &tol.ub_rad, discs, 3000, 11)
                .unwrap()
        })
    };
    let one = run(1, &discs);
    assert_eq!(one, run(2, &discs));
    assert_eq!(one.count().samples(), 3000);
    let plain = run(2, &[]);
    assert_eq!(
        plain,
        e2e.angle().angle_yield(&ex, &tol.ub_rad, 3000, 11).unwrap()
    );
    assert_ne!(one, plain);
}

/// A harmonic pair under a disc: the certified lower value and the rigorous upper bound lie
/// between the constant disc's norm and the square's harmonic bound, on every row of the
/// three-axis example (first and second harmonics of every shaft) and on random functionals
/// built from random per-position effects (the form every row has).
#[test]
fn harmonic_disc_bound_lies_between_the_constant_disc_and_the_square_harmonic_bound() {
    let (e2e, tol) = three_axis_with_sheet();
    let t = e2e.turntable();
    let harmonics = tt_kinematics::on_shafts(t, |j| V::Harmonics {
        joint: j.into(),
        orders: vec![1, 2],
    });
    let ex = expansion(&e2e, &harmonics);
    let model = e2e.angle().pair_model(&ex).unwrap();
    let constant = e2e.linearization();
    let check = |upper: f64, lower: f64, constant_disc: f64, square: f64| {
        assert!(lower <= upper, "{lower} > {upper}");
        assert!(
            lower >= constant_disc * (1.0 - NESTING_REL),
            "{lower} < {constant_disc}"
        );
        assert!(upper <= square * (1.0 + NESTING_REL), "{upper} > {square}");
    };
    let mut tighter = 0;
    for d in &tol.discs {
        let [a, b] = d.errors;
        if !matches!(
            ex.groups()[a].shape,
            tt_kinematics::GroupShape::Harmonics { .. }
        ) {
            continue;
        }
        for r in 0..constant.matrix().nrows() {
            let disc = model.dual(
                r,
                Pair {
                    errors: d.errors,
                    shape: PairShape::Disc,
                },
            );
            let square = model.dual(
                r,
                Pair {
                    errors: d.errors,
                    shape: PairShape::Square,
                },
            );
            let m = constant.matrix();
            check(
                disc.upper,
                disc.lower,
                m[(r, a)].hypot(m[(r, b)]),
                square.upper,
            );
            if disc.upper < square.upper * (1.0 - 1e-6) {
                tighter += 1;
            }
        }
    }
    assert!(tighter > 0, "the disc is tighter than the square somewhere");
    // random functionals s = sum_i e_i basis(phi_i) and their `any` form
    let any_v = tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() });
    let any_ex = expansion(&e2e, &any_v);
    let mut state = 12345_u64;
    let mut normal = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let functional = |ex: &Expansion, e: &[Vec<f64>]| -> Vec<f64> {
        let mut s = vec![0.0; ex.n_coefficients()];
        for g in ex.groups() {
            for (c, basis) in g.basis.iter().enumerate() {
                s[g.first + c] = basis.iter().zip(&e[g.error]).map(|(x, y)| x * y).sum();
            }
        }
        s
    };
    for _ in 0..40 {
        let e: Vec<Vec<f64>> = (0..e2e.n_errors())
            .map(|_| (0..e2e.len()).map(|_| normal()).collect())
            .collect();
        let s = functional(&ex, &e);
        let s_any = functional(&any_ex, &e);
        for d in &tol.discs {
            let [a, b] = d.errors;
            let (ga, gb) = (&ex.groups()[a], &ex.groups()[b]);
            if !matches!(ga.shape, tt_kinematics::GroupShape::Harmonics { .. }) {
                continue;
            }
            let disc = disc_dual(&ex, &s, Some((&any_ex, &s_any)), a, b);
            let constant_disc = e[a].iter().sum::<f64>().hypot(e[b].iter().sum::<f64>());
            let square = ga.dual_norm(&s[ga.first..ga.first + ga.len()])
                + gb.dual_norm(&s[gb.first..gb.first + gb.len()]);
            check(disc.upper, disc.lower, constant_disc, square);
        }
    }
}

/// A "disc" on two errors that follow different joints bounds nothing per shaft angle (the
/// two angles differ from position to position): the dual norm falls back to the square's,
/// even where the two joints visit the same angles.
#[test]
fn disc_on_errors_of_different_joints_is_bounded_by_the_square() {
    let (e2e, _) = three_axis_with_sheet();
    let t = e2e.turntable();
    let ex = expansion(
        &e2e,
        &tt_kinematics::on_shafts(t, |j| V::Any { joint: j.into() }),
    );
    let model = e2e.angle().pair_model(&ex).unwrap();
    let (a, b) = (
        t.rotation_error_index("dalpha_ox").unwrap(),
        t.rotation_error_index("dalpha_iz").unwrap(),
    );
    for r in 0..model.expanded().matrix().nrows() {
        let disc = model.dual(
            r,
            Pair {
                errors: [a, b],
                shape: PairShape::Disc,
            },
        );
        let square = model.dual(
            r,
            Pair {
                errors: [a, b],
                shape: PairShape::Square,
            },
        );
        assert_relative_eq!(disc.upper, square.upper, max_relative = CLOSED_FORM_REL);
    }
}
