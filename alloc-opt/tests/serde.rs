//! The result types serialise with the `serde` feature (issue 20 item 4, nalgebra's
//! convention): a caller writes a `ToleranceBox` as JSON with serde, no hand-built JSON; the
//! numbers are the box's own, in its units (radians), the enums in snake case.

use alloc_opt::{Allocator, EqualEffects, SensitivityWeighted, paper};
use serde_json::Value;

/// A `ToleranceBox` written as JSON keeps its method, every bound (radians, bit for bit
/// through serde_json's shortest round-trip printing), its certificate per angle and its
/// details (the two-step subproblems, in snake case).
#[test]
fn a_tolerance_box_serialises_its_bounds_certificate_and_details() {
    let problem = paper::example_problem().unwrap();
    for allocator in [
        &SensitivityWeighted::paper() as &dyn Allocator,
        &EqualEffects,
    ] {
        let tb = allocator.allocate(&problem).unwrap();
        let v: Value = serde_json::from_str(&serde_json::to_string(&tb).unwrap()).unwrap();
        assert_eq!(v["method"], tb.method());
        let ub: Vec<f64> = v["upper_bounds_rad"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(ub, tb.upper_bounds_rad());
        let names: Vec<&str> = v["certificate"]["axes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["psi", "theta", "gamma"]);
        for (a, c) in v["certificate"]["axes"]
            .as_array()
            .unwrap()
            .iter()
            .zip(tb.certificate().axes())
        {
            assert_eq!(a["satisfied"], c.satisfied());
            assert_eq!(
                a["worst_case_rad"].as_f64().map(f64::to_bits),
                Some(c.worst_case_rad().to_bits())
            );
        }
        let subproblems = v["details"]["two_step"]["subproblems"].as_array().unwrap();
        assert_eq!(subproblems.len(), 3);
    }
}
