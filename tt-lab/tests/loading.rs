//! Loading a study: typed errors that name the file and key, and the paper's study as shipped.

use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// A study key the schema does not know is an input error naming the file and the key.
#[test]
fn unknown_study_key_is_an_input_error_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(root().join("studies/gyrowheel-2017.toml")).unwrap();
    std::fs::write(&path, format!("not_a_key = 1\n{text}")).unwrap();
    let err = tt_lab::loaded::load(Some(&path)).unwrap_err();
    assert!(err.location.contains("bad.toml"), "{err}");
    assert!(err.to_string().contains("not_a_key"), "{err}");
    let lab: tt_lab::LabError = err.into();
    assert!(lab.input().is_some());
}

/// The paper's study loads with its requirement, one pose per schedule entry, and a simulator.
#[test]
fn paper_study_loads_with_its_requirement_poses_and_simulator() {
    let s = tt_lab::loaded::load(Some(&root().join("studies/gyrowheel-2017.toml"))).unwrap();
    let r = tt_lab::loaded::requirement(&s).unwrap();
    // the paper's study states its requirement (section 4.1), and it agrees with eq 15-16
    assert_eq!(
        r.given,
        matches!(s.requirement, study::RequirementSource::Given { .. })
    );
    assert!(r.used.is_some());
    assert!(r.computed.is_ok());
    assert_eq!(
        tt_lab::loaded::poses(&s).unwrap().len(),
        s.schedule_angles_deg().len()
    );
    tt_lab::loaded::simulator(&s).unwrap();
}
