//! Claim tests of issue 7: the end-to-end calibration error of a turntable with geometric
//! errors, its linearisation and worst case, Monte Carlo yield, direct and yield-based
//! allocation, and typed errors for bad input.

use alloc_opt::{AllocationProblem, Allocator, SensitivityWeighted, Weights, paper_table4_rad};
use approx::{assert_abs_diff_eq, assert_relative_eq};
use calib_lsq::{ErrorForm, Estimate, Reading, RequirementProblem};
use e2e_verify::{
    E2eError, EndToEnd, EndToEndInputs, McSettings, paper_objective, wilson_interval_95,
};
use gw_model::units::{deg_per_h_to_rad_per_s, rad_per_s_to_deg_per_h};
use gw_model::{DeltaRKind, OrientationAngles, Position, SensingAxis, Site};
use mc_verify::{BLOCK_CAPACITY, ErrorBox, McError, SampleBlock, TurntableSampler, chunk_rng};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{
    CHI_LEN, ChainKind, ErrorComponent, Pose, TurntableErrors, actual_transform, delta_r,
    ideal_transform,
};

/// Rotation matrices computed by two association orders of the same ten factors: a few ulp
/// of entries of order 1. Dimensionless.
const ROTATION_ABS: f64 = 1e-14;

/// Rate errors computed by the fast path (precomputed $A^+$) and by calib-lsq (QR solve):
/// the outputs are of order $10^{-4}$ rad/s (Table 1 drifts), rounded to $10^{-20}$; the two
/// solves differ by a few ulp of those. rad/s ($10^{-15}$ rad/s $= 2\times10^{-10}$ deg/h).
const RATE_ABS_RAD_PER_S: f64 = 1e-15;

/// With $\chi = 0$ every reading's error vector is a difference of equal sums of terms of
/// order $10^{-4}$ rad/s: zero up to their rounding. rad/s.
const ZERO_RATE_ABS_RAD_PER_S: f64 = 1e-17;

/// Central-difference step for the numerical Jacobian, rad: truncation $O(h^2) \sim 10^{-12}$
/// relative, rounding $10^{-20}/h \sim 10^{-14}$ rad/s per rad.
const FD_STEP_RAD: f64 = 1e-6;

/// Analytic vs central-difference Jacobian, relative to the largest entry of M
/// (dimensionless): truncation plus rounding, both far below this.
const JACOBIAN_REL: f64 = 1e-7;

/// Absolute floor of the Jacobian comparison, rad/s per rad: readings whose error is
/// identically zero (intended outputs, nominal rate) give differences of rounding,
/// $10^{-20}/h = 10^{-14}$.
const JACOBIAN_FLOOR: f64 = 1e-12;

/// A load counts as active when within this of 1 (alloc-opt's exchange method ends within
/// $10^{-13}$, `TIGHT_REL` is $10^{-9}$). Dimensionless.
const ACTIVE_REL: f64 = 1e-9;

/// Loads may exceed 1 by rounding only. Dimensionless.
const FEASIBLE_REL: f64 = 1e-12;

/// Relative tolerance on published/golden numbers of this crate's findings (4 digits).
const GOLDEN_REL: f64 = 1e-3;

fn omega_m() -> f64 {
    deg_per_h_to_rad_per_s(0.01)
}

fn two_step_ub() -> [f64; CHI_LEN] {
    SensitivityWeighted::paper()
        .allocate(&AllocationProblem::paper_example().unwrap())
        .unwrap()
        .upper_bounds_rad
}

fn beta1_residual_readings() -> Vec<Reading> {
    Reading::all()
        .into_iter()
        .filter(|r| r.estimate == Estimate::Beta1 && r.form != ErrorForm::DeltaBeta)
        .collect()
}

fn random_chi(rng: &mut ChaCha8Rng, ub: &[f64; CHI_LEN]) -> [f64; CHI_LEN] {
    std::array::from_fn(|j| {
        let u = f64::from(rng.next_u32()) / f64::from(u32::MAX);
        (2.0 * u - 1.0) * ub[j]
    })
}

