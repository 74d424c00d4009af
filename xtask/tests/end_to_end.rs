//! `cargo xtask end-to-end`: the JSON equals the library's answer for the paper's study, the
//! text answers the buyer's question for both readings, and bad flags exit 2 naming the flag.

use approx::assert_relative_eq;
use calib_lsq::Reading;
use e2e_verify::{EndToEndInputs, answer, objective_to_arcmin};
use std::process::{Command, Output};
use tt_kinematics::ErrorComponent;
use tt_kinematics::units::RAD_PER_ARCMIN;

/// The command prints serde_json's shortest round-trip decimals of the library's values after
/// one unit conversion: equal up to a few ulp.
const ROUND_TRIP_REL: f64 = 8.0 * f64::EPSILON;

/// Turntables per box of the paper's study file (`[monte_carlo] samples`).
const STUDY_SAMPLES: u64 = 10_000;

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("end-to-end")
        .args(args)
        .output()
        .expect("spawn xtask")
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// `--json` has the keys of issue 7 and the library's numbers for the paper's study (PAPER
/// reading at the top level, the USER reading under `user_reading`).
#[test]
fn end_to_end_json_matches_library() {
    let out = run(&["--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let inputs = EndToEndInputs {
        samples: STUDY_SAMPLES,
        ..EndToEndInputs::paper()
    };
    let lib = answer(&inputs).unwrap();
    assert_eq!(v["reading"], Reading::PAPER.to_string());
    assert_eq!(v["user_reading"]["reading"], Reading::USER.to_string());
    assert_relative_eq!(
        num(&v["two_step_objective"]),
        objective_to_arcmin(lib.two_step_objective),
        max_relative = ROUND_TRIP_REL
    );
    for (json, r) in [
        (&v, &lib.readings[0]),
        (&v["user_reading"], &lib.readings[1]),
    ] {
        for (key, b) in [("table4", &r.table4), ("ours", &r.ours)] {
            let w = b.worst_case.exact_deg_per_h();
            assert_relative_eq!(
                num(&json["worst_case_deg_per_h"][key]["x"]),
                w[0],
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(
                num(&json["worst_case_deg_per_h"][key]["y"]),
                w[1],
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(
                num(&json["yield"][key]),
                b.distribution.yield_fraction(),
                max_relative = ROUND_TRIP_REL
            );
        }
        for c in ErrorComponent::ALL {
            assert_relative_eq!(
                num(&json["direct_allocation_arcmin"][c.name()]),
                r.direct.upper_bounds_rad[c.index()] / RAD_PER_ARCMIN,
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(
                num(&json["yield_allocation_arcmin"][c.name()]),
                r.yield_based.upper_bounds_rad[c.index()] / RAD_PER_ARCMIN,
                max_relative = ROUND_TRIP_REL
            );
        }
        assert_relative_eq!(
            num(&json["direct_objective"]),
            r.direct.objective_arcmin(),
            max_relative = ROUND_TRIP_REL
        );
        let per = json["per_position_worst_case_deg_per_h"]["direct"]["x"]
            .as_array()
            .unwrap();
        assert_eq!(per.len(), 32);
    }
    // The buyer's answer in the PAPER reading: Table 4 meets omega_m = 0.01 deg/h.
    assert!(num(&v["worst_case_deg_per_h"]["table4"]["x"]) < 0.01);
    // In the USER reading it does not.
    assert!(num(&v["user_reading"]["worst_case_deg_per_h"]["table4"]["x"]) > 0.01);
}

/// The text names both readings, the four bound sets and the throughput line.
#[test]
fn end_to_end_text_answers_for_both_readings() {
    let out = run(&["--samples", "2000"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    for k in [
        "intended/beta1/printed",
        "actual/beta1/printed",
        "Table 4",
        "two-step",
        "direct",
        "yield-based",
        "Throughput",
        "turntables",
    ] {
        assert!(text.contains(k), "missing {k}: {text}");
    }
}

/// Bad flags are user-input errors: exit code 2, the flag named, nothing on standard output.
#[test]
fn bad_flags_exit_2_naming_the_flag() {
    for (args, flag) in [
        (&["--samples", "0"][..], "samples"),
        (&["--yield-fraction", "1.5"][..], "yield"),
        (&["--reading", "intended/beta9/printed"][..], "reading"),
    ] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
    }
}
