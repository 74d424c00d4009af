//! Bad recordings and segments are typed errors naming the line, the column or the segment;
//! mismatches that leave the estimate sound are stated warnings; the calibration file is never
//! overwritten.

mod common;

use calib_run::segments::parse_segments;
use calib_run::{CalibrateOptions, RunError, calibrate};
use common::{record, settings, study};

fn six() -> (study::Study, Vec<u8>) {
    let s = study("imu-six-face-three-rotation.toml");
    let rec = record(&s, &s.sensor, &settings(&s, 50.0, 10.0, 5));
    (s, rec)
}

fn text(rec: &[u8]) -> String {
    String::from_utf8(rec.to_vec()).expect("utf8")
}

/// The recording with data line `line` (1-based in the file) replaced by `f(line text)`.
fn with_line(rec: &[u8], line: usize, f: impl Fn(&str) -> String) -> Vec<u8> {
    text(rec)
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { f(l) } else { l.to_string() } + "\n")
        .collect::<String>()
        .into_bytes()
}

fn err(s: &study::Study, rec: &[u8], o: &CalibrateOptions) -> RunError {
    calibrate(s, rec, "log.csv", o).expect_err("rejected")
}

#[test]
fn a_non_numeric_cell_names_its_line_and_column() {
    let (s, rec) = six();
    let bad = with_line(&rec, 40, |l| {
        let mut c: Vec<&str> = l.split(',').collect();
        c[2] = "abc";
        c.join(",")
    });
    let e = err(&s, &bad, &CalibrateOptions::default()).to_string();
    assert!(e.starts_with("log.csv:40 (column `gy`)"), "{e}");
    assert!(e.contains("`abc` is not a number"), "{e}");
}

#[test]
fn a_nan_cell_is_rejected_by_line_and_column() {
    let (s, rec) = six();
    let bad = with_line(&rec, 7, |l| {
        let mut c: Vec<&str> = l.split(',').collect();
        c[5] = "NaN";
        c.join(",")
    });
    let e = err(&s, &bad, &CalibrateOptions::default()).to_string();
    assert!(
        e.starts_with("log.csv:7 (column `ay`)") && e.contains("not a finite number"),
        "{e}"
    );
}

#[test]
fn a_missing_output_column_is_named() {
    let (s, rec) = six();
    let bad = text(&rec).replacen("t_s,gx,gy,gz,ax", "t_s,gx,gy,gz,bx", 1);
    let e = err(&s, bad.as_bytes(), &CalibrateOptions::default()).to_string();
    assert!(e.contains("no column `ax` for output `ax`"), "{e}");
}

#[test]
fn time_that_goes_back_and_a_gap_are_named_by_line() {
    let (s, rec) = six();
    let back = with_line(&rec, 30, |l| {
        let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
        c[0] = "0.1".into();
        c.join(",")
    });
    let e = err(&s, &back, &CalibrateOptions::default()).to_string();
    assert!(
        e.starts_with("log.csv:30 (column `t_s`)") && e.contains("does not increase"),
        "{e}"
    );
    // drop ten rows: a gap
    let gap: String = text(&rec)
        .lines()
        .enumerate()
        .filter(|(i, _)| !(100..110).contains(i))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let e = err(&s, gap.as_bytes(), &CalibrateOptions::default()).to_string();
    assert!(
        e.starts_with("log.csv:101 (column `t_s`)") && e.contains("gap"),
        "{e}"
    );
}

#[test]
fn a_row_of_the_wrong_length_is_named_by_line() {
    let (s, rec) = six();
    let bad = with_line(&rec, 12, |l| format!("{l},7"));
    let e = err(&s, &bad, &CalibrateOptions::default()).to_string();
    assert!(
        e.starts_with("log.csv:12") && e.contains("fields where the header has"),
        "{e}"
    );
}

#[test]
fn a_recording_cut_short_has_fewer_segments_than_the_schedule_needs() {
    let (s, rec) = six();
    let cut: String = text(&rec)
        .lines()
        .take(1500)
        .map(|l| format!("{l}\n"))
        .collect();
    match err(&s, cut.as_bytes(), &CalibrateOptions::default()) {
        RunError::Segments { reason } => assert!(
            reason.contains("fewer segments than the schedule needs"),
            "{reason}"
        ),
        other => panic!("{other}"),
    }
}