/// gw-model's $\mathbf R_d = R_y(\phi_1)R_z(\phi_2)$ (eq 21, `Position::base_from_body`) is
/// tt-kinematics' ideal rotation $\mathbf R_d$ (eq 21, `ideal_transform`), and the actual
/// inputs of eq 8 with $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ (eq 23) are the base-frame
/// gravity and earth rate seen in the actual turntable frame $\mathbf R_t$ (eq 22).
#[test]
fn position_convention_matches_turntable_chain_eq21_eq23() {
    let site = Site::paper_default();
    let chi =
        TurntableErrors::from_arcmin([0.4, -0.8, 0.3, 0.7, -0.2, 0.25, -0.4, 0.35], 0.0).unwrap();
    for (p1, p2) in [
        (0.0, 0.0),
        (30.0, 45.0),
        (90.0, 135.0),
        (200.0, 315.0),
        (-75.0, 10.0),
    ] {
        let pos = Position::from_deg(p1, p2).unwrap();
        let pose = Pose::from_deg(p1, p2).unwrap();
        let rd_tt = ideal_transform(&pose).fixed_view::<3, 3>(0, 0).into_owned();
        assert_abs_diff_eq!(pos.base_from_body(), rd_tt, epsilon = ROTATION_ABS);
        let rt = actual_transform(&pose, &chi, ChainKind::Exact)
            .fixed_view::<3, 3>(0, 0)
            .into_owned();
        let dr = delta_r(&pose, &chi, ChainKind::Exact);
        let actual = site.inputs_with_error(&pos, &dr);
        assert_abs_diff_eq!(
            actual.specific_force_g,
            rt.transpose() * site.specific_force_base_g(),
            epsilon = ROTATION_ABS
        );
        assert_abs_diff_eq!(
            actual.rate_rad_per_s,
            rt.transpose() * site.earth_rate_base_rad_per_s(),
            epsilon = ROTATION_ABS * 1e-4
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The factored chain $R_z(\phi_2)^T\mathbf U R_z(\phi_2)\mathbf V$ equals
    /// tt-kinematics' exact $\Delta\mathbf R$ (eq 23) at every position, for errors up to
    /// 0.5 deg.
    #[test]
    fn factored_chain_equals_tt_kinematics_exact_delta_r(
        chi in prop::array::uniform8(-8.7e-3_f64..8.7e-3)
    ) {
        let e2e = EndToEnd::paper(Reading::PAPER);
        let fast = e2e.delta_r_fast(&chi);
        let reference = e2e.delta_r_reference(&chi).unwrap();
        for (f, r) in fast.iter().zip(&reference) {
            prop_assert!((f - r).amax() < ROTATION_ABS, "{}", (f - r).amax());
        }
    }

    /// The exact end-to-end error never leaves the linearised value by more than the derived
    /// second-order bound, at any point of a box up to 10x Table 4 (PAPER and USER readings).
    #[test]
    fn exact_error_within_second_order_bound_of_linearisation(
        u in prop::array::uniform8(-1.0_f64..1.0),
        scale in 1.0_f64..10.0,
        user in any::<bool>(),
    ) {
        let reading = if user { Reading::USER } else { Reading::PAPER };
        let e2e = EndToEnd::paper(reading);
        let lin = e2e.linearization();
        let ub = paper_table4_rad().map(|v| v * scale);
        let chi: [f64; CHI_LEN] = std::array::from_fn(|j| u[j] * ub[j]);
        let s: f64 = chi.iter().map(|v| v.abs()).sum();
        let exact = e2e.error_vectors(&chi).unwrap();
        let linear = lin.matrix() * nalgebra::SVector::<f64, CHI_LEN>::from(chi);
        let n = e2e.len();
        for (k, axis) in [SensingAxis::X, SensingAxis::Y].into_iter().enumerate() {
            let tau = e2e.second_order_bound(axis, s).unwrap().unwrap();
            let diff = (&exact[k] - linear.rows(k * n, n)).amax();
            prop_assert!(diff <= tau, "{axis:?}: remainder {diff} > tau {tau}");
        }
    }
}

/// The fast path (precomputed $\mathbf A^+$) gives calib-lsq's eq 7-14 error vectors for
/// every reading with the user's estimate $\hat\beta_1$ and a residual form.
#[test]
fn fast_path_equals_calib_lsq_analysis_for_every_beta1_reading() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let ub = paper_table4_rad().map(|v| 3.0 * v);
    let readings = beta1_residual_readings();
    assert_eq!(readings.len(), 8);
    for reading in readings {
        let e2e = EndToEnd::paper(reading);
        assert!(e2e.has_fast_path());
        for _ in 0..5 {
            let chi = random_chi(&mut rng, &ub);
            let fast = e2e.error_vectors(&chi).unwrap();
            let run = e2e.run(&chi).unwrap();
            for (f, a) in fast.iter().zip(&run.analyses) {
                let d = (f - &a.error_vector).amax();
                assert!(d < RATE_ABS_RAD_PER_S, "{reading}: {d}");
            }
        }
    }
}

/// A perfect turntable ($\chi = 0$) gives zero end-to-end error in every reading of eq 13.
#[test]
fn zero_turntable_error_gives_zero_rate_error_in_every_reading() {
    for reading in Reading::all() {
        let e2e = EndToEnd::paper(reading);
        let run = e2e.run(&[0.0; CHI_LEN]).unwrap();
        for v in run.delta_omega_rad_per_s() {
            assert_abs_diff_eq!(v, 0.0, epsilon = ZERO_RATE_ABS_RAD_PER_S);
        }
        for v in e2e.delta_omega(&[0.0; CHI_LEN]).unwrap() {
            assert_abs_diff_eq!(v, 0.0, epsilon = ZERO_RATE_ABS_RAD_PER_S);
        }
    }
}

/// §2.2: with one constant orientation error at every position the end-to-end error equals
/// calib-lsq's §2 analysis (`RequirementProblem::rate_error`, eq 7-14), for both matrix kinds
/// and the PAPER and USER readings.
#[test]
fn constant_orientation_error_equals_section_2_analysis() {
    let angles = OrientationAngles::from_deg(0.02, -0.015, 0.025).unwrap();
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = EndToEnd::paper(reading);
        for kind in [DeltaRKind::SmallAngle, DeltaRKind::Exact] {
            let problem = RequirementProblem {
                reading,
                delta_r_kind: kind,
                ..RequirementProblem::paper()
            };
            let dr = vec![angles.delta_r(kind); e2e.len()];
            let got = e2e.delta_omega_for_delta_r(&dr).unwrap();
            for (k, axis) in [SensingAxis::X, SensingAxis::Y].into_iter().enumerate() {
                let want = problem.rate_error(axis, &angles).unwrap();
                assert!(want > 0.0);
                assert_abs_diff_eq!(got[k], want, epsilon = RATE_ABS_RAD_PER_S);
            }
        }
    }
}

