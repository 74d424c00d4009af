//! The serde form of a run's result: its keys, in their order, and the counts under them
//! (the form callers with the `serde` feature read; it does not follow the Rust layout).

mod common;

use common::theta_only_run;
use serde_json::Value;

/// The keys of a JSON object in the order they were written.
fn keys_in_order(json: &str, keys: &[&str]) -> Vec<usize> {
    keys.iter()
        .map(|k| {
            json.find(&format!("\"{k}\":"))
                .unwrap_or_else(|| panic!("key {k} missing in {json}"))
        })
        .collect()
}

/// [`theta_only_run`] as written and as read back.
fn run_json() -> (String, Value) {
    let r = theta_only_run();
    let s = serde_json::to_string(&r).unwrap();
    let v: Value = serde_json::from_str(&s).unwrap();
    (s, v)
}

#[test]
fn a_result_serialises_its_counts_under_the_keys_samples_seed_and_within_requirement() {
    let (s, v) = run_json();
    let top = [
        "samples",
        "seed",
        "chunk_size",
        "requirement",
        "axes",
        "within_requirement_all",
    ];
    let o = v.as_object().unwrap();
    let mut expected: Vec<&str> = top.to_vec();
    expected.sort_unstable();
    let mut got: Vec<&str> = o.keys().map(String::as_str).collect();
    got.sort_unstable();
    assert_eq!(got, expected);
    // written in this order (the top-level keys are unique in the string but for `samples`
    // and `seed`, which come first)
    let at = keys_in_order(&s, &top);
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{at:?}");
    assert_eq!(v["samples"], 20_000);
    assert_eq!(v["seed"], 3);
    let axes = v["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 3);
    let axis_keys = [
        "axis",
        "max_abs_rad",
        "worst",
        "mean_rad",
        "m2_rad2",
        "within_requirement",
        "histogram",
    ];
    for a in axes {
        let mut got: Vec<&str> = a.as_object().unwrap().keys().map(String::as_str).collect();
        got.sort_unstable();
        let mut expected = axis_keys.to_vec();
        expected.sort_unstable();
        assert_eq!(got, expected);
    }
    assert_eq!(axes[0]["within_requirement"], 20_000);
    assert_eq!(axes[2]["within_requirement"], 20_000);
    let theta = axes[1]["within_requirement"].as_u64().unwrap();
    assert!(theta < 20_000);
    assert_eq!(v["within_requirement_all"].as_u64(), Some(theta));
}
