//! The report as a library (issue 20 item 4): computed and rendered without running the binary
//! or touching the disk; its Markdown, its results model and its files agree.

use std::path::Path;
use tt_report::{Error, Report, ReportOptions};

fn paper_study() -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/gyrowheel-2017.toml"),
    )
    .unwrap()
}

/// The paper's report through the library: the files `ttalloc report` writes (Markdown, HTML,
/// figures, results), the Markdown states Table 4's end-to-end verdict under the user's
/// reading (0.0159 deg/h against 0.01, README "What we find"), and the results model carries
/// the same seed and samples as asked, and each reading's end to end with exactly its keys
/// (`unconstrained` and `no_bound_needed` beside the boxes, as before they came from the view
/// tt-lab's `end-to-end --json` shares).
#[test]
fn the_paper_report_renders_from_the_library_with_its_verdict_and_results() {
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    options.seed = Some(5);
    options.paper = true;
    let report = Report::compute(paper_study(), options).unwrap();
    let files = report.files().unwrap();
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    for wanted in ["report.md", "report.html", "results.json"] {
        assert!(names.contains(&wanted), "{names:?}");
    }
    assert!(names.iter().any(|n| n.ends_with(".svg")), "{names:?}");
    let md = report.markdown().unwrap();
    assert!(md.contains("Table 4"));
    assert!(md.contains("0.0159"), "Table 4 under the user's reading");
    let results = report.results().unwrap();
    assert_eq!(results["seed"], 5);
    assert_eq!(results["samples"], 2_000);
    let readings = results["end_to_end"].as_array().unwrap();
    assert_eq!(readings.len(), 2, "the paper's and the user's reading");
    for r in readings {
        let keys: Vec<&str> = r.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(
            keys,
            [
                "boxes",
                "direct",
                "direct_certified",
                "direct_certified_note",
                "no_bound_needed",
                "reading",
                "unconstrained",
                "yield_based",
                "yield_target",
                "yield_verdict",
            ]
        );
        // every error of the paper's table is constrained by some output
        assert_eq!(r["unconstrained"], serde_json::json!([]));
        assert_eq!(r["no_bound_needed"], false);
    }
}

/// Too few samples to resolve the yield target is the caller's input error, naming it.
#[test]
fn too_few_samples_is_an_input_error() {
    let mut options = ReportOptions::default();
    options.samples = Some(10);
    let err = Report::compute(paper_study(), options).unwrap_err();
    let Error::Lab(tt_lab::LabError::Input(input)) = &err else {
        panic!("an input error, got {err}");
    };
    assert!(input.to_string().contains("samples"), "{input}");
}

fn study_named(file: &str) -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../studies")
            .join(file),
    )
    .unwrap()
}

/// Relative agreement of a figure the report states with the library's: both are the same
/// f64 serialised and read back (shortest round-trip), so only the last bit may differ.
const SAME_FIGURE_REL: f64 = 1e-12;

/// Issue 34 item 2: for a study with `[[specifications]]` the report's results model carries,
/// per specification, the GUM budget the library computes for the same plan (the direct
/// allocation's box it states, the study's law, noise and timing): U, u_c, k, the ratio, the
/// verdict and every row's contribution and dof, in the specification's unit; the Markdown
/// gains the section with one table per specification, the rule, the contributions figure,
/// and the study's names shown literally (`bg_x` is escaped in Markdown and renders as
/// written).
#[test]
fn the_specifications_section_states_the_library_budget_of_every_specification() {
    let s = study_named("imu-triad-example.toml");
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    let report = Report::compute(s.clone(), options).unwrap();
    let results = report.results().unwrap();
    let spec = &results["specifications"];
    let names = s.turntable.rotation_error_names();
    let tol: Vec<f64> = names
        .iter()
        .map(|n| spec["tolerances_rad"][*n].as_f64().unwrap_or(f64::INFINITY))
        .collect();
    let poses: Vec<tt_core::Pose> = s
        .schedule_angles_deg()
        .iter()
        .map(|p| tt_core::Pose::from_deg(p).unwrap())
        .collect();
    let e2e = e2e_verify::EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading).unwrap();
    let law = s.uncertainty.tolerance_distribution;
    let v = e2e
        .budget()
        .plan_verdict(
            &s.specifications,
            &tol,
            |n, a| law.input(n, a),
            &s.noise,
            s.timing.as_ref(),
        )
        .unwrap();
    let specs = spec["specifications"].as_array().unwrap();
    assert_eq!(specs.len(), s.specifications.len());
    assert_eq!(spec["meets"].as_bool(), Some(v.meets_all()));
    let md = report.markdown().unwrap();
    for (b, (sp, j)) in v.budgets().iter().zip(s.specifications.iter().zip(specs)) {
        let f = sp.to_written();
        let o = b.output();
        for (key, lib) in [
            ("expanded", o.expanded() * f),
            ("combined_standard_uncertainty", o.combined() * f),
            ("coverage_factor", o.coverage_factor()),
            ("ratio", b.check().ratio()),
        ] {
            approx::assert_relative_eq!(
                j[key].as_f64().unwrap(),
                lib,
                max_relative = SAME_FIGURE_REL
            );
        }
        assert_eq!(j["meets"].as_bool(), Some(v.meets(b.spec())));
        let rows = j["budget"].as_array().unwrap();
        assert_eq!(rows.len(), b.result().rows().len());
        for ((r, u), jr) in b.result().rows().iter().zip(o.contributions()).zip(rows) {
            assert_eq!(jr["name"].as_str(), Some(r.name()));
            approx::assert_relative_eq!(
                jr["contribution"].as_f64().unwrap(),
                u.abs() * f,
                max_relative = SAME_FIGURE_REL
            );
            assert_eq!(jr["dof"].as_f64(), r.dof().is_finite().then(|| r.dof()));
        }
        // one table per specification, under a heading naming its quantity
        let label = sp.label(&s.sensor).replace('_', "\\_");
        assert!(md.contains(&format!("### {label}")), "{label}");
    }
    assert!(md.contains("## Specifications: uncertainty budgets and the decision rule"));
    assert!(md.contains("specification_contributions.svg"));
    assert!(md.contains("rule: "), "the headline states the rule");
    assert!(md.contains("bg\\_x"), "the coefficient's name escaped");
    let mut html = String::new();
    pulldown_cmark::html::push_html(&mut html, pulldown_cmark::Parser::new(&md));
    assert!(html.contains("gx bg_x (bias)"), "rendered as written");
    // the new figure is one of the report's files (that `ttalloc report` accepts every name:
    // ttalloc/tests/report_library.rs)
    let files = report.files().unwrap();
    assert!(
        files
            .iter()
            .any(|f| f.name == "specification_contributions.svg")
    );
}

/// A study without specifications gets no such section and no `specifications` in its
/// results (the paper's report is otherwise the one before issue 34 item 2).
#[test]
fn a_study_without_specifications_has_no_specifications_section() {
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    let report = Report::compute(paper_study(), options).unwrap();
    let md = report.markdown().unwrap();
    assert!(!md.contains("Specifications: uncertainty budgets"));
    assert!(report.results().unwrap().get("specifications").is_none());
}
