//! The report as a library (issue 20 item 4): computed and rendered without running the binary
//! or touching the disk; its Markdown, its results model and its files agree.

use std::path::Path;
use ttalloc::{Report, ReportOptions};

fn paper_study() -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/gyrowheel-2017.toml"),
    )
    .unwrap()
}

/// The paper's report through the library: the files `ttalloc report` writes (Markdown, HTML,
/// figures, results), the Markdown states Table 4's end-to-end verdict under the user's
/// reading (0.0159 deg/h against 0.01, README "What we find"), and the results model carries
/// the same seed and samples as asked.
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
}

/// Too few samples to resolve the yield target is the caller's input error, naming it.
#[test]
fn too_few_samples_is_an_input_error() {
    let mut options = ReportOptions::default();
    options.samples = Some(10);
    let err = Report::compute(paper_study(), options).unwrap_err();
    let input = err
        .downcast_ref::<ttalloc::InputError>()
        .expect("an input error");
    assert!(input.to_string().contains("samples"), "{input}");
}
