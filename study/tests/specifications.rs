//! Specifications per coefficient (`[[specifications]]`, `[uncertainty]`): each kind in its
//! units converted to the model's, and every bad input a typed error naming the key.

use approx::assert_relative_eq;
use gw_model::spec::{CoefficientKind, Resolved};
use study::Study;
use study::spec::ToleranceDistribution;

const IMU_FILE: &str = include_str!("../../studies/imu-triad-example.toml");

/// The IMU example without its own specifications (the tests add theirs).
fn imu_bare() -> &'static str {
    &IMU_FILE[..IMU_FILE
        .find("# Specifications per calibrated quantity")
        .expect("the IMU example's specifications")]
}

/// Unit conversions are exact up to a few ulps (relative).
const CONVERSION_REL: f64 = 1e-14;

/// The IMU example with `extra` appended (its own tables at the end of the file).
fn imu_with(extra: &str) -> Result<Study, study::StudyError> {
    Study::parse("s.toml", &format!("{}\n{extra}\n", imu_bare()))
}

fn err(extra: &str) -> String {
    imu_with(extra).unwrap_err().to_string()
}

fn spec(output: &str, coefficient: &str, limit: f64, unit: &str) -> String {
    format!(
        "[[specifications]]\noutput = \"{output}\"\ncoefficient = \"{coefficient}\"\nlimit = {limit:?}\nunit = \"{unit}\"\n"
    )
}

#[test]
fn a_study_without_specifications_has_none_and_the_default_coverage() {
    let s = imu_with("").unwrap();
    assert!(s.specifications.is_empty());
    assert_relative_eq!(s.uncertainty.coverage, 0.95);
    assert!(!s.uncertainty.coverage_given);
    assert_eq!(
        s.uncertainty.tolerance_distribution,
        ToleranceDistribution::Rectangular
    );
}

