//! Each study-level question called on a shipped study, without the binary: the same golden
//! values the command line's tests assert on the same studies (`ttalloc/tests`), read from the
//! results and from their JSON views (the `--json` schema, `serde` feature).
#![cfg(feature = "serde")]

use approx::assert_relative_eq;
use serde_json::Value;
use std::path::{Path, PathBuf};
use study::Study;

/// Six printed digits (the paper's objectives as printed).
const PRINTED_REL: f64 = 5e-6;
/// The figures the command-line tests assert with four significant digits.
const FOUR_DIGITS_REL: f64 = 1e-4;
/// One figure computed two ways in double precision (the same path).
const SAME_REL: f64 = 1e-9;

/// A shipped file, from the workspace root.
fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

fn study(name: &str) -> Study {
    tt_lab::loaded::load(Some(&shipped(&format!("studies/{name}.toml")))).unwrap()
}

fn json(v: &impl serde::Serialize) -> Value {
    serde_json::to_value(v).unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// `allocate`: the paper's optimum of problems (31)-(34), J = 115.867 arcmin^-2, equal effects
/// 124.458 and Table 4 138.467, Lemma 1 over the full range (as
/// `allocate_json_keeps_the_paper_numbers`).
#[test]
fn allocation_of_the_paper_study_keeps_the_paper_objectives() {
    let s = study("gyrowheel-2017");
    let r =
        tt_lab::allocation::allocate_study(&s, &tt_lab::allocation::Options::default()).unwrap();
    let a = r.two_step().unwrap();
    assert_relative_eq!(
        a.ours.objective_arcmin(),
        115.867,
        max_relative = PRINTED_REL
    );
    assert_relative_eq!(
        a.equal.objective_arcmin(),
        124.458,
        max_relative = PRINTED_REL
    );
    assert_relative_eq!(
        a.table4.as_ref().unwrap().2,
        138.467,
        max_relative = PRINTED_REL
    );
    assert!(r.rate().is_none());
    let v = json(
        &tt_lab::allocation::allocate_json(&s, a, alloc_opt::ConstraintForm::FullRange, 0.0)
            .unwrap(),
    );
    assert_relative_eq!(num(&v["objective"]), 115.867, max_relative = PRINTED_REL);
    assert_eq!(v["lemma1_full_range"], true);
}

/// `allocate` on a study with rate steps: no two-step allocation, the direct allocation with
/// the rate tolerances instead.
#[test]
fn allocation_of_a_rate_study_is_the_direct_one_with_rate_tolerances() {
    let s = study("tactical-rate-table-example");
    let r =
        tt_lab::allocation::allocate_study(&s, &tt_lab::allocation::Options::default()).unwrap();
    assert!(r.two_step().is_none());
    let (_, rate) = r.rate().unwrap();
    assert!(rate.is_some());
}

/// `end-to-end`: under the user's reading, Table 4's worst case of the first output is 0.015936
/// deg/h, and the yield-based allocation needs 1419 turntables to resolve its target (as
/// `end_to_end_json_*` and `yield_based_allocation_is_judged_against_its_target_*`); the
/// direct allocation's view has exactly its keys.
#[test]
fn end_to_end_of_the_paper_study_finds_table4_worst_case_under_the_users_reading() {
    let s = study("gyrowheel-2017");
    let o = tt_lab::end_to_end::Options {
        samples: Some(2000),
        ..Default::default()
    };
    let r = tt_lab::end_to_end::end_to_end(&s, &o).unwrap();
    let v = json(&tt_lab::end_to_end::EndToEndJson::of(&s, &r));
    let readings = v["readings"].as_array().unwrap();
    assert_eq!(readings.len(), 2);
    assert_eq!(readings[1]["reading"], "actual/beta1/printed");
    #[cfg(feature = "paper")]
    assert_relative_eq!(
        num(&testkit::json::box_named(&readings[1], "Table 4")["worst_case"][0]["exact_at_vertex"]),
        0.015936,
        max_relative = FOUR_DIGITS_REL
    );
    for reading in readings {
        assert_eq!(reading["yield_based"]["min_samples"], 1419);
        // the direct allocation's keys, `unconstrained` and `no_bound_needed` among them (a
        // view shared with the report's results.json, flattened in)
        let keys: Vec<&str> = reading["direct"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        assert_eq!(
            keys,
            [
                "active_rows",
                "bounds_arcmin",
                "box",
                "limited_by",
                "no_bound_needed",
                "objective",
                "unconstrained",
            ]
        );
        assert_eq!(reading["direct"]["unconstrained"], serde_json::json!([]));
        assert_eq!(reading["direct"]["no_bound_needed"], false);
        // no specifications: the yield counts every accuracy, no specification view, none
        // left out
        assert!(reading["yield_based"].get("specifications").is_none());
        assert!(reading["yield_based"].get("not_counted").is_none());
    }
    assert_relative_eq!(
        num(&v["direct_objective"]),
        r.answer().readings()[0].direct().objective_arcmin(),
        max_relative = SAME_REL
    );
}

/// `end-to-end` of the IMU example (with specifications): the yield-based allocation counts
/// the draws meeting every accuracy and every specification, says so, and gives the draws
/// meeting each specification; its verdict is the re-measured interval's against the target.
#[test]
fn end_to_end_of_the_imu_example_counts_the_specifications_in_its_yield() {
    let s = study("imu-triad-example");
    let o = tt_lab::end_to_end::Options {
        samples: Some(2000),
        ..Default::default()
    };
    let r = tt_lab::end_to_end::end_to_end(&s, &o).unwrap();
    let v = json(&tt_lab::end_to_end::EndToEndJson::of(&s, &r));
    for reading in v["readings"].as_array().unwrap() {
        let y = &reading["yield_based"];
        let sp = &y["specifications"];
        // the example's two gyro specifications no table can meet are named as not counted,
        // in the words of the text and the report
        assert_eq!(r.no_table_suffices().len(), 2);
        // and listed, with their figures, as the answer has them (the text's and the report's
        // list)
        assert_eq!(y["not_counted"], json(&r.no_table_suffices()), "{y}");
        assert_eq!(
            sp["counts"],
            format!(
                "{} a table can meet (2 specifications no table can meet not counted: the noise alone fills the limit)",
                e2e_verify::SPECIFIED_YIELD_COUNTS
            ),
            "{y}"
        );
        let target = num(&y["target"]);
        let design = sp["design_meeting"].as_u64().unwrap();
        let samples = sp["design_samples"].as_u64().unwrap();
        assert!(design as f64 >= target * samples as f64, "{sp}");
        assert_relative_eq!(
            num(&y["design_yield"]),
            design as f64 / samples as f64,
            max_relative = SAME_REL
        );
        let per = sp["design_per_specification"].as_array().unwrap();
        assert!(!per.is_empty());
        for p in per {
            assert!(p["meeting"].as_u64().unwrap() >= design, "{p}");
            assert!(p["specification"].as_str().unwrap().contains(" in "), "{p}");
        }
        let again = sp["remeasured_per_specification"].as_array().unwrap();
        assert_eq!(again.len(), per.len());
        let i = sp["remeasured_interval_95"].as_array().unwrap();
        let expected = e2e_verify::YieldVerdict::of((num(&i[0]), num(&i[1])), target);
        assert_eq!(y["verdict"], expected.name(), "{y}");
    }
}

/// Too few turntables for the yield target: an input error naming the option as given.
#[test]
fn end_to_end_refuses_too_few_draws_naming_the_flag() {
    let s = study("gyrowheel-2017");
    let o = tt_lab::end_to_end::Options {
        samples: Some(100),
        ..Default::default()
    };
    let e = tt_lab::end_to_end::end_to_end(&s, &o).unwrap_err();
    let i = e.input().expect("an input error");
    assert_eq!(i.location, "--samples");
    assert!(i.reason.contains("at least 1419"), "{}", i.reason);
}

/// The vendor check of the harmonic study against Table 4: the user's reading fails; with the
/// measured errors compensated (deps_x to 0.05 arcmin) it is guaranteed (as
/// `check_turntable_reports_before_and_after_compensation`).
#[test]
fn vendor_check_compensation_turns_the_users_reading_from_fails_to_guaranteed() {
    let s = study("gyrowheel-2017-harmonic-errors");
    let o = tt_lab::vendor::Options {
        samples: Some(1500),
        ..Default::default()
    };
    let c = tt_lab::vendor::check(&s, &shipped("studies/tolerances/table4.toml"), &o).unwrap();
    assert_eq!(c.checks().len(), 2);
    assert!(c.angle().is_some() && c.rate().is_none());
    let v = json(&tt_lab::vendor::CheckJson::of(&s, &c));
    assert_eq!(v["user_reading"]["verdict"], "fails");
    let comp = &v["compensated"];
    assert_relative_eq!(
        num(&comp["tolerances_arcmin"]["deps_x"]),
        0.05,
        max_relative = SAME_REL
    );
    assert_eq!(comp["readings"][1]["verdict"], "guaranteed");
}

/// The vendor check of the rate study against its sheet: the rate part is answered, the
/// angle-dependent part is not.
#[test]
fn vendor_check_of_a_rate_study_answers_the_rate_part() {
    let s = study("tactical-rate-table-example");
    let o = tt_lab::vendor::Options {
        samples: Some(2000),
        ..Default::default()
    };
    let c = tt_lab::vendor::check(
        &s,
        &shipped("studies/tolerances/tactical-rate-table-sheet.toml"),
        &o,
    )
    .unwrap();
    assert!(c.angle().is_none());
    assert_eq!(c.rate().unwrap().len(), c.checks().len());
    let v = json(&tt_lab::vendor::CheckJson::of(&s, &c));
    assert_eq!(v["rate_steps_note"], tt_lab::vendor::RATE_STEPS_NOTE);
}

/// `estimable` on the paper's study with Table 4: the eight errors act as five (rank 14 + 5 of
/// 22), no bound is needed once they are estimated (as
/// `estimable_on_the_paper_study_finds_the_five_groups_and_needs_no_bound`).
#[test]
fn estimable_on_the_paper_study_finds_the_five_groups() {
    let s = study("gyrowheel-2017");
    let o = tt_lab::estimable::Options {
        tolerances: Some(shipped("studies/tolerances/table4.toml")),
    };
    let a = tt_lab::estimable::estimable(&s, &o).unwrap();
    let v = json(&tt_lab::estimable::to_json(&s, &a));
    assert_eq!(v["reading"], "actual/beta1/printed");
    assert_eq!(v["rank"], 19);
    assert_eq!(v["columns"], 22);
    assert_eq!(v["table_rank"], 5);
    assert_eq!(v["estimable"].as_array().unwrap().len(), 5);
    assert_eq!(v["allocation"]["joint"]["no_bound_needed"], true);
    assert_eq!(v["allocation"]["ordinary"]["no_bound_needed"], false);
}
