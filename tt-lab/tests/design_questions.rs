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

/// Relative agreement of two computations of the same J through the same allocation core
/// (dimensionless): the designer's and `end-to-end`'s paths build the same simulator and rows.
const SAME_J_REL: f64 = 1e-9;

/// The IMU example with its accelerometer misalignment specified at 10 arcsec instead of
/// 20 (docs/verdict.md): the specifications then bind the direct allocation.
fn imu_with_tight_misalignment() -> Study {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../studies"))
        .join("imu-triad-example.toml");
    let text = std::fs::read_to_string(&p).unwrap();
    let old = "coefficient = \"mis_xy\"\nlimit = 20\n";
    assert!(
        text.contains(old),
        "the shipped example's misalignment spec"
    );
    let dir = std::env::temp_dir().join(format!("tt-lab-design-spec-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("imu-tight-misalignment.toml");
    std::fs::write(
        &file,
        text.replace(old, "coefficient = \"mis_xy\"\nlimit = 10\n"),
    )
    .unwrap();
    let s = tt_lab::loaded::load(Some(&file)).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    s
}

/// J (rad^-2) of `end-to-end`'s direct allocation of `s` (the specified one where the study
/// gives specifications).
fn end_to_end_direct_objective(s: &Study) -> f64 {
    let o = tt_lab::end_to_end::Options {
        samples: Some(2000),
        ..Default::default()
    };
    let a = tt_lab::end_to_end::end_to_end(s, &o).unwrap();
    a.answer().readings()[0].direct().objective()
}

/// The designer's objective of a fixed schedule is `end-to-end`'s specified allocation's J
/// for that schedule (1e-9 relative): on the IMU example (its ax specifications; the gx ones
/// the noise alone fills are left out, as `end-to-end` leaves them out) and with the
/// misalignment at 10 arcsec, where the specification rows bind and J is larger than eq 14's.
#[test]
fn the_designers_objective_of_a_schedule_is_end_to_ends_specified_objective() {
    for (s, binds) in [
        (study("imu-triad-example.toml"), false),
        (imu_with_tight_misalignment(), true),
    ] {
        let spec = tt_lab::design::schedule::spec_objective(&s)
            .unwrap()
            .expect("the IMU example has specifications that leave room");
        let problem = schedule_design::DesignProblem::new(
            &s.turntable,
            &s.sensor,
            &s.site,
            s.reading,
            &s.lower_bounds_rad,
            s.positions_deg.clone(),
        )
        .unwrap();
        let study_schedule: Vec<usize> = (0..s.positions_deg.len()).collect();
        let eq14 = problem.evaluate(&study_schedule).unwrap().objective();
        let designer = problem
            .with_specifications(Some(spec))
            .evaluate(&study_schedule)
            .unwrap()
            .objective();
        let reference = end_to_end_direct_objective(&s);
        approx::assert_relative_eq!(designer, reference, max_relative = SAME_J_REL);
        if binds {
            assert!(designer > eq14 * 1.01, "{designer} vs eq 14's {eq14}");
        } else {
            assert!(
                designer >= eq14 * (1.0 - SAME_J_REL),
                "{designer} vs {eq14}"
            );
        }
    }
}

/// With specifications that bind, the designed schedule is never worse than the study's on
/// the specified objective, and its J is `end-to-end`'s for the designed positions.
#[test]
fn a_design_against_binding_specifications_is_no_worse_than_the_studys_schedule() {
    let s = imu_with_tight_misalignment();
    let mut o = Options::default();
    o.step_deg = 90.0;
    let a = design(&s, &o, &|| {}).unwrap();
    let d = a.design();
    let designed = d.designed().allocation().objective();
    let of_study = d.study().allocation().objective();
    assert!(designed <= of_study, "{designed} vs {of_study}");
    approx::assert_relative_eq!(
        of_study,
        end_to_end_direct_objective(&s),
        max_relative = SAME_J_REL
    );
    let s2 = s
        .with_positions_deg(d.designed().positions_deg().to_vec())
        .unwrap();
    approx::assert_relative_eq!(
        designed,
        end_to_end_direct_objective(&s2),
        max_relative = SAME_J_REL
    );
    // the specification rows are part of the designed allocation
    assert!(!d.designed().allocation().spec_loads().is_empty());
}

/// The STIM300-class rate-table example with each gyro's scale factor specified at `ppm`
/// (a test plan's figure in the coefficient's unit; the shipped study gives none).
fn rate_table_with_scale_factor_specs(ppm: f64) -> Study {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../studies"))
        .join("stim300-rate-table-example.toml");
    let mut text = std::fs::read_to_string(&p).unwrap();
    for (o, c) in [("gx", "sf_gx"), ("gy", "sf_gy"), ("gz", "sf_gz")] {
        text.push_str(&format!(
            "\n[[specifications]]\noutput = \"{o}\"\ncoefficient = \"{c}\"\nlimit = {ppm}\nunit = \"ppm\"\n"
        ));
    }
    let dir = std::env::temp_dir().join(format!("tt-lab-rate-spec-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("rate-table-sf-spec.toml");
    std::fs::write(&file, text).unwrap();
    let s = tt_lab::loaded::load(Some(&file)).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    s
}

/// Relative tolerance of a ratio of two J stated to four digits (dimensionless).
const FOUR_DIGITS_REL: f64 = 1e-3;

/// The candidate rates of the rate-choice tests (deg/s), within every joint's limit.
const RATES_DEG_PER_S: [f64; 4] = [10.0, 30.0, 100.0, 300.0];

/// With the gyros' scale factors specified in ppm the rate choice holds them at every
/// candidate rate (rows over the angles and the rate tolerances, each rate's own noise): J is
/// never below eq 14's alone at the same rate (rows only add constraints), and at 10 deg/s,
/// where the noise over the rate is largest in ppm, the 30 ppm specification binds (J 18.7 %
/// above eq 14's: 8,993 against 7,576 arcmin^-2).
#[test]
fn scale_factor_specifications_in_ppm_enter_the_rate_choice_at_every_rate() {
    let plain = study("stim300-rate-table-example.toml");
    let eq14 =
        tt_lab::design::rates::choose(&plain, &plain.positions_deg, &RATES_DEG_PER_S).unwrap();
    let s = rate_table_with_scale_factor_specs(30.0);
    let spec = tt_lab::design::rates::choose(&s, &s.positions_deg, &RATES_DEG_PER_S).unwrap();
    for ((r, a), (_, b)) in eq14.candidates().iter().zip(spec.candidates()) {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!(b >= a * (1.0 - SAME_J_REL), "{r} deg/s: {b} vs eq 14's {a}");
    }
    let (a, b) = (
        eq14.candidates()[0].1.unwrap(),
        spec.candidates()[0].1.unwrap(),
    );
    approx::assert_relative_eq!(b / a, 1.187, max_relative = FOUR_DIGITS_REL);
}

/// The cost of answering every candidate against the specifications (a simulator per
/// evaluation): the design of the IMU example with its misalignment at 10 arcsec on the 90 deg
/// grid, with and without its specifications (seconds on this machine; not asserted, run by
/// hand: `cargo test -p tt-lab --test design_questions -- --ignored --nocapture cost`).
#[test]
#[ignore = "a timing, run by hand"]
fn cost_of_the_specified_objective() {
    let s = imu_with_tight_misalignment();
    let mut plain = s.clone();
    plain.specifications.clear();
    let mut o = Options::default();
    o.step_deg = 90.0;
    for (label, st) in [("eq 14", &plain), ("specified", &s)] {
        let a = design(st, &o, &|| {}).unwrap();
        let d = a.design();
        eprintln!(
            "{label}: {:.1} s, designed J {:.4} arcmin^-2, study's {:.4}, exact evaluations {}",
            a.seconds(),
            d.designed().allocation().objective_arcmin(),
            d.study().allocation().objective_arcmin(),
            d.search().designed().exact_evaluations()
        );
    }
}
