//! `cargo xtask mc`: JSON schema, Figure 9 for both allocations, thread-count independence,
//! bad input exits 2 naming the flag.

use serde_json::Value;
use std::process::{Command, Output};

/// eq 16: the paper's requirement, degrees.
const REQUIREMENT_DEG: f64 = 0.027;

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("mc")
        .args(args)
        .output()
        .expect("spawn xtask")
}

fn run_json(args: &[&str]) -> Value {
    let mut all = vec!["--json"];
    all.extend_from_slice(args);
    let out = run(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// The documented keys are present with sane values.
#[test]
fn mc_json_has_the_documented_keys() {
    let v = run_json(&["--samples", "1e5", "--seed", "7", "--threads", "2"]);
    assert_eq!(v["samples"], 100_000);
    assert_eq!(v["seed"], 7);
    assert_eq!(v["threads"], 2);
    assert_eq!(v["bounds"], "table4");
    assert!(v["seconds"].as_f64().unwrap() > 0.0);
    assert!(v["samples_per_sec"].as_f64().unwrap() > 0.0);
    for axis in ["psi", "theta", "gamma"] {
        let m = v["max_abs_deg"][axis].as_f64().unwrap();
        assert!(m > 0.0 && m <= REQUIREMENT_DEG, "{axis}: {m}");
        assert!(v["std_deg"][axis].as_f64().unwrap() > 0.0);
        let counts = v["histogram_deg"][axis]["counts"].as_array().unwrap();
        let total: u64 = counts.iter().map(|c| c.as_u64().unwrap()).sum();
        assert_eq!(total, 100_000);
        assert!(v["worst"][axis]["chi"]["dphi_z2_arcmin"].is_number());
    }
    assert!(v["within_requirement_fraction"].as_f64().unwrap() > 1.0 - 1e-12);
    assert!(["portable", "avx2"].contains(&v["simd_level"].as_str().unwrap()));
}

/// `--baselines` reports the same-run rates and their ratios (each ratio is our rate over
/// the baseline's: the best of the interleaved rounds for the generator and SIMD ratios, the
/// main run for the plain chain); the NumPy entry is either a result or an error, never a
/// failure.
#[test]
fn mc_baselines_report_same_run_rates_and_consistent_ratios() {
    let v = run_json(&["--samples", "2e5", "--baselines"]);
    let b = &v["baselines"];
    let fast = v["samples_per_sec"].as_f64().unwrap();
    let fast_best = b["fast_best_samples_per_sec"].as_f64().unwrap();
    for (rate, ratio, ours) in [
        (
            "generator_alone_samples_per_sec",
            "ratio_fast_over_generator_alone",
            fast_best,
        ),
        (
            "generator_words_only_samples_per_sec",
            "ratio_fast_over_generator_words_only",
            fast_best,
        ),
        (
            "portable_simd_samples_per_sec",
            "ratio_fast_over_portable_simd",
            fast_best,
        ),
        (
            "plain_chain_samples_per_sec",
            "ratio_fast_over_plain_chain",
            fast,
        ),
    ] {
        let r = b[rate].as_f64().unwrap();
        assert!(r > 0.0, "{rate}: {r}");
        let q = b[ratio].as_f64().unwrap();
        assert!(((q * r) / ours - 1.0).abs() < 1e-12, "{ratio}: {q}");
    }
    // best of the interleaved rounds
    let rounds = b["interleaved_rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 3);
    let best_gen = rounds
        .iter()
        .map(|r| r["generator_alone"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!((best_gen - b["generator_alone_samples_per_sec"].as_f64().unwrap()).abs() < 1e-9);
    assert_eq!(b["interleaved_samples"], 200_000);
    assert_eq!(b["plain_chain_samples"], 200_000);
    assert!(b["numpy"].get("samples_per_sec").is_some() || b["numpy"].get("error").is_some());
}

/// Paper §4.3, Figure 9, for both allocations: every one of 10^6 random turntables (Table 4
/// or ours, LB = 0) stays inside |angle| <= 0.027 deg (eq 16) on the exact chain.
#[test]
fn figure9_every_sample_of_a_million_inside_eq16_for_table4_and_ours() {
    for bounds in ["table4", "ours"] {
        let v = run_json(&["--samples", "1e6", "--bounds", bounds]);
        assert_eq!(v["samples"], 1_000_000);
        assert!(
            (v["within_requirement_fraction"].as_f64().unwrap() - 1.0).abs() < f64::EPSILON,
            "{bounds}"
        );
        for axis in ["psi", "theta", "gamma"] {
            assert!(v["max_abs_deg"][axis].as_f64().unwrap() <= REQUIREMENT_DEG);
        }
    }
}

/// The result does not depend on --threads (everything but timing and the thread count).
#[test]
fn mc_result_is_identical_for_1_and_2_threads() {
    let strip = |mut v: Value| {
        let o = v.as_object_mut().unwrap();
        for k in ["seconds", "samples_per_sec", "threads"] {
            o.remove(k);
        }
        v
    };
    let args = ["--samples", "300000", "--chunk-size", "4096", "--seed", "3"];
    let mut one = vec!["--threads", "1"];
    one.extend_from_slice(&args);
    let mut two = vec!["--threads", "2"];
    two.extend_from_slice(&args);
    assert_eq!(strip(run_json(&one)), strip(run_json(&two)));
}

#[test]
fn mc_bad_input_exits_2_naming_the_flag() {
    for (args, needle) in [
        (vec!["--samples", "0"], "samples"),
        (vec!["--samples", "abc"], "samples"),
        (vec!["--samples", "1.5"], "samples"),
        (vec!["--threads", "0"], "threads"),
        (vec!["--chunk-size", "0"], "chunk-size"),
        (vec!["--bins", "0"], "bins"),
        (vec!["--requirement-deg", "-1"], "requirement"),
        (vec!["--bounds", "nope"], "bounds"),
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
