//! `cargo xtask allocate`: the JSON equals the library's allocation for the paper's inputs
//! (eq 16, problems 31-34) and carries Table 4 as published; the text shows both side by side.

use alloc_opt::{
    AllocationProblem, Allocator, Certificate, EqualEffects, PAPER_TABLE4_ARCMIN,
    SensitivityWeighted, Weights, paper_table4_rad,
};
use approx::assert_relative_eq;
use std::process::{Command, Output};
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{ErrorComponent, OrientationAxis};

/// serde_json prints shortest round-trip decimals: equal to the library up to the unit
/// conversions, a few ulps.
const ROUND_TRIP_REL: f64 = 8.0 * f64::EPSILON;

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("allocate")
        .args(args)
        .output()
        .expect("spawn xtask")
}

/// Problems (31)-(34) through the CLI: the required keys, the library's numbers, Table 4 as
/// golden data, and the shares of the requirement.
#[test]
fn allocate_json_matches_library_and_table4() {
    let out = run(&["--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let problem = AllocationProblem::paper_example().unwrap();
    let ours = SensitivityWeighted::paper().allocate(&problem).unwrap();
    let equal = EqualEffects.allocate(&problem).unwrap();
    for a in OrientationAxis::ALL {
        assert_relative_eq!(
            v["requirement_deg"][a.name()].as_f64().unwrap(),
            0.027,
            max_relative = ROUND_TRIP_REL
        );
        assert_relative_eq!(
            v["share"][a.name()].as_f64().unwrap(),
            ours.certificate.get(a).share,
            max_relative = ROUND_TRIP_REL
        );
    }
    for c in ErrorComponent::ALL {
        let i = c.index();
        assert_relative_eq!(
            v["allocation_arcmin"][c.name()].as_f64().unwrap(),
            ours.upper_bounds_arcmin()[i],
            max_relative = ROUND_TRIP_REL
        );
        assert_relative_eq!(
            v["paper_table4_arcmin"][c.name()].as_f64().unwrap(),
            PAPER_TABLE4_ARCMIN[i],
            max_relative = ROUND_TRIP_REL
        );
        assert_relative_eq!(
            v["equal_effects_arcmin"][c.name()].as_f64().unwrap(),
            equal.upper_bounds_arcmin()[i],
            max_relative = ROUND_TRIP_REL
        );
    }
    assert_relative_eq!(
        v["objective"].as_f64().unwrap(),
        ours.objective_arcmin(),
        max_relative = ROUND_TRIP_REL
    );
    let table = paper_table4_rad();
    let j_table = Weights::inverse_average_sensitivity(problem.model()).objective(&table)
        * RAD_PER_ARCMIN
        * RAD_PER_ARCMIN;
    assert_relative_eq!(
        v["paper_table4_objective"].as_f64().unwrap(),
        j_table,
        max_relative = ROUND_TRIP_REL
    );
    let cert = Certificate::compute(
        problem.model(),
        &problem.requirement(),
        &problem.lower_bounds_rad(),
        &table,
    );
    assert_relative_eq!(
        v["paper_table4_share"]["gamma"].as_f64().unwrap(),
        cert.get(OrientationAxis::Gamma).share,
        max_relative = ROUND_TRIP_REL
    );
    assert_eq!(v["lemma1_full_range"], serde_json::Value::Bool(true));
    assert!(v["objective"].as_f64().unwrap() < j_table);
}

/// The text output shows ours beside Table 4, the objective row and the shares.
#[test]
fn allocate_text_shows_ours_beside_table4() {
    let out = run(&[]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("Table 4"));
    let row = text
        .lines()
        .find(|l| l.starts_with("dalpha_x2"))
        .expect("dalpha_x2 row");
    let cols: Vec<f64> = row
        .split_whitespace()
        .skip(1)
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(cols.len(), 3);
    assert_relative_eq!(cols[0], 0.3062, max_relative = 2e-4);
    assert_relative_eq!(cols[1], 0.2825, max_relative = 2e-4);
    assert!(text.contains("share gamma"));
    assert!(text.contains("Lemma 1 on the full pose range: true"));
}
