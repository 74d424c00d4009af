//! The proof of issue 20 item 1, end to end: the az/el mount (not a `Turntable`) calibrates a
//! sensor of our own through e2e-verify's public API: the linearisation, the worst case with
//! its second-order bound, the certified direct allocation and the Monte Carlo over the box.

use approx::assert_relative_eq;
use azel::{AzElMount, at_poses, base_from_sensor};
use calib_lsq::{Calibration, Position, Reading, Schedule};
use e2e_verify::{EndToEnd, McSettings};
use gw_model::{Input, Output, Regressor, SensorModel, Site, Term};
use tt_kinematics::AtPoses;

/// Relative agreement of the model's Jacobian with central differences of step 1e-6 rad on
/// the exact chain: truncation O(h^2) ~ 1e-12 relative, rounding ~ 1e-16/1e-6 = 1e-10 of the
/// outputs' size (deg/h) over the coefficients' size.
const JACOBIAN_REL: f64 = 1e-6;

/// Rounding of the calibration of a perfect mount (deg/h): the precision bound of the
/// simulator is about 1e-11 deg/h for this sensor.
const PERFECT_ABS_DEG_PER_H: f64 = 1e-10;

/// Our own single-axis rate sensor: the rate about x (known) plus a bias and two
/// g-sensitivities (estimated), in deg/h; accuracy 0.01 deg/h.
fn sensor() -> SensorModel {
    let term = |name: &str, regressor, value, known| Term {
        coefficient: name.into(),
        regressor,
        value,
        known,
    };
    SensorModel::new(vec![Output {
        name: "x".into(),
        unit: "deg_per_h".into(),
        accuracy: 0.01,
        terms: vec![
            term("omega_x", Regressor::input(Input::Wx), 1.0, true),
            term("bias", Regressor::ONE, 0.5, false),
            term("g_x", Regressor::input(Input::Ax), 1.0, false),
            term("g_z", Regressor::input(Input::Az), 0.8, false),
        ],
    }])
    .unwrap()
}

/// Twelve positions: azimuth every 90 deg at elevations 0, 45 and 90 deg.
fn setup() -> EndToEnd<AtPoses<AzElMount>> {
    let poses: Vec<[f64; 2]> = [0.0_f64, 45.0, 90.0]
        .iter()
        .flat_map(|e| [0.0_f64, 90.0, 180.0, 270.0].map(|a| [a.to_radians(), e.to_radians()]))
        .collect();
    let mount = at_poses(&poses).unwrap();
    let positions = base_from_sensor(&poses)
        .into_iter()
        .zip(&poses)
        .map(|(r, p)| Position::new(r, vec![p[0].to_degrees(), p[1].to_degrees()]).unwrap())
        .collect();
    let site = Site::from_deg(30.0, 7.292_115_9e-5).unwrap();
    let cal = Calibration::new(&sensor(), &site, &Schedule::new(positions).unwrap()).unwrap();
    EndToEnd::for_model(mount, &cal, Reading::USER).unwrap()
}

#[test]
fn a_perfect_mount_calibrates_the_sensor_exactly() {
    let e2e = setup();
    assert_eq!(
        e2e.error_names(),
        ["az_tilt", "el_offset", "non_perp", "flexure"]
    );
    let dw = e2e.delta_omega(&[0.0; 4]).unwrap();
    assert!(dw[0] <= PERFECT_ABS_DEG_PER_H, "{dw:?}");
}

#[test]
fn the_flexure_column_is_the_elevation_offset_column_times_cos_el() {
    // to first order the flexure is an elevation error chi_3 cos e: at every position its
    // column of M is cos(e_i) times the encoder offset's (closed form, crate docs)
    let e2e = setup();
    let m = e2e.linearization();
    for i in 0..e2e.len() {
        let e = [0.0_f64, 45.0, 90.0][i / 4].to_radians();
        let (off, flex) = (m.matrix()[(i, 1)], m.matrix()[(i, 3)]);
        // (both columns derived by central differences: relative error ~1e-10, 1e-8 bounds it
        // as tt_kinematics::DERIVED_FIRST_ORDER_TOLERANCE does)
        assert_relative_eq!(flex, e.cos() * off, epsilon = 1e-8 * off.abs().max(1.0));
    }
    // and the (derived) Jacobian is the derivative of the exact chain
    let numeric = e2e.linearization_numerical(1e-6).unwrap();
    let scale = m.matrix().amax();
    for (a, b) in m.matrix().iter().zip(numeric.matrix().iter()) {
        assert!((a - b).abs() <= JACOBIAN_REL * scale, "{a} vs {b}");
    }
}

