//! The schedule design called on shipped studies without the binary: the numbers the
//! command-line tests (`ttalloc/tests/design_schedule.rs`) assert of the same studies.

use std::path::PathBuf;
use study::Study;
use tt_lab::design::schedule::{Options, ScheduleAnswer, design};

fn study(name: &str) -> Study {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../studies")).join(name);
    tt_lab::loaded::load(Some(&p)).expect("a shipped study loads")
}

/// The largest condition number the design accepts by default.
const MAX_CONDITION: f64 = 10.0;

fn designed_at_45_deg(name: &str) -> (Study, ScheduleAnswer) {
    let s = study(name);
    let mut o = Options::default();
    o.step_deg = 45.0;
    let a = design(&s, &o, &|| {}).expect("the shipped study designs");
    (s, a)
}

/// On the 45 deg grid (512 candidates over three joints) the three-axis example (32
/// positions) and the IMU triad (24) design a schedule that meets the condition bound, is a
/// local optimum and is no worse than the study's own schedule (a start of the search).
#[test]
fn three_axis_and_imu_examples_design_within_the_bound_and_no_worse_than_their_schedules() {
    for (name, positions) in [
        ("three-axis-example.toml", 32),
        ("imu-triad-example.toml", 24),
    ] {
        let (s, a) = designed_at_45_deg(name);
        assert_eq!(a.candidates(), 512, "{name}");
        let d = a.design();
        for r in [d.designed(), d.study(), d.d_optimal()] {
            assert_eq!(r.positions_deg().len(), positions, "{name}");
            assert!(r.positions_deg().iter().all(|p| p.len() == 3), "{name}");
            assert_eq!(r.condition_numbers().len(), s.sensor.outputs().len());
            assert!(r.allocation().objective_arcmin() > 0.0, "{name}");
        }
        assert!(
            d.designed().allocation().objective_arcmin()
                <= d.study().allocation().objective_arcmin(),
            "{name}"
        );
        assert!(
            d.designed()
                .condition_numbers()
                .iter()
                .all(|c| *c <= MAX_CONDITION),
            "{name}"
        );
        assert!(d.search().designed().local_optimum(), "{name}");
        // no budget and no candidate rates asked: neither answered
        assert!(a.budget().is_none() && a.rates().is_none(), "{name}");
    }
}

/// A candidate rate for a study without rate steps is refused before the search, naming
/// the flag.
#[test]
fn a_rate_for_a_study_without_rate_steps_is_refused_naming_the_flag() {
    let s = study("three-axis-example.toml");
    let mut o = Options::default();
    o.rates_deg_per_s = Some(vec![10.0]);
    let e = design(&s, &o, &|| panic!("no search before the check")).unwrap_err();
    assert_eq!(e.input().unwrap().location, "--rates-deg-per-s");
}

/// The JSON view keeps the command's keys (the public schema).
#[cfg(feature = "serde")]
#[test]
fn schedule_view_keeps_its_keys() {
    let (s, a) = designed_at_45_deg("three-axis-example.toml");
    let run = tt_lab::design::schedule::RunView {
        command: "cargo xtask design-schedule",
        ..Default::default()
    };
    let v = serde_json::to_value(a.view(&s, run)).unwrap();
    for k in [
        "designed",
        "study",
        "d_optimal",
        "random_best",
        "search",
        "groups",
        "candidates",
        "command",
        "written_study",
    ] {
        assert!(v.get(k).is_some(), "{k}");
    }
    for k in ["noise_note", "combined", "time_budget", "pareto", "rates"] {
        assert!(v.get(k).is_none(), "{k}");
    }
    assert_eq!(v["candidates"], 512);
    // the same number, not a recomputation
    assert_eq!(
        v["designed"]["objective"].as_f64().unwrap().to_bits(),
        a.design()
            .designed()
            .allocation()
            .objective_arcmin()
            .to_bits()
    );
}
