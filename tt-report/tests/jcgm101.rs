//! `report --jcgm101` as a library option (issue 34 item 3 in the report): the subsection's
//! numbers and `results.json`'s `jcgm101` are `tt_lab::budget_mc`'s for the same tolerances
//! and seed on the IMU example; without the option the report gains nothing.

use std::path::Path;
use tt_lab::budget_mc::{Jcgm101Json, MC_RULE, Options};
use tt_report::{Report, ReportOptions};

fn imu_example() -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/imu-triad-example.toml"),
    )
    .unwrap()
}

/// Relative agreement of a figure of `results.json` with the library's: the same f64
/// serialised and read back (shortest round-trip), so only the last bit may differ.
const SAME_FIGURE_REL: f64 = 1e-12;

/// The report's options: 2,000 turntables per box, seed 7, the Monte Carlo at one digit when
/// `mc`.
fn options(mc: bool) -> ReportOptions {
    let mut o = ReportOptions::default();
    o.samples = Some(2_000);
    o.seed = Some(7);
    o.jcgm101 = mc.then(|| Options {
        significant_digits: 1,
        ..Options::default()
    });
    o
}

#[test]
fn the_jcgm101_subsection_states_budget_mc_of_the_specifications_tolerances() {
    let s = imu_example();
    let report = Report::compute(s.clone(), options(true)).unwrap();
    let results = report.results().unwrap();
    // the library's run over the tolerances the specifications section evaluated, its seed
    let names = s.turntable.rotation_error_names();
    let tol: Vec<f64> = names
        .iter()
        .map(|n| {
            results["specifications"]["tolerances_rad"][*n]
                .as_f64()
                .unwrap_or(f64::INFINITY)
        })
        .collect();
    let e2e = tt_lab::loaded::simulator(&s).unwrap();
    let verdict = tt_lab::vendor::spec::compute(&s, &e2e, &tol)
        .unwrap()
        .unwrap();
    let o = Options {
        significant_digits: 1,
        seed: Some(7),
        ..Options::default()
    };
    let lib = tt_lab::budget_mc::compute(&s, &e2e, &tol, &verdict, &o).unwrap();
    let want = Jcgm101Json::new(&s, &lib);
    let got = &results["jcgm101"];
    assert_eq!(got["rule"].as_str(), Some(MC_RULE));
    assert_eq!(got["seed"].as_u64(), Some(7));
    assert_eq!(got["significant_digits"].as_u64(), Some(1));
    assert_eq!(got["meets"].as_bool(), Some(want.meets));
    let specs = got["specifications"].as_array().unwrap();
    assert_eq!(specs.len(), want.specifications.len());
    assert_eq!(specs.len(), s.specifications.len());
    let md = report.markdown().unwrap();
    for (j, w) in specs.iter().zip(&want.specifications) {
        assert_eq!(j["quantity"].as_str(), Some(w.quantity.as_str()));
        for (key, lib) in [
            ("mean", w.mean),
            ("standard_uncertainty", w.standard_uncertainty),
            ("numerical_tolerance", w.numerical_tolerance),
            ("limit", w.limit),
        ] {
            approx::assert_relative_eq!(
                j[key].as_f64().unwrap(),
                lib,
                max_relative = SAME_FIGURE_REL
            );
        }
        for (key, lib) in [
            ("symmetric_interval", w.symmetric_interval),
            ("shortest_interval", w.shortest_interval),
        ] {
            for k in 0..2 {
                approx::assert_relative_eq!(
                    j[key][k].as_f64().unwrap(),
                    lib[k],
                    max_relative = SAME_FIGURE_REL
                );
            }
        }
        assert_eq!(j["trials"].as_u64(), Some(w.trials));
        assert_eq!(j["stabilized"].as_bool(), Some(w.stabilized));
        assert_eq!(j["gum_validated"].as_bool(), Some(w.gum_validated));
        assert_eq!(j["meets"].as_bool(), Some(w.meets));
        // the table row states u(y) to four digits
        assert!(
            md.contains(&tt_core::human::sig(w.standard_uncertainty, 4)),
            "{}",
            w.quantity
        );
    }
    assert!(md.contains("### JCGM 101 Monte Carlo of each specification"));
    assert!(md.contains(&tt_lab::budget_mc::headline(&lib).replace('_', "\\_")));
    assert!(md.contains("jcgm101_intervals.svg"));
    assert!(
        md.contains("--jcgm101 --mc-digits 1"),
        "the reproducing command"
    );
    // the subsection sits under the specifications' section (after it, before the next)
    let spec_at = md.find("## Specifications: uncertainty budgets").unwrap();
    let mc_at = md.find("### JCGM 101 Monte Carlo").unwrap();
    assert!(spec_at < mc_at);
    assert!(
        !md[spec_at + 3..mc_at].contains("\n## "),
        "no section between"
    );
    assert!(
        report
            .files()
            .unwrap()
            .iter()
            .any(|f| f.name == "jcgm101_intervals.svg")
    );
}

