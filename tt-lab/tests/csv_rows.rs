//! Turntables as CSV rows read by the library (`tt_lab::rows::read_rows`, the reader of
//! `orientation-error` and `calibration-error`): RFC 4180 quoting, CRLF line ends, and every
//! bad cell named by its line and column.

use std::path::Path;
use study::Study;
use study::csv::{JointColumns, TurntableRow};
use tt_lab::InputError;

const HEADER: &str = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";
const ROW: &str = "30,45,0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1";

fn study() -> Study {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/gyrowheel-2017.toml");
    tt_lab::loaded::load(Some(&p)).unwrap()
}

/// Every row of `text`, with its line, or the first error.
fn read(text: &str) -> Result<Vec<(usize, TurntableRow)>, InputError> {
    let s = study();
    let mut rows = Vec::new();
    tt_lab::rows::read_rows(
        text.as_bytes(),
        "t.csv",
        &s.turntable,
        JointColumns::Required,
        |line, row| {
            rows.push((line, row));
            Ok(())
        },
    )?;
    Ok(rows)
}

/// The same text parsed the same way gives bit-identical rows: `TurntableRow`'s derived
/// equality is exact on purpose here (one decimal string, one parse).
#[test]
fn quoted_fields_read_as_their_unquoted_values() {
    let plain = read(&format!("{HEADER}\n{ROW}\n")).unwrap();
    let quoted_header = HEADER.replace("phi2_deg", "\"phi2_deg\"");
    let quoted_row = "\"30\", 45 ,\"0.4\",0.78,0.42,0.78,0.28,0.28,0.42,0.42,\"0.1\"";
    let quoted = read(&format!("{quoted_header}\n{quoted_row}\n")).unwrap();
    assert_eq!(quoted, plain);
    assert_eq!(quoted.len(), 1);
    assert_eq!(quoted[0].0, 2);
}

/// A quoted comma stays inside its field: the cell `"30,5"` is one cell that is not a number
/// (a reader splitting on commas saw twelve cells and blamed the count).
#[test]
fn a_quoted_comma_is_one_cell_named_by_its_line_and_column() {
    let row = ROW.replacen("30", "\"30,5\"", 1);
    let e = read(&format!("{HEADER}\n{row}\n")).unwrap_err();
    assert_eq!(e.location, "t.csv:2 column 1");
    assert!(e.reason.contains("`30,5` is not a number"), "{e}");
}

#[test]
fn a_crlf_file_reads_like_its_lf_twin() {
    let lf = read(&format!("{HEADER}\n{ROW}\n\n{ROW}\n")).unwrap();
    let crlf = read(&format!("\u{feff}{HEADER}\r\n{ROW}\r\n\r\n{ROW}\r\n")).unwrap();
    assert_eq!(crlf, lf);
    let lines: Vec<usize> = crlf.iter().map(|(l, _)| *l).collect();
    assert_eq!(lines, [2, 4], "blank line 3 skipped, lines counted");
}

#[test]
fn a_bad_cell_is_named_by_its_line_and_column() {
    let bad = ROW.replacen("0.78", "x", 1);
    let e = read(&format!("{HEADER}\r\n{ROW}\r\n{bad}\r\n")).unwrap_err();
    assert_eq!(e.location, "t.csv:3 column 4");
    assert!(
        e.reason.contains("`dphi_z2_arcmin`: `x` is not a number"),
        "{e}"
    );
    // after a record with a quoted line break, lines still count physical lines
    let broken_header = HEADER.replacen("phi1_deg", "\"phi1\n_deg\"", 1);
    let e = read(&format!("{broken_header}\n{ROW}\n")).unwrap_err();
    assert!(e.location.starts_with("t.csv:1 column 1"), "{e}");
    let e = read(&format!("{HEADER}\n\"a\nb\",{}\n{bad}\n", &ROW[3..])).unwrap_err();
    assert_eq!(e.location, "t.csv:2 column 1");
}

/// The reader's buffer stays bounded: a record longer than the limit is refused at its line,
/// also when the length hides inside quotes.
#[test]
fn a_record_longer_than_the_limit_is_refused_at_its_line() {
    let long = "1".repeat(tt_lab::records::MAX_LINE_BYTES + 1);
    let e = read(&format!("{HEADER}\n{ROW}\n{long}\n")).unwrap_err();
    assert_eq!(e.location, "t.csv:3");
    assert!(e.reason.contains("longer than"), "{e}");
    let lines = "\"".to_string() + &"2\n".repeat(tt_lab::records::MAX_LINE_BYTES / 2 + 1) + "\"";
    let e = read(&format!("{HEADER}\n{lines}\n")).unwrap_err();
    assert!(e.reason.contains("longer than"), "{e}");
}
