//! `ttalloc report --recording LOG.csv` (issue 36 item 5): the report gains a "Processed run"
//! section from the recording, processed with calibrate's own flags; a bad recording exits 2
//! naming its line and column and leaves no report directory; a recording flag without
//! `--recording` is refused naming the flag.

mod common;

use common::{
    assert_input_error, names, ok, run as ttalloc, six_face_recording as recording,
    six_face_recording_with_a_bad_cell, six_face_study as study_path,
};
use std::path::Path;

/// `report` of the six-face study (2,000 Monte Carlo samples) into `out` with the recording
/// `log` and `extra` flags.
fn report(out: &Path, log: &Path, extra: &[&str]) -> std::process::Output {
    let study = study_path();
    let mut tail = vec!["--recording", log.to_str().expect("utf8")];
    tail.extend_from_slice(extra);
    ttalloc(&common::report_args(&study, out, "2000", &tail))
}

#[test]
fn report_with_a_recording_writes_the_processed_run_section_and_its_figures() {
    let dir = tempfile::tempdir().expect("dir");
    let log = recording(dir.path());
    let out = dir.path().join("report");
    let o = report(&out, &log, &["--spec", "bg_x=100", "--robust"]);
    ok(&o);
    let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(md.contains("## Processed run"), "no section");
    let sha = calib_run::recording::sha256_hex(&std::fs::read(&log).expect("log"));
    assert!(md.contains(&sha), "the recording's hash");
    assert!(
        md.contains("specification 100: meets"),
        "the --spec verdict"
    );
    assert!(
        md.contains("--spec bg_x=100 --robust"),
        "the reproducing command"
    );
    for f in ["fig_run_segments.svg", "fig_run_residuals.svg"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).expect("json"))
            .expect("parsed");
    assert_eq!(
        json["processed_run"]["run"]["segments"]
            .as_array()
            .expect("segments")
            .len(),
        9
    );
    assert_eq!(json["processed_run"]["run"]["robust"], true);
}

#[test]
fn report_with_a_bad_recording_exits_2_naming_line_and_column_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("dir");
    let bad_path = six_face_recording_with_a_bad_cell(dir.path());
    let out = dir.path().join("report");
    let o = report(&out, &bad_path, &[]);
    assert_input_error(&o, &["bad.csv:20 (column `gx`)", "is not a number"]);
    assert!(!out.exists(), "no report directory left behind");
    assert_eq!(
        names(dir.path()),
        ["bad.csv", "run.csv"],
        "only the two recordings"
    );
}

#[test]
fn a_recording_flag_without_a_recording_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().expect("dir");
    let out = dir.path().join("report");
    let o = ttalloc(&[
        "report",
        "--study",
        &study_path(),
        "--out",
        out.to_str().expect("utf8"),
        "--robust",
    ]);
    assert_input_error(&o, &["--robust", "--recording"]);
    assert!(!out.exists());
}