#[test]
fn the_certified_direct_box_meets_the_accuracy_on_the_exact_chain_and_in_the_monte_carlo() {
    let e2e = setup();
    let linear = e2e.linearization();
    let alloc = e2e.allocate_direct_certified(&linear, &[0.0; 4]).unwrap();
    let ub = alloc.upper_bounds_rad();
    // every error the output sees gets a finite, positive bound. The non-perpendicularity
    // turns the platform about (cos e, 0, sin e): gravity moves along y only (no a_y term),
    // and the earth rate's effect on omega_x, chi_2 sin(e) omega_y, changes sign with the
    // azimuth (omega_y ~ -sin a) while a_x and a_z do not depend on it, so it is orthogonal to
    // the regressors and leaves the estimate unchanged: no bound is needed for it.
    for j in [0, 1, 3] {
        assert!(ub[j].is_finite() && ub[j] > 0.0, "{ub:?}");
    }
    assert!(ub[2].is_infinite(), "{ub:?}");
    // the unbounded error is held at 0 by the library: the mount's angle-sum bound (a plain
    // sum) never sees +inf (before, this failed with "l1_norm_rad must be finite, got inf")
    let worst = e2e.worst_case(&linear, ub).unwrap();
    let out = &worst.outputs()[0];
    let certified = out
        .certified_bound()
        .expect("the mount declares its angle-sum bound");
    assert!(certified <= 0.01, "certified {certified}");
    assert!(out.exact_at_vertex() <= certified, "{out:?}");
    // the linear worst case is the active constraint of the allocation (to its margin)
    assert!(out.linear_bound() >= 0.5 * 0.01, "{out:?}");
    // every drawn mount of the box meets the accuracy, and none exceeds the certified bound
    let bounds = e2e.box_of(ub, &[0.0; 4]).unwrap();
    let mc = e2e
        .monte_carlo()
        .rate_distribution(&linear, &bounds, &McSettings::new(20_000, 7))
        .unwrap();
    // (every draw meets: the yield is n/n exactly)
    assert!(mc.count().fraction() >= 1.0, "{}", mc.count().fraction());
    assert!(mc.max()[0] <= certified, "{:?} vs {certified}", mc.max());
}

#[test]
fn a_callers_certify_params_keep_the_share_of_the_accuracy_it_asks_for() {
    // the knobs are a parameter struct with Default: keeping 20% of the accuracy free for a
    // decimal round trip leaves a box whose certified bound is within 80% of it, and costs more
    let e2e = setup();
    let linear = e2e.linearization();
    let default = e2e.allocate_direct_certified(&linear, &[0.0; 4]).unwrap();
    let mut params = e2e_verify::CertifyParams::default();
    params.round_trip_rel = 0.2;
    let tight = e2e
        .allocate_direct_certified_with(&linear, &[0.0; 4], &params)
        .unwrap();
    let worst = e2e.worst_case(&linear, tight.upper_bounds_rad()).unwrap();
    let certified = worst.outputs()[0].certified_bound().unwrap();
    assert!(certified <= 0.8 * 0.01, "{certified}");
    assert!(tight.objective() > default.objective());
}

/// Issue 20 item 1 end to end: the mount's own end-to-end problem goes through alloc-opt's one
/// `Allocator` seam with the library's direct and certified methods and our own
/// `UniformBound`, all answering with a `ToleranceBox` whose certificate holds against the
/// accuracy; the library's direct box is the cheapest of them (it minimises J, which the
/// uniform bound does not).
#[test]
fn the_mounts_end_to_end_problem_goes_through_the_one_allocator_seam() {
    use alloc_opt::Allocator;
    let e2e = setup();
    let problem = e2e
        .allocation_problem(e2e.linearization(), vec![0.0; 4])
        .unwrap();
    let direct = e2e_verify::Direct::new(&e2e).allocate(&problem).unwrap();
    let certified = e2e_verify::DirectCertified::new(&e2e)
        .allocate(&problem)
        .unwrap();
    let uniform = azel::UniformBound.allocate(&problem).unwrap();
    for b in [&direct, &certified, &uniform] {
        assert!(b.certificate().lemma1_holds(), "{}", b.method());
        // the azimuth non-perpendicularity needs no bound (see the certified test above)
        assert!(b.upper_bounds_rad()[2].is_infinite(), "{}", b.method());
        assert_eq!(b.error_names(), e2e.error_names().as_slice());
    }
    assert!(direct.objective() <= certified.objective());
    assert!(direct.objective() <= uniform.objective());
    // the direct box equals the crate's own direct allocation
    let own = e2e
        .allocate_direct(&e2e.linearization(), &[0.0; 4])
        .unwrap();
    assert_eq!(direct.upper_bounds_rad(), own.upper_bounds_rad());
}