/// The analytic Jacobian (eq 26 chained with the derivative of eq 8-13) equals central
/// differences of calib-lsq's analysis on the exact chain, for every reading of eq 13.
#[test]
fn analytic_jacobian_matches_central_differences_for_every_reading() {
    for reading in Reading::all() {
        let e2e = EndToEnd::paper(reading);
        let a = e2e.linearization();
        let nmat = e2e.linearization_numerical(FD_STEP_RAD).unwrap();
        let scale = a.matrix().amax();
        let d = (a.matrix() - nmat.matrix()).amax();
        assert!(
            d <= JACOBIAN_REL * scale + JACOBIAN_FLOOR,
            "{reading}: {d} vs {scale}"
        );
    }
}

/// The PAPER reading's error is minus the earth-rate perturbation (calib-lsq's analysis), so
/// its rows are $(\boldsymbol\delta\times\boldsymbol\omega)_{x,y}$ with eq 26's
/// $\boldsymbol\delta$: $M_{x,i} = \omega_z\,\partial\Delta\psi - \omega_y\,\partial\Delta\theta$.
#[test]
fn paper_reading_rows_are_the_earth_rate_cross_product() {
    let e2e = EndToEnd::paper(Reading::PAPER);
    let lin = e2e.linearization();
    let model = tt_kinematics::LinearModel::paper_eq26();
    for (i, (pose, inp)) in e2e.poses().iter().zip(e2e.nominal_inputs()).enumerate() {
        let k = model.coefficients(pose.phi2_rad);
        let w = inp.rate_rad_per_s;
        for j in 0..CHI_LEN {
            let delta = Vector3::new(k[(2, j)], k[(0, j)], k[(1, j)]);
            let c = delta.cross(&w);
            assert_abs_diff_eq!(lin.row(SensingAxis::X, i)[j], c.x, epsilon = 1e-20);
            assert_abs_diff_eq!(lin.row(SensingAxis::Y, i)[j], c.y, epsilon = 1e-20);
        }
    }
}

