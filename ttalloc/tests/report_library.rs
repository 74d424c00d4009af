//! The report library (`tt-report`) as `ttalloc` re-exports it and writes it: its own tests
//! (the model, the rendering) are in tt-report/tests.

use std::path::Path;
use ttalloc::{Report, ReportOptions};

/// Every file of a study's report (the specifications' figure included) has a name the
/// report writer accepts (`ttalloc::fuzzing::is_report_file`): `ttalloc report` can write
/// exactly `Report::files`, reached through `ttalloc`'s re-export.
#[test]
fn every_file_of_a_report_is_one_the_writer_accepts() {
    let s = study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/imu-triad-example.toml"),
    )
    .unwrap();
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    let files = Report::compute(s, options).unwrap().files().unwrap();
    assert!(
        files
            .iter()
            .any(|f| f.name == "specification_contributions.svg")
    );
    for f in &files {
        assert!(ttalloc::fuzzing::is_report_file(&f.name), "{}", f.name);
    }
}