#[test]
fn saturated_samples_are_a_stated_warning_naming_the_column() {
    let (s, rec) = six();
    let mut o = CalibrateOptions::default();
    // the accelerometers read up to ~1000 mg: a 990 mg range saturates the +1 g faces
    o.recording.range = Some(990.0);
    let run = calibrate(&s, rec.as_slice(), "log.csv", &o).expect("still estimated");
    assert!(
        run.warnings()
            .iter()
            .any(|w| w.contains("column `az`") && w.contains("saturated")),
        "{:?}",
        run.warnings()
    );
    assert!(
        run.warnings()
            .iter()
            .any(|w| w.contains("segment of entry 0") && w.contains("saturated"))
    );
}

#[test]
fn segments_files_with_overlaps_bad_kinds_and_missing_entries_are_named() {
    let overlap = "start,end,entry\n0,100,0\n50,150,1\n";
    let e = parse_segments(overlap.as_bytes(), "seg.csv", 2, 0)
        .expect_err("overlap")
        .to_string();
    assert!(
        e.starts_with("seg.csv:3 (column `start`)") && e.contains("overlaps the segment of line 2"),
        "{e}"
    );
    let kind = "start,end,entry,kind\n0,100,0,rotation\n";
    let e = parse_segments(kind.as_bytes(), "seg.csv", 1, 1)
        .expect_err("kind")
        .to_string();
    assert!(
        e.starts_with("seg.csv:2") && e.contains("is a static position but the kind is rotation"),
        "{e}"
    );
    let missing = "start,end,entry\n0,100,0\n";
    let e = parse_segments(missing.as_bytes(), "seg.csv", 2, 1)
        .expect_err("missing")
        .to_string();
    assert!(e.contains("no segment for entries 1, 2"), "{e}");
    let range = "start,end,entry\n0,100,5\n";
    let e = parse_segments(range.as_bytes(), "seg.csv", 2, 0)
        .expect_err("range")
        .to_string();
    assert!(e.contains("entry 5 is outside the schedule"), "{e}");
}

#[test]
fn a_segment_beyond_the_recording_is_out_of_range() {
    let (s, rec) = six();
    let mut specs = String::from("start,end,entry\n");
    for e in 0..9 {
        let start = e * 600;
        specs.push_str(&format!(
            "{start},{},{e}\n",
            start + 500 + if e == 8 { 1_000_000 } else { 0 }
        ));
    }
    let o = CalibrateOptions {
        segments: Some(parse_segments(specs.as_bytes(), "seg.csv", 6, 3).expect("parsed")),
        ..CalibrateOptions::default()
    };
    match err(&s, &rec, &o) {
        RunError::Segments { reason } => assert!(
            reason.contains("line 10") && reason.contains("out of range"),
            "{reason}"
        ),
        other => panic!("{other}"),
    }
}

#[test]
fn the_calibration_file_is_never_overwritten() {
    let (s, rec) = six();
    let run = calibrate(&s, rec.as_slice(), "log.csv", &CalibrateOptions::default()).expect("ok");
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("cal.json");
    std::fs::write(&path, "mine").expect("write");
    let file = calib_run::file::CalibrationFile::of(&run);
    match calib_run::file::write_new(&path, &file) {
        Err(RunError::Exists { .. }) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(std::fs::read_to_string(&path).expect("read"), "mine");
    // a new name is written, and reads back
    let fresh = dir.path().join("new.json");
    calib_run::file::write_new(&fresh, &file).expect("written");
    let back = calib_run::file::CalibrationFile::parse(
        "new.json",
        &std::fs::read_to_string(&fresh).expect("read"),
    )
    .expect("parsed");
    assert_eq!(back, file);
}

#[test]
fn apply_recovers_the_inputs_of_a_simulated_recording() {
    // the study's own coefficients as truth: apply with them maps the outputs back to inputs
    // whose specific force has magnitude 1 g at rest (first sample: z up)
    let (s, rec) = six();
    let run = calibrate(&s, rec.as_slice(), "log.csv", &CalibrateOptions::default()).expect("ok");
    let file = calib_run::file::CalibrationFile::of(&run);
    let mut out = Vec::new();
    let summary = calib_run::file::apply(
        &file,
        "cal.json",
        rec.as_slice(),
        "log.csv",
        &Default::default(),
        &mut out,
    )
    .expect("applied");
    assert_eq!(summary.columns.len(), 6);
    let first = text(&out)
        .lines()
        .nth(1)
        .expect("row")
        .split(',')
        .map(|v| v.parse::<f64>().expect("num"))
        .collect::<Vec<_>>();
    // a_z within 3 sigma of one sample's noise (0.4 mg/sqrt(Hz) at 50 Hz: 2.8 mg) of 1 g
    assert!((first[3] - 1.0).abs() < 0.01, "{first:?}");
    assert!(summary.max_mismatch < 1e-9);
}