/// The worst vertex of the linearised model, re-evaluated on the exact chain, lies within the
/// derived second-order term of the linear bound (Table 4, the two-step optimum and 10x
/// Table 4; PAPER and USER readings).
#[test]
fn exact_worst_case_within_second_order_term_of_linear_vertex_bound() {
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = EndToEnd::paper(reading);
        let lin = e2e.linearization();
        // (box, largest tau / linear bound): tau is second order, a few % at Table 4's size
        // and 10x that at 10x the size.
        for (ub, tau_share) in [
            (paper_table4_rad(), 0.05),
            (two_step_ub(), 0.05),
            (paper_table4_rad().map(|v| 10.0 * v), 0.5),
        ] {
            let wc = e2e.worst_case(&lin, &ub).unwrap();
            for a in &wc.axes {
                let tau = a.second_order_bound_rad_per_s.unwrap();
                assert!(tau < tau_share * a.linear_bound_rad_per_s, "tau {tau}");
                assert!(a.exact_at_vertex_rad_per_s <= a.linear_bound_rad_per_s + tau);
                assert!(a.exact_at_vertex_rad_per_s >= a.linear_bound_rad_per_s - tau);
                // The vertex really is the linear worst case of its row.
                let row = lin.row(a.axis, a.position);
                let v: f64 = row.iter().zip(&a.worst_chi_rad).map(|(m, c)| m * c).sum();
                assert_relative_eq!(v.abs(), a.linear_bound_rad_per_s, max_relative = 1e-12);
            }
        }
    }
}

/// The buyer's answer (finding of this crate): under the PAPER reading Table 4's worst
/// turntable calibrates to 0.00834 deg/h (the square requirement of eq 16 wastes 17% of
/// omega_m); under the USER reading it gives 0.01593 deg/h on x, above omega_m = 0.01 deg/h.
#[test]
fn table4_meets_omega_m_in_paper_reading_but_not_in_user_reading() {
    let paper = EndToEnd::paper(Reading::PAPER);
    let wc = paper
        .worst_case(&paper.linearization(), &paper_table4_rad())
        .unwrap();
    let [x, y] = wc.exact_deg_per_h();
    assert_relative_eq!(x, 0.008337, max_relative = GOLDEN_REL);
    assert_relative_eq!(y, 0.008337, max_relative = GOLDEN_REL);
    let user = EndToEnd::paper(Reading::USER);
    let wc = user
        .worst_case(&user.linearization(), &paper_table4_rad())
        .unwrap();
    let [x, y] = wc.exact_deg_per_h();
    assert_relative_eq!(x, 0.015935, max_relative = GOLDEN_REL);
    assert_relative_eq!(y, 0.012451, max_relative = GOLDEN_REL);
    assert!(x > 0.01 && y > 0.01);
}

