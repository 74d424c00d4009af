//! `--jcgm101` of `check-turntable` and `end-to-end` (issue 34 item 3): the JCGM 101 Monte
//! Carlo of every specification printed and in `--json` with the library's numbers, its rule
//! named, the same answer for one thread and two, a bad `--mc-digits` (or one without
//! `--jcgm101`) refused with exit 2.

mod common;

use approx::assert_relative_eq;
use common::{assert_input_error, check_turntable, end_to_end_json, json, num, run, stdout};
use e2e_verify::budget_mc::MC_RULE;
use metrology::montecarlo::McSettings;

const STUDY: &str = "studies/imu-triad-example.toml";
const SHEET: &str = "studies/tolerances/three-axis-navigation-grade.toml";

/// The CLI prints the library's figures through JSON (shortest round-trip): equal to a few
/// ulps after the unit conversion.
const SAME_REL: f64 = 1e-12;

fn check_args(extra: &[&'static str]) -> Vec<&'static str> {
    let mut a = check_turntable(
        STUDY,
        SHEET,
        "2000",
        &["--seed", "5", "--jcgm101", "--mc-digits", "1"],
    );
    a.extend_from_slice(extra);
    a
}

#[test]
fn check_turntable_jcgm101_gives_every_specification_the_librarys_monte_carlo() {
    let v = json(&check_args(&["--json"]));
    let mc = &v["jcgm101"];
    assert_eq!(mc["rule"].as_str().unwrap(), MC_RULE);
    assert_eq!(mc["seed"].as_u64().unwrap(), 5);
    assert_eq!(mc["significant_digits"].as_u64().unwrap(), 1);
    let specs = mc["specifications"].as_array().unwrap();
    // the library's run over the same sheet, law, noise and seed
    let common::LibraryPlan {
        study: s,
        tolerances: tol,
        e2e,
        verdict,
    } = common::library_plan(std::path::Path::new(STUDY), SHEET);
    let law = s.uncertainty.tolerance_distribution;
    let table: Vec<_> = e2e
        .error_names()
        .iter()
        .zip(&tol.ub_rad)
        .map(|(n, &a)| law.input(n, a).unwrap())
        .collect();
    let settings = McSettings {
        significant_digits: 1,
        seed: 5,
        max_trials: tt_lab::budget_mc::DEFAULT_MAX_TRIALS,
        ..McSettings::default()
    };
    let lib = e2e
        .budget()
        .specification_monte_carlo(&s.specifications, &verdict, &table, &settings)
        .unwrap();
    assert_eq!(specs.len(), s.specifications.len());
    for ((j, m), sp) in specs.iter().zip(&lib).zip(&s.specifications) {
        let f = sp.to_written();
        let o = m.output();
        assert_relative_eq!(num(&j["mean"]), o.estimate() * f, max_relative = SAME_REL);
        assert_relative_eq!(
            num(&j["standard_uncertainty"]),
            o.standard_uncertainty() * f,
            max_relative = SAME_REL
        );
        for (key, (lo, hi)) in [
            ("symmetric_interval", o.symmetric()),
            ("shortest_interval", o.shortest()),
        ] {
            assert_relative_eq!(num(&j[key][0]), lo * f, max_relative = SAME_REL);
            assert_relative_eq!(num(&j[key][1]), hi * f, max_relative = SAME_REL);
        }
        assert_eq!(j["trials"].as_u64().unwrap(), m.trials());
        assert_eq!(j["stabilized"].as_bool().unwrap(), m.stabilized());
        assert_eq!(
            j["gum_validated"].as_bool().unwrap(),
            m.validation().validated()
        );
        assert_eq!(j["meets"].as_bool().unwrap(), m.meets());
        assert!(m.stabilized());
    }
    // the GUM verdict stays beside it
    assert_eq!(
        v["decision"]["specifications"].as_array().unwrap().len(),
        specs.len()
    );
    // without the flag, no key and no run
    let plain = json(&check_turntable(STUDY, SHEET, "2000", &["--json"]));
    assert!(plain.get("jcgm101").is_none());
}

/// The text of a run with `RAYON_NUM_THREADS` threads.
fn text_on(threads: &str) -> String {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_ttalloc"))
        .args(check_args(&[]))
        .current_dir(common::root())
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    stdout(&o)
}

#[test]
fn jcgm101_text_names_its_rule_and_is_the_same_on_one_thread_and_two() {
    let one = text_on("1");
    assert_eq!(one, text_on("2"));
    assert!(
        one.contains("JCGM 101 Monte Carlo of each specification"),
        "{one}"
    );
    assert!(one.contains(MC_RULE), "{one}");
    let lines = one
        .lines()
        .filter(|l| l.contains("% symmetric [") && l.contains("shortest ["))
        .count();
    assert_eq!(lines, 5, "one line per specification of the example: {one}");
    assert!(one.contains("stabilized"), "{one}");
}

#[test]
fn jcgm101_digits_out_of_range_exit_2_naming_the_flag() {
    for bad in ["0", "7", "two"] {
        for cmd in ["check-turntable", "end-to-end"] {
            let mut args = vec![cmd, "--study", STUDY, "--jcgm101", "--mc-digits", bad];
            if cmd == "check-turntable" {
                args.extend(["--tolerances", SHEET]);
            }
            assert_input_error(&run(&args), &["--mc-digits", bad]);
        }
    }
}

/// `--mc-digits` tunes the Monte Carlo only: without `--jcgm101` it is refused (it was
/// accepted and ignored), naming both flags.
#[test]
fn mc_digits_without_jcgm101_exits_2_naming_both_flags() {
    for cmd in ["check-turntable", "end-to-end"] {
        let mut args = vec![cmd, "--study", STUDY, "--mc-digits", "3"];
        if cmd == "check-turntable" {
            args.extend(["--tolerances", SHEET]);
        }
        assert_input_error(&run(&args), &["--mc-digits", "--jcgm101"]);
    }
}

#[test]
fn end_to_end_jcgm101_adds_the_monte_carlo_of_the_direct_allocations_box() {
    let v = end_to_end_json(STUDY, "2000", &["--jcgm101", "--mc-digits", "1"]);
    let mc = &v["jcgm101"];
    assert_eq!(mc["rule"].as_str().unwrap(), MC_RULE);
    let specs = mc["specifications"].as_array().unwrap();
    assert_eq!(specs.len(), 5);
    for j in specs {
        let (lo, hi) = (
            num(&j["symmetric_interval"][0]),
            num(&j["symmetric_interval"][1]),
        );
        assert!(lo < hi, "{j}");
        assert!(num(&j["standard_uncertainty"]) > 0.0, "{j}");
        // the verdict is the rule's: the symmetric interval within +-limit
        assert_eq!(
            j["meets"].as_bool().unwrap(),
            lo.abs().max(hi.abs()) <= num(&j["limit"]),
            "{j}"
        );
    }
    assert_eq!(
        mc["meets"].as_bool().unwrap(),
        specs.iter().all(|j| j["meets"].as_bool().unwrap())
    );
}

/// `report --jcgm101` into a fresh directory with `RAYON_NUM_THREADS` threads: the
/// Markdown's Monte Carlo subsection (up to the next section) and `results.json`'s
/// `jcgm101`.
fn report_on(threads: &str) -> (String, serde_json::Value) {
    let dir = tempfile::tempdir().expect("dir");
    let out = dir.path().join("r");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_ttalloc"))
        .args([
            "report",
            "--study",
            STUDY,
            "--samples",
            "2000",
            "--seed",
            "5",
            "--jcgm101",
            "--mc-digits",
            "1",
            "--out",
            out.to_str().expect("utf8"),
        ])
        .current_dir(common::root())
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    let start = md
        .find("### JCGM 101 Monte Carlo of each specification")
        .expect("the subsection");
    let end = start + md[start..].find("\n## ").expect("a next section");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).expect("json"))
            .expect("parsed");
    assert!(out.join("jcgm101_intervals.svg").exists());
    (md[start..end].to_string(), json["jcgm101"].clone())
}

#[test]
fn report_jcgm101_writes_the_subsection_the_same_on_one_thread_and_two() {
    let (one, json) = report_on("1");
    let (two, json_two) = report_on("2");
    assert_eq!(one, two);
    assert_eq!(json, json_two);
    assert_eq!(json["rule"].as_str().unwrap(), MC_RULE);
    assert_eq!(json["seed"].as_u64().unwrap(), 5);
    assert_eq!(json["specifications"].as_array().unwrap().len(), 5);
    // one table row per specification, the verdict with its rule
    let rows = one
        .lines()
        .filter(|l| l.starts_with("| gx ") || l.starts_with("| ax "))
        .count();
    assert_eq!(rows, 5, "{one}");
    assert!(one.contains("Monte Carlo verdict: "), "{one}");
}

#[test]
fn report_mc_digits_without_jcgm101_exits_2_naming_both_flags() {
    let dir = tempfile::tempdir().expect("dir");
    let out = dir.path().join("r");
    let o = run(&[
        "report",
        "--study",
        STUDY,
        "--mc-digits",
        "2",
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert_input_error(&o, &["--mc-digits", "--jcgm101"]);
    assert!(!out.exists(), "nothing written");
}