/// `md` with the line "computed in X s" (wall clock) made constant.
fn without_seconds(md: &str) -> String {
    md.lines()
        .map(|l| match (l.find("computed in "), l.find(" s by the")) {
            (Some(a), Some(b)) if a < b => format!("{}{}", &l[..a], &l[b..]),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Without the option the report is the one before it: its Markdown is the report with the
/// option minus the subsection and the two flags of the reproducing command (the wall-clock
/// seconds aside), no figure of it and no `jcgm101` in `results.json`.
#[test]
fn without_jcgm101_the_report_has_no_subsection_and_is_otherwise_the_same() {
    let plain = Report::compute(imu_example(), options(false)).unwrap();
    let with = Report::compute(imu_example(), options(true)).unwrap();
    let md = plain.markdown().unwrap();
    assert!(
        !md.contains("JCGM 101"),
        "no Monte Carlo in the plain report"
    );
    assert!(plain.results().unwrap().get("jcgm101").is_none());
    assert!(
        !plain
            .files()
            .unwrap()
            .iter()
            .any(|f| f.name.contains("jcgm101"))
    );
    let md_with = with.markdown().unwrap();
    let start = md_with.find("### JCGM 101 Monte Carlo").unwrap();
    let end = start + md_with[start..].find("\n## ").unwrap() + 1;
    let cut = format!("{}{}", &md_with[..start], &md_with[end..])
        .replace(" --jcgm101 --mc-digits 1", "")
        .lines()
        // the contents' entry of the subsection
        .filter(|l| !l.contains("(#jcgm-101-monte-carlo-of-each-specification)"))
        .collect::<Vec<_>>()
        .join("\n");
    let (cut, md) = (without_seconds(&cut), without_seconds(&md));
    for (a, b) in cut.lines().zip(md.lines()) {
        assert_eq!(a, b, "the first line that differs");
    }
    // (the line joins above drop the file's final newline)
    assert_eq!(cut.trim_end(), md.trim_end());
    let mut r_with = with.results().unwrap();
    let mut r_plain = plain.results().unwrap();
    r_with.as_object_mut().unwrap().remove("jcgm101");
    for r in [&mut r_with, &mut r_plain] {
        r.as_object_mut().unwrap().remove("seconds");
    }
    assert_eq!(r_with, r_plain);
}

/// Issue 34: a budget row's sensitivity of numerical zero printed as `-1.11e-16` (the IMU
/// example, gx's bias against `dphi_o`): the table shows 0 for it and for its contribution,
/// `results.json` keeps the raw value (that `sig` printed before the fix).
#[test]
fn a_numerically_zero_sensitivity_is_shown_as_0_and_kept_raw_in_results() {
    let report = Report::compute(imu_example(), options(false)).unwrap();
    let results = report.results().unwrap();
    let gx_bias = &results["specifications"]["specifications"][0];
    assert_eq!(gx_bias["quantity"].as_str(), Some("gx bg_x (bias)"));
    let rows = gx_bias["budget"].as_array().unwrap();
    let largest = rows
        .iter()
        .map(|r| r["sensitivity"].as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    let raw = rows.iter().find(|r| r["name"] == "dphi_o").unwrap()["sensitivity"]
        .as_f64()
        .unwrap();
    assert!(raw != 0.0 && raw.abs() < 1e-12 * largest, "raw {raw}");
    let md = report.markdown().unwrap();
    let table = &md[md.find("### gx bg\\_x (bias)").unwrap()..];
    let row = table
        .lines()
        .find(|l| l.starts_with("| `dphi_o` |"))
        .unwrap();
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // | input | distribution | u(x) | c | contribution | dof |
    assert_eq!(cells[4], "0", "{row}");
    assert!(cells[5].starts_with("0 "), "{row}");
}