/// Direct allocation: the linearised worst case meets omega_m with equality on the active rows
/// (positions) and is below it elsewhere; the exact chain confirms within the second-order
/// term; and it is cheaper than the two-step optimum and Table 4 under the PAPER reading.
#[test]
fn direct_allocation_meets_omega_m_with_equality_on_active_positions() {
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = EndToEnd::paper(reading);
        let lin = e2e.linearization();
        let d = e2e
            .allocate_direct(&lin, omega_m(), &[0.0; CHI_LEN])
            .unwrap();
        let active = d.active_rows();
        assert!(!active.is_empty());
        assert!(active.len() < d.loads.len());
        for r in &d.loads {
            assert!(r.load <= 1.0 + FEASIBLE_REL, "{r:?}");
            if r.load >= 1.0 - ACTIVE_REL {
                assert_abs_diff_eq!(r.load, 1.0, epsilon = ACTIVE_REL);
            }
        }
        let wc = e2e.worst_case(&lin, &d.upper_bounds_rad).unwrap();
        for a in &wc.axes {
            assert_relative_eq!(
                a.linear_bound_rad_per_s,
                omega_m(),
                max_relative = ACTIVE_REL
            );
            let tau = a.second_order_bound_rad_per_s.unwrap();
            assert!(a.exact_at_vertex_rad_per_s <= omega_m() + tau);
        }
        assert_relative_eq!(d.objective, paper_objective(&d.upper_bounds_rad));
    }
    let e2e = EndToEnd::paper(Reading::PAPER);
    let d = e2e
        .allocate_direct(&e2e.linearization(), omega_m(), &[0.0; CHI_LEN])
        .unwrap();
    assert!(d.objective < paper_objective(&two_step_ub()));
    assert!(d.objective < paper_objective(&paper_table4_rad()));
}

/// The certified direct allocation leaves room for the derived second-order term: its
/// linearised worst case plus tau is within omega_m, so the exact chain meets omega_m at the
/// worst vertex (where the plain direct allocation exceeds it by a second-order amount); it
/// costs a little more than the plain one.
#[test]
fn certified_direct_allocation_meets_omega_m_on_exact_chain() {
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = EndToEnd::paper(reading);
        let lin = e2e.linearization();
        let plain = e2e
            .allocate_direct(&lin, omega_m(), &[0.0; CHI_LEN])
            .unwrap();
        let cert = e2e
            .allocate_direct_certified(&lin, omega_m(), &[0.0; CHI_LEN])
            .unwrap();
        let tau = cert.second_order_margin_rad_per_s;
        assert!(tau > 0.0);
        let wc = e2e.worst_case(&lin, &cert.upper_bounds_rad).unwrap();
        for a in &wc.axes {
            let t = a.second_order_bound_rad_per_s.unwrap();
            assert!(a.linear_bound_rad_per_s + t <= omega_m());
            assert!(a.exact_at_vertex_rad_per_s <= omega_m());
        }
        assert!(cert.objective > plain.objective);
        assert!(cert.objective < plain.objective * (1.0 + 20.0 * tau / omega_m()));
        let max_load = cert.loads.iter().map(|l| l.load).fold(0.0, f64::max);
        assert_relative_eq!(max_load, 1.0 - tau / omega_m(), max_relative = 1e-9);
    }
}

/// The combined weights reproduce alloc-opt's objective $J_\psi + J_\theta + J_\gamma$
/// (eq 28 weights), so direct and two-step objectives are comparable.
#[test]
fn combined_weights_reproduce_alloc_opt_objective() {
    let w = Weights::inverse_average_sensitivity(&tt_kinematics::LinearModel::paper_eq26());
    for ub in [paper_table4_rad(), two_step_ub()] {
        assert_relative_eq!(paper_objective(&ub), w.objective(&ub), max_relative = 1e-14);
    }
}

