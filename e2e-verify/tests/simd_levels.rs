//! The per-turntable chain and calibration of the end-to-end Monte Carlo, compiled per SIMD
//! level (runtime dispatch through `mc_verify::simd`), give the portable level's
//! $\Delta\omega_k$ bit for bit: only the vector width changes. On a CPU without AVX2 only the
//! portable level runs (the test says so).

mod common;

use calib_lsq::{Calibration, Reading};
use common::{paper, poses_of, study_e2e};
use e2e_verify::{E2eError, EndToEnd};
use mc_verify::{McError, SimdLevel};

/// Angular errors for draw `d`: a few arcmin of either sign, different per error and draw.
fn chi(e2e: &EndToEnd, d: usize) -> Vec<f64> {
    (0..e2e.n_errors())
        .map(|j| 1e-3 * (((d * 31 + j * 17) % 23) as f64 / 11.0 - 1.0))
        .collect()
}

/// The simulators compared: the paper's study under both readings (32 positions, a whole
/// number of lanes), the paper's table on a 3 x 7 grid (21 positions: a short last group of
/// the chain and a short last block of the calibration), the IMU example (three-axis table,
/// accelerometers and gyros, the user's reading) and the three-axis example.
fn simulators() -> Vec<(String, EndToEnd)> {
    let grid = calib_lsq::paper::grid(
        &[0.0, 90.0, 180.0],
        &[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0],
    )
    .expect("a valid grid");
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &grid,
    )
    .expect("the grid identifies every coefficient");
    let poses = poses_of(&cal);
    let mut v = Vec::new();
    for reading in [Reading::PAPER, Reading::USER] {
        v.push((format!("paper, {reading}"), paper(reading)));
        let e2e = EndToEnd::new(&tt_kinematics::paper::table3(), &cal, &poses, reading)
            .expect("grid simulator");
        v.push((format!("paper table on a 21-position grid, {reading}"), e2e));
        v.push((
            format!("three-axis example, {reading}"),
            study_e2e("three-axis-example", Some(reading)),
        ));
    }
    v.push((
        "IMU example (its reading)".into(),
        study_e2e("imu-triad-example", None),
    ));
    v
}

/// Every level this CPU has gives the portable level's $\Delta\omega_k$ for every output, bit
/// for bit, on 50 draws of each simulator; the default work (the detected level) too.
#[test]
fn simd_levels_give_bit_identical_calibration_errors() {
    let available = SimdLevel::available();
    if !available.contains(&SimdLevel::Avx2) {
        println!("this CPU has no AVX2: only the portable level runs (comparison skipped)");
    }
    for (name, e2e) in simulators() {
        let mut portable = e2e
            .work()
            .with_simd_level(SimdLevel::Portable)
            .expect("portable is always available");
        let mut levels: Vec<_> = available
            .iter()
            .map(|&l| e2e.work().with_simd_level(l).expect("an available level"))
            .collect();
        let mut detected = e2e.work();
        assert_eq!(detected.simd_level(), SimdLevel::detected(), "{name}");
        for d in 0..50 {
            let chi = chi(&e2e, d);
            e2e.delta_omega_into(&chi, &mut portable).expect("a draw");
            let want: Vec<u64> = portable.delta_omega.iter().map(|x| x.to_bits()).collect();
            assert!(
                portable.delta_omega.iter().all(|&x| x > 0.0),
                "{name}: a non-trivial draw"
            );
            for w in levels.iter_mut().chain(std::iter::once(&mut detected)) {
                e2e.delta_omega_into(&chi, w).expect("a draw");
                let got: Vec<u64> = w.delta_omega.iter().map(|x| x.to_bits()).collect();
                assert_eq!(
                    got,
                    want,
                    "{name}, draw {d}, level {}",
                    w.simd_level().name()
                );
            }
        }
    }
}

/// A work accepts exactly the levels the CPU has and names the others in a typed error.
#[test]
fn unavailable_simd_levels_are_typed_errors() {
    let e2e = paper(Reading::USER);
    for level in SimdLevel::ALL {
        match e2e.work().with_simd_level(level) {
            Ok(w) => {
                assert!(level.is_available(), "{}", level.name());
                assert_eq!(w.simd_level(), level);
            }
            Err(E2eError::Bounds(McError::SimdUnavailable { level: name })) => {
                assert!(!level.is_available());
                assert_eq!(name, level.name());
            }
            Err(e) => panic!("unexpected error {e}"),
        }
    }
}
