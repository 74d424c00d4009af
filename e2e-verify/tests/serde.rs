//! The end-to-end result types serialise with the `serde` feature (issue 20 item 4): the
//! buyer's check of a vendor's box and the allocations through the `Allocator` seam, with
//! their verdicts in snake case and the numbers of the result itself.

mod common;

use alloc_opt::Allocator;
use calib_lsq::Reading;
use common::*;
use e2e_verify::{Direct, McSettings};
use serde_json::Value;

/// The buyer's check of Table 4 under the user's reading serialises its verdict (`fails`:
/// 0.0159 deg/h against 0.01, README), every output's worst case, the yield's draws and
/// its worst draws (index and errors, no empty extra data); the
/// direct box through the seam serialises its joint details.
#[test]
fn the_buyers_check_and_the_direct_box_serialise_their_verdicts_and_numbers() {
    let e2e = paper(Reading::USER);
    let ub = alloc_opt::paper::table4_rad();
    let lb = vec![0.0; e2e.n_errors()];
    let check = e2e
        .vendor()
        .check_tolerances(&e2e.linearization(), &ub, &lb, &McSettings::new(2_000, 3))
        .unwrap();
    let v: Value = serde_json::to_value(&check).unwrap();
    let outputs = v["outputs"].as_array().unwrap();
    assert_eq!(outputs.len(), check.outputs().len());
    for (o, c) in outputs.iter().zip(check.outputs()) {
        assert_eq!(o["verdict"], c.verdict().name());
    }
    assert!(outputs.iter().any(|o| o["verdict"] == "fails"));
    assert_eq!(v["distribution"]["samples"], 2_000);
    // the worst draws are the Monte Carlos' one `WorstSample`, with no extra data end to end
    let worst = v["distribution"]["worst"].as_array().unwrap();
    for (w, d) in worst.iter().zip(check.distribution().worst()) {
        assert_eq!(w["index"], d.index());
        assert_eq!(w["chi_rad"].as_array().unwrap().len(), d.chi_rad().len());
        assert!(w.get("extra").is_none(), "{w}");
    }
    assert_eq!(worst.len(), e2e.n_outputs());

    let problem = e2e.allocation_problem(e2e.linearization(), lb).unwrap();
    let tb = Direct::new(&e2e).allocate(&problem).unwrap();
    let v: Value = serde_json::to_value(&tb).unwrap();
    assert_eq!(v["method"], "direct");
    assert_eq!(
        v["details"]["joint"]["margins"].as_array().unwrap().len(),
        e2e.n_outputs()
    );
    let names: Vec<String> = v["certificate"]["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, e2e.output_names());
}