/// KKT by perturbation: no feasible neighbour of the direct allocation has a lower objective
/// (the problem is convex, so this checks optimality).
#[test]
fn direct_allocation_is_optimal_under_feasible_perturbations() {
    let e2e = EndToEnd::paper(Reading::USER);
    let lin = e2e.linearization();
    let d = e2e
        .allocate_direct(&lin, omega_m(), &[0.0; CHI_LEN])
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..300 {
        let x: [f64; CHI_LEN] = std::array::from_fn(|j| {
            let u = f64::from(rng.next_u32()) / f64::from(u32::MAX) - 0.5;
            d.upper_bounds_rad[j] * (2e-3 * u).exp()
        });
        let load = lin.row_worst_cases(&x).max() / omega_m();
        let x = x.map(|v| v / load.max(1.0));
        let j = paper_objective(&x);
        assert!(j >= d.objective * (1.0 - 1e-10), "{j} < {}", d.objective);
    }
}

/// Yield-based allocation: the yield at the chosen scale, re-measured with another seed
/// (and 2x the draws), lies within the allocation's stated 95% Wilson interval; it is cheaper
/// than the worst-case (direct) allocation.
#[test]
fn yield_remeasured_with_other_seed_within_stated_interval() {
    let e2e = EndToEnd::paper(Reading::PAPER);
    let lin = e2e.linearization();
    let d = e2e
        .allocate_direct(&lin, omega_m(), &[0.0; CHI_LEN])
        .unwrap();
    let y = e2e
        .allocate_yield(
            &d.upper_bounds_rad,
            &[0.0; CHI_LEN],
            omega_m(),
            0.9973,
            &McSettings::new(20_000, 1),
        )
        .unwrap();
    let (lo, hi) = y.interval_95;
    assert!(lo <= 0.9973 && 0.9973 <= hi, "{lo} {hi}");
    // At least ceil(p N) design draws meet omega_m, and not many more (the scale is the
    // largest: the quantile draw sits on omega_m).
    assert!(y.meeting >= 19_946 && y.meeting <= 19_948, "{}", y.meeting);
    let again = e2e
        .rate_distribution(
            &ErrorBox::from_upper_rad(y.upper_bounds_rad).unwrap(),
            omega_m(),
            &McSettings::new(40_000, 99),
        )
        .unwrap();
    let f = again.yield_fraction();
    assert!(lo <= f && f <= hi, "{f} outside [{lo}, {hi}]");
    assert!(y.scale > 1.0);
    assert!(y.objective < d.objective);
}

/// With positive lower bounds the scale is bisected with common random numbers and the design
/// yield reaches the target.
#[test]
fn yield_allocation_with_lower_bounds_reaches_target() {
    let e2e = EndToEnd::paper(Reading::PAPER);
    let lin = e2e.linearization();
    let lb = [0.05 * RAD_PER_ARCMIN; CHI_LEN];
    let d = e2e.allocate_direct(&lin, omega_m(), &lb).unwrap();
    let settings = McSettings::new(2_000, 3);
    let y = e2e
        .allocate_yield(&d.upper_bounds_rad, &lb, omega_m(), 0.99, &settings)
        .unwrap();
    assert!(y.yield_fraction() >= 0.99);
    for (u, l) in y.upper_bounds_rad.iter().zip(&lb) {
        assert!(u >= l);
    }
    // A slightly larger scale falls below the target (the scale is the largest one).
    let bigger = y.upper_bounds_rad.map(|v| v * 1.02);
    let dist = e2e
        .rate_distribution(&ErrorBox::new(lb, bigger).unwrap(), omega_m(), &settings)
        .unwrap();
    assert!(dist.yield_fraction() < 0.99);
}

