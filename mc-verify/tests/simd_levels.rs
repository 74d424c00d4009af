//! The hot loop compiled per SIMD level (runtime dispatch, `mc_verify::simd`) gives the same
//! result, bit for bit, as the portable loop: only the vector width changes.

mod common;

use common::{TABLE4_ARCMIN, fingerprint, table4};
use mc_verify::{ErrorBox, McConfig, McError, MonteCarlo, SimdLevel};

/// One box per evaluation path of the fast run: zero lower bounds in the short-series range
/// (the paper's Table 4), non-zero lower bounds in the short range, the medium series
/// (bounds up to 20 arcmin) and the `f64::sin_cos` fall-back (up to 2 degrees).
fn boxes() -> Vec<(&'static str, ErrorBox)> {
    let lb_short = TABLE4_ARCMIN.map(|u| 0.25 * u);
    vec![
        ("table4, LB = 0, short series", table4()),
        (
            "table4, LB = UB/4, short series",
            ErrorBox::from_arcmin(lb_short, TABLE4_ARCMIN).unwrap(),
        ),
        (
            "20 arcmin, medium series",
            ErrorBox::from_arcmin([0.0; 8], [20.0; 8]).unwrap(),
        ),
        (
            "2 deg, sin_cos fall-back",
            ErrorBox::from_arcmin([30.0; 8], [120.0; 8]).unwrap(),
        ),
    ]
}

/// Every level this CPU has equals the portable level bit for bit (moments, extremes, worst
/// samples, histograms, yields), on every evaluation path, and `run` (the detected level)
/// is one of them. A short last chunk and a short last block are included.
#[test]
fn simd_levels_give_bit_identical_results() {
    for (name, b) in boxes() {
        let mut cfg = McConfig::new(70_001, 11);
        cfg.chunk_size = 10_000;
        let mc = MonteCarlo::new(b, cfg).unwrap();
        let portable = fingerprint(&mc.run_with_simd(SimdLevel::Portable).unwrap());
        for level in SimdLevel::available() {
            let r = mc.run_with_simd(level).unwrap();
            assert_eq!(fingerprint(&r), portable, "{name}: level {}", level.name());
        }
        assert_eq!(fingerprint(&mc.run()), portable, "{name}: detected level");
    }
}

/// `run_with_simd` accepts exactly the levels the CPU has and names the others in a typed
/// error; the detected level is the widest available one.
#[test]
fn unavailable_simd_levels_are_typed_errors_and_detection_picks_the_widest() {
    let mc = MonteCarlo::new(table4(), McConfig::new(1_000, 1)).unwrap();
    for level in SimdLevel::ALL {
        match mc.run_with_simd(level) {
            Ok(r) => {
                assert!(level.is_available());
                assert_eq!(r.samples, 1_000);
            }
            Err(McError::SimdUnavailable { level: name }) => {
                assert!(!level.is_available());
                assert_eq!(name, level.name());
            }
            Err(e) => panic!("unexpected error {e}"),
        }
    }
    let available = SimdLevel::available();
    assert_eq!(available.first(), Some(&SimdLevel::Portable));
    assert_eq!(available.last(), Some(&SimdLevel::detected()));
}
