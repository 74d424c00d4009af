//! `cargo xtask requirement`: the JSON equals the library's requirement for the paper's inputs
//! (eq 16), the text names the reading, and a bad reading exits 2 naming the key.

use approx::assert_relative_eq;
use calib_lsq::{Reading, RequirementProblem};
use std::process::{Command, Output};

/// The command prints serde_json's shortest round-trip decimals: equal to the library's values
/// up to the degree conversion, a few ulps.
const ROUND_TRIP_REL: f64 = 4.0 * f64::EPSILON;

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("requirement")
        .args(args)
        .output()
        .expect("spawn xtask")
}

/// Eq 16 through the CLI: `--json` has the required keys and the library's numbers.
#[test]
fn requirement_json_matches_library_eq16() {
    let out = run(&["--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let lib = RequirementProblem::paper().requirement().unwrap();
    assert_eq!(v["reading"], Reading::PAPER.to_string());
    assert_relative_eq!(
        v["latitude_deg"].as_f64().unwrap(),
        45.75,
        max_relative = ROUND_TRIP_REL
    );
    let req = &v["orientation_requirement_deg"];
    for (key, want) in ["psi", "theta", "gamma"].iter().zip(lib.deg()) {
        let got = req[key].as_f64().unwrap();
        assert_relative_eq!(got, want, max_relative = ROUND_TRIP_REL);
        assert!((got - 0.027).abs() < 0.0005, "{key} = {got}");
    }
}

/// Text output names the reading and prints the three bounds.
#[test]
fn requirement_text_names_reading_and_bounds() {
    let out = run(&[]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("intended/beta1/printed"), "{text}");
    for k in ["I_psi", "I_theta", "I_gamma"] {
        assert!(text.contains(k), "{text}");
    }
}

/// A reading that does not exist is a user-input error: exit code 2, message naming `reading`,
/// nothing on standard output.
#[test]
fn unknown_reading_exits_2_naming_the_key() {
    let out = run(&["--reading", "intended/beta9/printed"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("reading"), "{err}");
}

/// Another reading through the flag gives that reading's (different) library result.
#[test]
fn reading_flag_selects_the_reading() {
    let name = "actual/beta1/printed";
    let out = run(&["--json", "--reading", name]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reading"], name);
    let lib = RequirementProblem {
        reading: name.parse().unwrap(),
        ..RequirementProblem::paper()
    }
    .requirement()
    .unwrap();
    assert_relative_eq!(
        v["orientation_requirement_deg"]["psi"].as_f64().unwrap(),
        lib.deg()[0],
        max_relative = ROUND_TRIP_REL
    );
}