/// The Monte Carlo draws are mc-verify's: chunk `c` is `chunk_rng(seed, c)` drawn by
/// `TurntableSampler::fill_block` in blocks of `BLOCK_CAPACITY`; results are bit-identical for
/// 1 and 3 threads.
#[test]
fn monte_carlo_reuses_mc_verify_streams_and_is_thread_count_independent() {
    let e2e = EndToEnd::paper(Reading::USER);
    let bounds = ErrorBox::from_upper_rad(paper_table4_rad()).unwrap();
    let settings = McSettings {
        chunk_size: 300,
        ..McSettings::new(500, 42)
    };
    // Sample 0, and sample 433 = sample 128 + 5 of chunk 1 (500 draws in chunks of 300: chunk 1
    // holds 200 = blocks of 128 + 72).
    let sampler = TurntableSampler::new(&bounds);
    let mut block = SampleBlock::default();
    sampler.fill_block(&mut chunk_rng(42, 0), BLOCK_CAPACITY, &mut block);
    let chi0 = block.chi_rad(0);
    let mut rng = chunk_rng(42, 1);
    sampler.fill_block(&mut rng, BLOCK_CAPACITY, &mut block);
    sampler.fill_block(&mut rng, 72, &mut block);
    let chi_433 = block.chi_rad(5);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| e2e.sample_rates(&bounds, &settings).unwrap())
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(one.len(), 500);
    assert_eq!(one[0].chi_rad.map(f64::to_bits), chi0.map(f64::to_bits));
    assert_eq!(
        one[433].chi_rad.map(f64::to_bits),
        chi_433.map(f64::to_bits)
    );
    for (a, b) in one.iter().zip(&three) {
        assert_eq!(
            a.delta_omega_rad_per_s.map(f64::to_bits),
            b.delta_omega_rad_per_s.map(f64::to_bits)
        );
        assert_eq!(a.chi_rad.map(f64::to_bits), b.chi_rad.map(f64::to_bits));
    }
    // The expected value of the first draw through the calibration.
    assert_eq!(
        one[0].delta_omega_rad_per_s.map(f64::to_bits),
        e2e.delta_omega(&chi0).unwrap().map(f64::to_bits)
    );
}

/// Distribution summary: quantiles ordered, histogram counts add up, yield consistent.
#[test]
fn rate_distribution_summary_is_consistent() {
    let e2e = EndToEnd::paper(Reading::USER);
    let bounds = ErrorBox::from_upper_rad(paper_table4_rad()).unwrap();
    let dist = e2e
        .rate_distribution(&bounds, omega_m(), &McSettings::new(3_000, 8))
        .unwrap();
    for h in &dist.histogram_counts {
        assert_eq!(h.iter().sum::<u64>(), 3_000);
    }
    for w in dist.quantiles.windows(2) {
        for k in 0..3 {
            assert!(w[0].rad_per_s[k] <= w[1].rad_per_s[k]);
        }
    }
    let last = dist.quantiles.last().unwrap();
    assert_eq!(last.rad_per_s[0].to_bits(), dist.max_rad_per_s[0].to_bits());
    assert!(dist.yield_fraction() > 0.5 && dist.yield_fraction() < 1.0);
    // No drawn turntable exceeds the exact worst case bound (linear + tau).
    let wc = e2e
        .worst_case(&e2e.linearization(), &paper_table4_rad())
        .unwrap();
    for (k, a) in wc.axes.iter().enumerate() {
        let bound = a.linear_bound_rad_per_s + a.second_order_bound_rad_per_s.unwrap();
        assert!(dist.max_rad_per_s[k] <= bound);
    }
    assert!(rad_per_s_to_deg_per_h(dist.max_rad_per_s[0]) > 0.01);
}

/// Wilson interval: known values (0 of 10: upper 0.2775; 5 of 10: 0.2366..0.7634).
#[test]
fn wilson_interval_known_values() {
    let (lo, hi) = wilson_interval_95(0, 10);
    assert_abs_diff_eq!(lo, 0.0);
    assert_abs_diff_eq!(hi, 0.2775, epsilon = 1e-4);
    let (lo, hi) = wilson_interval_95(5, 10);
    assert_abs_diff_eq!(lo, 0.2366, epsilon = 1e-4);
    assert_abs_diff_eq!(hi, 0.7634, epsilon = 1e-4);
}