#[test]
fn each_kind_is_converted_from_its_unit_to_the_models() {
    let extra = [
        spec("gx", "bg_x", 0.05, "deg_per_h"),
        spec("gx", "gs_xx", 0.1, "deg/h/g"),
        spec("ax", "ba_x", 50.0, "ug"),
        spec("ax", "sf_x", 100.0, "ppm"),
        spec("ax", "mis_xy", 20.0, "arcsec"),
        spec("ay", "sf_y", 100.0, "ppm"),
        spec("az", "mis_zx", 100.0, "urad"),
        spec("gy", "bg_y", 1e-5, "deg/s"),
    ]
    .concat();
    let s = imu_with(&extra).unwrap();
    let got: Vec<(f64, Resolved)> = s
        .specifications
        .iter()
        .map(|p| (p.limit(), p.resolved().clone()))
        .collect();
    let arcsec = std::f64::consts::PI / (180.0 * 3600.0);
    // model units: deg/h, deg/h/g, mg, mg/g (1 mg/g = 1e-3 = 1000 ppm = 1 mrad)
    let want = [
        (0.05, CoefficientKind::Bias),
        (0.1, CoefficientKind::GSensitivity),
        (0.05, CoefficientKind::Bias),
        (0.1, CoefficientKind::ScaleFactor),
        (20.0 * arcsec * 1e3, CoefficientKind::Misalignment),
        (0.1, CoefficientKind::ScaleFactor),
        (0.1, CoefficientKind::Misalignment),
        (0.036, CoefficientKind::Bias),
    ];
    for ((limit, resolved), (want_limit, want_kind)) in got.iter().zip(want) {
        assert_relative_eq!(*limit, want_limit, max_relative = CONVERSION_REL);
        match resolved {
            Resolved::Coefficient { kind, .. } => assert_eq!(*kind, want_kind),
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(got.len(), 8);
    // the written figure comes back through to_written
    let sf = &s.specifications[3];
    assert_relative_eq!(sf.limit() * sf.to_written(), 100.0, max_relative = 1e-15);
    assert_eq!(sf.label(&s.sensor), "ax sf_x (scale factor)");
}

#[test]
fn an_error_over_a_range_and_an_accuracy_are_specifications_of_an_output() {
    let extra = "[[specifications]]\noutput = \"gz\"\nquantity = \"error_over_range\"\nrange = 300\nrange_unit = \"deg/s\"\nlimit = 0.5\nunit = \"deg_per_h\"\ncoverage = 0.99\n\n[[specifications]]\noutput = \"ax\"\nquantity = \"accuracy\"\nlimit = 100\nunit = \"ug\"\n";
    let s = imu_with(extra).unwrap();
    match s.specifications[0].resolved() {
        Resolved::ErrorOverRange { axis, range } => {
            assert_eq!(*axis, gw_model::Input::Wz);
            assert_relative_eq!(*range, 300.0 * 3600.0, max_relative = CONVERSION_REL);
        }
        other => panic!("{other:?}"),
    }
    assert_relative_eq!(s.specifications[0].coverage(), 0.99);
    assert_eq!(s.specifications[1].resolved(), &Resolved::Accuracy);
    assert_relative_eq!(
        s.specifications[1].limit(),
        0.1,
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(s.specifications[1].coverage(), 0.95);
}

#[test]
fn a_unit_of_the_wrong_family_names_the_unit_and_the_coefficient() {
    let e = err(&spec("gx", "bg_x", 100.0, "ppm"));
    assert!(e.contains("key `specifications[0].unit`"), "{e}");
    assert!(
        e.contains("\"ppm\"") && e.contains("`bg_x`") && e.contains("bias"),
        "{e}"
    );
    let e = err(&spec("ax", "sf_x", 20.0, "arcsec"));
    assert!(
        e.contains("\"arcsec\"") && e.contains("`sf_x`") && e.contains("scale factor"),
        "{e}"
    );
    let e = err(&spec("ax", "ba_x", 0.5, "deg_per_h"));
    assert!(e.contains("\"deg_per_h\"") && e.contains("`ba_x`"), "{e}");
}

#[test]
fn a_coefficient_the_model_does_not_estimate_is_refused_by_name() {
    let e = err(&spec("gx", "omega_gx", 1.0, "deg_per_h"));
    assert!(e.contains("key `specifications[0].coefficient`"), "{e}");
    assert!(e.contains("`omega_gx`") && e.contains("known term"), "{e}");
    let e = err(&spec("gx", "bg_y", 1.0, "deg_per_h"));
    assert!(e.contains("`bg_y` is not a coefficient"), "{e}");
    let e = err(&spec("gq", "bg_x", 1.0, "deg_per_h"));
    assert!(
        e.contains("key `specifications[0].output`") && e.contains("\"gq\""),
        "{e}"
    );
}

#[test]
fn a_coverage_outside_zero_one_or_an_unknown_distribution_names_its_key() {
    for bad in ["0.0", "1.0", "95.0", "-0.5", "nan"] {
        let e = err(&format!("[uncertainty]\ncoverage = {bad}\n"));
        assert!(e.contains("key `uncertainty.coverage`"), "{e}");
        let e = err(&format!(
            "{}coverage = {bad}\n",
            spec("gx", "bg_x", 0.1, "deg_per_h")
        ));
        assert!(e.contains("key `specifications[0].coverage`"), "{e}");
    }
    let e = err("[uncertainty]\ntolerance_distribution = \"gaussian\"\n");
    assert!(
        e.contains("key `uncertainty.tolerance_distribution`"),
        "{e}"
    );
    assert!(e.contains("\"gaussian\""), "{e}");
    let s =
        imu_with("[uncertainty]\ncoverage = 0.99\ntolerance_distribution = \"arcsine\"\n").unwrap();
    assert_relative_eq!(s.uncertainty.coverage, 0.99);
    assert_eq!(
        s.uncertainty.tolerance_distribution,
        ToleranceDistribution::Arcsine
    );
}

#[test]
fn malformed_specifications_name_their_key() {
    for (extra, key) in [
        (spec("gx", "bg_x", -1.0, "deg_per_h"), "specifications[0].limit"),
        (
            "[[specifications]]\noutput = \"gx\"\nlimit = 1\nunit = \"deg_per_h\"\n".into(),
            "specifications[0].coefficient",
        ),
        (
            "[[specifications]]\noutput = \"gx\"\nquantity = \"drift\"\nlimit = 1\nunit = \"deg_per_h\"\n"
                .into(),
            "specifications[0].quantity",
        ),
        (
            "[[specifications]]\noutput = \"gx\"\nquantity = \"error_over_range\"\nrange = 3\nrange_unit = \"g\"\nlimit = 1\nunit = \"deg_per_h\"\n"
                .into(),
            "specifications[0].range_unit",
        ),
        (
            format!("{}range = 3\n", spec("gx", "bg_x", 1.0, "deg_per_h")),
            "specifications[0].range",
        ),
    ] {
        let e = err(&extra);
        assert!(e.contains(&format!("key `{key}`")), "{key}: {e}");
    }
}

/// The STIM300-class study states a test plan's specifications on every output: gyro bias in
/// deg/h, g-sensitivity in deg/h/g, accelerometer bias in ug, scale factor in ppm,
/// misalignment in urad, and one eq 14 accuracy, each converted to the model's units.
#[test]
fn the_stim300_class_study_specifies_every_kind_in_its_unit() {
    let s = Study::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/stim300-class-example.toml"
    )))
    .unwrap();
    assert_eq!(s.specifications.len(), 16);
    let kinds: Vec<Option<CoefficientKind>> = s
        .specifications
        .iter()
        .map(|p| match p.resolved() {
            Resolved::Coefficient { kind, .. } => Some(*kind),
            _ => None,
        })
        .collect();
    use CoefficientKind::{Bias, GSensitivity, Misalignment, ScaleFactor};
    let gyro = [Some(Bias), Some(GSensitivity)];
    let acc = [Some(Bias), Some(ScaleFactor), Some(Misalignment)];
    let want: Vec<Option<CoefficientKind>> = gyro
        .iter()
        .cycle()
        .take(6)
        .chain(acc.iter().cycle().take(9))
        .copied()
        .chain([None])
        .collect();
    assert_eq!(kinds, want);
    // 300 ppm of 1 g/g = 0.3 mg/g; 1000 urad = 1 mg/g; 50 ug = 0.05 mg
    assert_relative_eq!(
        s.specifications[7].limit(),
        0.3,
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(
        s.specifications[8].limit(),
        1.0,
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(
        s.specifications[6].limit(),
        0.05,
        max_relative = CONVERSION_REL
    );
}
