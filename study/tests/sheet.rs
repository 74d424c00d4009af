//! A study makes the tolerance sheet every check takes: the file's bounds and discs, the
//! study's lower bounds held within them, its measured errors with their uncertainties; a
//! measured table outside the sheet is refused naming both entries.

use std::path::{Path, PathBuf};
use study::{Study, Tolerances};

fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

#[test]
fn a_study_makes_the_sheet_of_a_file_with_its_lower_bounds_and_measurements() {
    let s = Study::load(&shipped("studies/three-axis-example-compensated.toml")).unwrap();
    let path = shipped("studies/tolerances/three-axis-vendor-sheet.toml");
    let tol = Tolerances::load(&path, &s.turntable).unwrap();
    let sheet = s.load_sheet(&path).unwrap();
    assert_eq!(sheet.upper_bounds_rad(), tol.ub_rad.as_slice());
    assert_eq!(sheet.discs(), tol.discs.as_slice());
    assert_eq!(sheet.source(), tol.path);
    assert_eq!(sheet.name(), tol.name.as_deref());
    for ((l, given), u) in sheet
        .lower_bounds_rad()
        .iter()
        .zip(&s.lower_bounds_rad)
        .zip(&tol.ub_rad)
    {
        assert_eq!(l.to_bits(), given.min(*u).to_bits());
    }
    let measured: Vec<bool> = sheet.measured().iter().map(Option::is_some).collect();
    let in_study: Vec<bool> = s.measured.iter().map(Option::is_some).collect();
    assert_eq!(measured, in_study);
    assert!(sheet.has_measured());
    // the compensated sheet drops the discs of measured errors and keeps the others
    let (c, _) = sheet.compensated().unwrap();
    assert!(c.discs().len() < sheet.discs().len());
    for d in c.discs() {
        assert!(d.errors.iter().all(|&j| s.measured[j].is_none()));
    }
}

/// The message check-turntable gave before the sheet was a library type, word for word.
#[test]
fn a_measured_table_outside_the_sheet_is_refused_naming_the_measurement_and_the_sheets_bound() {
    let path = shipped("studies/three-axis-example-compensated.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let sheet = shipped("studies/tolerances/three-axis-vendor-sheet.toml");
    let mut s = Study::parse("measured.toml", &text).unwrap();
    let (j, mut m) = s
        .measured
        .iter()
        .enumerate()
        .find_map(|(j, m)| m.clone().map(|m| (j, m)))
        .unwrap();
    // the first measured error, its constant term made ten times the sheet's bound
    let tol = Tolerances::load(&sheet, &s.turntable).unwrap();
    m.coefficients_rad[0] = 10.0 * tol.ub_rad[j];
    s.measured[j] = Some(m.clone());
    let e = tol.sheet(&s).unwrap_err();
    assert_eq!(e.location, format!("measured.toml: key `{}`", m.key));
    let name = s.turntable.rotation_error_names()[j];
    assert!(
        e.reason.starts_with(&format!("the measured `{name}` = ")),
        "{}",
        e.reason
    );
    assert!(
        e.reason.contains("the measured table is outside its specification, which the check assumes it meets; check the measurement, or check a sheet that bounds this table"),
        "{}",
        e.reason
    );
    assert!(e.reason.contains(&tol.path), "{}", e.reason);
}