/// Bad input gives typed errors naming the field: LB > UB, negative and non-finite bounds,
/// zero samples, a yield fraction outside (0, 1), non-positive omega_m, non-finite chi,
/// infeasible lower bounds, a bad difference step.
#[test]
fn bad_input_gives_typed_errors_naming_the_field() {
    let e2e = EndToEnd::paper(Reading::PAPER);
    let lin = e2e.linearization();
    let ub = paper_table4_rad();
    // LB above Table 4's UB for deps_x (0.45' > 0.4234'), feasible for the two-step problem.
    let mut inputs = EndToEndInputs::paper();
    inputs.lower_bounds_rad[ErrorComponent::DepsX.index()] = 0.45 * RAD_PER_ARCMIN;
    let err = e2e_verify::answer(&inputs).unwrap_err();
    assert!(
        matches!(
            err,
            E2eError::Bounds(McError::LowerAboveUpper {
                component: "deps_x",
                ..
            })
        ),
        "{err:?}"
    );
    let mut bad = ub;
    bad[1] = -1e-4;
    let err = e2e.worst_case(&lin, &bad).unwrap_err();
    assert!(matches!(
        err,
        E2eError::Bounds(McError::NegativeBound {
            component: "dphi_z2",
            ..
        })
    ));
    bad[1] = f64::NAN;
    let err = e2e.worst_case(&lin, &bad).unwrap_err();
    assert!(matches!(
        err,
        E2eError::Bounds(McError::NonFiniteBound {
            component: "dphi_z2",
            ..
        })
    ));
    let box_ = ErrorBox::from_upper_rad(ub).unwrap();
    let err = e2e
        .rate_distribution(&box_, omega_m(), &McSettings::new(0, 1))
        .unwrap_err();
    assert_eq!(err, E2eError::ZeroSamples { field: "samples" });
    for p in [0.0, 1.0, -0.5, f64::NAN] {
        let err = e2e
            .allocate_yield(&ub, &[0.0; CHI_LEN], omega_m(), p, &McSettings::new(10, 1))
            .unwrap_err();
        assert!(
            matches!(
                err,
                E2eError::FractionOutOfRange {
                    field: "yield_fraction",
                    ..
                }
            ),
            "{err:?}"
        );
    }
    let err = e2e.allocate_direct(&lin, 0.0, &[0.0; CHI_LEN]).unwrap_err();
    assert!(matches!(err, E2eError::NotPositive { ref field, .. } if field == "omega_m"));
    let err = e2e
        .delta_omega(&[0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap_err();
    assert!(matches!(err, E2eError::NonFinite { ref field, .. } if field == "chi.dphi_z2"));
    let err = e2e
        .allocate_direct(&lin, omega_m(), &[10.0 * RAD_PER_ARCMIN; CHI_LEN])
        .unwrap_err();
    assert!(
        matches!(err, E2eError::InfeasibleLowerBounds { .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("lower bounds"));
    let err = e2e.linearization_numerical(0.0).unwrap_err();
    assert!(matches!(
        err,
        E2eError::OutOfRange {
            field: "step_rad",
            ..
        }
    ));
    let mut inputs = EndToEndInputs::paper();
    inputs.samples = 0;
    assert_eq!(
        inputs.validate().unwrap_err(),
        E2eError::ZeroSamples { field: "samples" }
    );
    let mut inputs = EndToEndInputs::paper();
    inputs.yield_fraction = 1.5;
    assert!(matches!(
        inputs.validate().unwrap_err(),
        E2eError::FractionOutOfRange {
            field: "yield_fraction",
            ..
        }
    ));
    let mut inputs = EndToEndInputs::paper();
    inputs.lower_bounds_rad[0] = -1.0;
    assert!(matches!(
        inputs.validate().unwrap_err(),
        E2eError::Bounds(McError::NegativeBound {
            component: "dphi_y1",
            ..
        })
    ));
    let wrong_len = vec![Matrix3::identity(); 3];
    assert!(matches!(
        e2e.delta_omega_for_delta_r(&wrong_len).unwrap_err(),
        E2eError::Calib(_)
    ));
}
