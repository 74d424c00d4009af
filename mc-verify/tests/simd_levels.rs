//! The hot loop compiled per SIMD level (runtime dispatch, `mc_verify::simd`) gives the same
//! result, bit for bit, as the portable loop: only the vector width changes. On a CPU without
//! AVX2 only the portable level runs (the test says so).

mod common;

use common::{TABLE4_ARCMIN, config, fingerprint, paper_table, table4, three_axis};
use mc_verify::{ErrorBox, McError, MonteCarlo, SimdLevel, Tier};
use tt_kinematics::Turntable;

/// One box per evaluation tier of the fast run, for both tables: zero lower bounds in the
/// short-series range (the paper's Table 4: tangent tier), non-zero lower bounds in the short
/// range, the medium series (bounds up to 20 arcmin) and the `f64::sin_cos` fall-back (up
/// to 2 degrees).
fn cases() -> Vec<(String, Turntable, ErrorBox, Tier)> {
    let mut v = Vec::new();
    for (name, t) in [("paper", paper_table()), ("three-axis", three_axis())] {
        let n = t.n_rotation_errors();
        let ub_short: Vec<f64> = (0..n).map(|i| TABLE4_ARCMIN[i % 8]).collect();
        let lb_short = ub_short.iter().map(|u| 0.25 * u).collect();
        let arcmin = |lb: Vec<f64>, ub: Vec<f64>| ErrorBox::from_arcmin(&t, lb, ub).unwrap();
        let boxes = [
            (
                "LB = 0, short",
                arcmin(vec![0.0; n], ub_short.clone()),
                Tier::Tangent,
            ),
            ("LB = UB/4, short", arcmin(lb_short, ub_short), Tier::Short),
            (
                "20 arcmin",
                arcmin(vec![0.0; n], vec![20.0; n]),
                Tier::Medium,
            ),
            (
                "30-120 arcmin",
                arcmin(vec![30.0; n], vec![120.0; n]),
                Tier::Any,
            ),
        ];
        for (what, b, tier) in boxes {
            v.push((format!("{name}: {what}"), t.clone(), b, tier));
        }
    }
    v
}

/// Every level this CPU has equals the portable level bit for bit (moments, extremes, worst
/// samples, histograms, yields), on every evaluation tier of both tables, and `run` (the
/// detected level) is one of them. A short last chunk and a short last block are included.
#[test]
fn simd_levels_give_bit_identical_results() {
    let available = SimdLevel::available();
    if !available.contains(&SimdLevel::Avx2) {
        println!("this CPU has no AVX2: only the portable level runs (comparison skipped)");
    }
    for (name, t, b, tier) in cases() {
        let mut cfg = config(70_001, 11);
        cfg.chunk_size = 10_000;
        let mc = MonteCarlo::new(&t, b, cfg).unwrap();
        assert_eq!(mc.tier(), tier, "{name}");
        let portable = fingerprint(&mc.run_with_simd(SimdLevel::Portable).unwrap());
        for &level in &available {
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
    let mc = MonteCarlo::new(&paper_table(), table4(), config(1_000, 1)).unwrap();
    for level in SimdLevel::ALL {
        match mc.run_with_simd(level) {
            Ok(r) => {
                assert!(level.is_available());
                assert_eq!(r.count().samples(), 1_000);
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
