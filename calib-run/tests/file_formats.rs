//! The calibration file in JSON and in TOML (chosen by the extension): the same content, the
//! same correction; any other extension refused naming `--out`, nothing written.

mod common;

use calib_run::file::{CalibrationFile, Format, apply, write_new};
use calib_run::{CalibrateOptions, RunError, calibrate};
use common::{record, settings, study};

fn corrected(file: &CalibrationFile, name: &str, rec: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    apply(file, name, rec, "log.csv", &Default::default(), &mut out).expect("applied");
    out
}

#[test]
fn the_toml_and_json_files_of_one_run_parse_to_equal_calibrations_and_correct_identically() {
    let s = study("imu-six-face-three-rotation.toml");
    let rec = record(&s, &s.sensor, &settings(&s, 50.0, 10.0, 5));
    let run = calibrate(&s, rec.as_slice(), "log.csv", &CalibrateOptions::default()).expect("ok");
    let file = CalibrationFile::of(&run);
    let dir = tempfile::tempdir().expect("dir");
    let json = dir.path().join("cal.json");
    let toml = dir.path().join("cal.toml");
    write_new(&json, &file).expect("JSON written");
    write_new(&toml, &file).expect("TOML written");
    let toml_text = std::fs::read_to_string(&toml).expect("read");
    // TOML indeed (a JSON parser refuses it), and not the JSON text
    assert!(serde_json::from_str::<serde_json::Value>(&toml_text).is_err());
    assert!(
        toml_text.contains("format = \"calib-run/1\""),
        "{toml_text}"
    );
    let from_json =
        CalibrationFile::parse("cal.json", &std::fs::read_to_string(&json).expect("read"))
            .expect("JSON parsed");
    let from_toml = CalibrationFile::parse("cal.toml", &toml_text).expect("TOML parsed");
    // equal to the bit: every value round-trips through either text
    assert_eq!(from_toml, from_json);
    assert_eq!(from_toml, file);
    assert_eq!(
        corrected(&from_toml, "cal.toml", &rec),
        corrected(&from_json, "cal.json", &rec)
    );
}

#[test]
fn a_calibration_file_named_neither_json_nor_toml_is_refused_naming_out_and_not_written() {
    let s = study("imu-six-face-three-rotation.toml");
    let rec = record(&s, &s.sensor, &settings(&s, 50.0, 10.0, 5));
    let run = calibrate(&s, rec.as_slice(), "log.csv", &CalibrateOptions::default()).expect("ok");
    let dir = tempfile::tempdir().expect("dir");
    for name in ["cal.yaml", "cal", "cal.json.bak"] {
        let path = dir.path().join(name);
        match write_new(&path, &CalibrationFile::of(&run)) {
            Err(RunError::Option { field, reason }) => {
                assert_eq!(field, "--out");
                assert!(
                    reason.contains(name) && reason.contains(".toml"),
                    "{reason}"
                );
            }
            other => panic!("{name}: {other:?}"),
        }
        assert!(!path.exists(), "{name} written");
    }
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
    assert_eq!(
        Format::of_path(std::path::Path::new("CAL.TOML"), "--out").expect("toml"),
        Format::Toml
    );
}

#[test]
fn a_toml_calibration_file_that_is_not_one_is_refused_naming_the_file() {
    match CalibrationFile::parse("cal.toml", "format = \"calib-run/1\"\n") {
        Err(RunError::CalibrationFile { path, reason }) => {
            assert_eq!(path, "cal.toml");
            assert!(reason.contains("missing field"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
}
