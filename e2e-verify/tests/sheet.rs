//! The tolerance sheet as a library value: its constructor holds the lower bounds within the
//! sheet once, refuses bad entries naming them and a measured table outside the sheet; its
//! compensated sheet bounds a measured error by what the measurement leaves and drops its
//! disc; a check takes the sheet.

mod common;

use approx::assert_relative_eq;
use calib_lsq::Reading;
use e2e_verify::sheet::{DiscBound, MeasuredError, SheetEntries, ToleranceSheet};
use e2e_verify::{E2eError, McSettings};
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::{ErrorVariation, paper};

/// Bounds built from arcmin by one product each compare to a few ulps (dimensionless).
const SAME_REL: f64 = 1e-12;

fn arcmin(v: f64) -> f64 {
    v * RAD_PER_ARCMIN
}

/// Table 3's errors each bounded by 0.4'.
fn entries() -> SheetEntries {
    let table = paper::table3();
    SheetEntries::with_bounds(&table, vec![arcmin(0.4); table.n_rotation_errors()])
}

fn constant_measured(value_arcmin: f64, uncertainty_arcmin: f64) -> MeasuredError {
    MeasuredError {
        key: "compensation.measured[0].value_arcmin".into(),
        variation: ErrorVariation::Constant,
        coefficients_rad: vec![arcmin(value_arcmin)],
        uncertainty_rad: arcmin(uncertainty_arcmin),
    }
}

fn sheet(
    entries: SheetEntries,
    lower_arcmin: f64,
    measured: Vec<Option<MeasuredError>>,
) -> Result<ToleranceSheet, E2eError> {
    let table = paper::table3();
    let n = table.n_rotation_errors();
    ToleranceSheet::new(
        &table,
        "sheet.toml",
        entries,
        &vec![arcmin(lower_arcmin); n],
        measured,
    )
}

#[test]
fn lower_bounds_above_the_sheet_are_held_within_it_and_the_compensated_sheet_holds_the_given_ones()
{
    let n = paper::table3().n_rotation_errors();
    let mut measured = vec![None; n];
    // uncertainty 0.6' above the sheet's 0.4': the residual is 0.4' + 0.1' = 0.5'
    measured[0] = Some(constant_measured(0.1, 0.6));
    let s = sheet(entries(), 0.45, measured).unwrap();
    for l in s.lower_bounds_rad() {
        assert_relative_eq!(*l, arcmin(0.4), max_relative = SAME_REL);
    }
    let (c, above) = s.compensated().expect("a measured error");
    assert_relative_eq!(
        c.upper_bounds_rad()[0],
        arcmin(0.5),
        max_relative = SAME_REL
    );
    // the study's 0.45' is within the residual 0.5': held from the given lower bound, not
    // from the sheet's clamped 0.4'
    assert_relative_eq!(
        c.lower_bounds_rad()[0],
        arcmin(0.45),
        max_relative = SAME_REL
    );
    assert_relative_eq!(
        c.lower_bounds_rad()[1],
        arcmin(0.4),
        max_relative = SAME_REL
    );
    assert_eq!(above.len(), 1);
    assert_eq!(above[0].error(), 0);
    assert_relative_eq!(
        above[0].residual_rad(),
        arcmin(0.5),
        max_relative = SAME_REL
    );
    assert_relative_eq!(
        above[0].largest_measured_rad(),
        arcmin(0.1),
        max_relative = SAME_REL
    );
    assert!(!c.has_measured());
}

#[test]
fn a_measured_error_is_bounded_by_its_uncertainty_and_drops_its_disc() {
    let mut e = entries();
    e.discs = vec![
        DiscBound {
            key: "axes.phi1.wobble_arcsec".into(),
            errors: [0, 1],
            bound_rad: arcmin(0.4),
        },
        DiscBound {
            key: "axes.phi2.wobble_arcsec".into(),
            errors: [2, 3],
            bound_rad: arcmin(0.4),
        },
    ];
    let n = paper::table3().n_rotation_errors();
    let mut measured = vec![None; n];
    measured[1] = Some(constant_measured(0.3, 0.05));
    let s = sheet(e, 0.0, measured).unwrap();
    assert!(s.compensated().is_some());
    let (c, above) = s.compensated().unwrap();
    assert!(above.is_empty());
    assert_relative_eq!(
        c.upper_bounds_rad()[1],
        arcmin(0.05),
        max_relative = SAME_REL
    );
    assert_relative_eq!(
        c.upper_bounds_rad()[0],
        arcmin(0.4),
        max_relative = SAME_REL
    );
    let keys: Vec<&str> = c.discs().iter().map(|d| d.key.as_str()).collect();
    assert_eq!(keys, ["axes.phi2.wobble_arcsec"]);
    // the original sheet is unchanged
    assert_eq!(s.discs().len(), 2);
}

#[test]
fn nothing_measured_gives_no_compensated_sheet() {
    let n = paper::table3().n_rotation_errors();
    assert!(
        sheet(entries(), 0.0, vec![None; n])
            .unwrap()
            .compensated()
            .is_none()
    );
}

#[test]
fn a_measured_error_beyond_the_sheet_is_refused_naming_its_key() {
    let n = paper::table3().n_rotation_errors();
    let mut measured = vec![None; n];
    measured[2] = Some(constant_measured(-0.5, 0.01));
    match sheet(entries(), 0.0, measured) {
        Err(E2eError::MeasuredOutsideSheet {
            key,
            error,
            reached_rad,
            bound_rad,
        }) => {
            assert_eq!(key, "compensation.measured[0].value_arcmin");
            assert_eq!(error, paper::table3().rotation_error_names()[2]);
            assert_relative_eq!(reached_rad, arcmin(0.5), max_relative = SAME_REL);
            assert_relative_eq!(bound_rad, arcmin(0.4), max_relative = SAME_REL);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_harmonic_measured_error_is_refused_by_the_magnitude_it_reaches_over_the_revolution() {
    let n = paper::table3().n_rotation_errors();
    let harmonic = |c0: f64, a1: f64| MeasuredError {
        key: "compensation.measured[0].coefficients_arcmin".into(),
        variation: ErrorVariation::Harmonics {
            joint: "phi1".into(),
            orders: vec![1],
        },
        coefficients_rad: vec![arcmin(c0), arcmin(a1), 0.0],
        uncertainty_rad: arcmin(0.01),
    };
    // 0.3' + 0.3' cos(phi) reaches 0.6' at phi = 0, beyond 0.4' though each term is within
    let mut measured = vec![None; n];
    measured[0] = Some(harmonic(0.3, 0.3));
    assert!(matches!(
        sheet(entries(), 0.0, measured),
        Err(E2eError::MeasuredOutsideSheet { .. })
    ));
    let mut measured = vec![None; n];
    measured[0] = Some(harmonic(0.2, 0.15));
    assert!(sheet(entries(), 0.0, measured).is_ok());
    // the wrong number of coefficients for its model
    let mut measured = vec![None; n];
    let mut m = harmonic(0.2, 0.15);
    m.coefficients_rad.pop();
    measured[0] = Some(m);
    assert!(matches!(
        sheet(entries(), 0.0, measured),
        Err(E2eError::MeasuredModel {
            coefficients: 2,
            expected: Some(3),
            ..
        })
    ));
}

#[test]
fn bad_entries_are_refused_naming_the_entry() {
    let table = paper::table3();
    let n = table.n_rotation_errors();
    let names = table.rotation_error_names();
    let field = |r: Result<ToleranceSheet, E2eError>| match r {
        Err(E2eError::Field(f)) => f.field().to_string(),
        other => panic!("{other:?}"),
    };
    let mut e = entries();
    e.upper_bounds_rad[3] = -1e-6;
    assert_eq!(
        field(sheet(e, 0.0, vec![None; n])),
        format!("upper_bounds.{}", names[3])
    );
    let mut e = entries();
    e.upper_bounds_rad[5] = f64::NAN;
    assert_eq!(
        field(sheet(e, 0.0, vec![None; n])),
        format!("upper_bounds.{}", names[5])
    );
    let mut e = entries();
    e.upper_bounds_rad.pop();
    assert_eq!(field(sheet(e, 0.0, vec![None; n])), "upper_bounds");
    assert_eq!(field(sheet(entries(), 0.0, vec![None; n - 1])), "measured");
    let mut e = entries();
    e.rate_accuracy[0] = Some(-1.0);
    assert_eq!(
        field(sheet(e, 0.0, vec![None; n])),
        format!("rate_accuracy.{}", paper::table3().joint_names()[0])
    );
    let mut e = entries();
    e.discs = vec![DiscBound {
        key: "axes.phi1.wobble_arcsec".into(),
        errors: [4, 4],
        bound_rad: arcmin(0.4),
    }];
    match sheet(e, 0.0, vec![None; n]) {
        Err(E2eError::SheetDisc { key, .. }) => assert_eq!(key, "axes.phi1.wobble_arcsec"),
        other => panic!("{other:?}"),
    }
    let mut e = entries();
    e.discs = vec![DiscBound {
        key: "axes.phi1.wobble_arcsec".into(),
        errors: [0, n],
        bound_rad: arcmin(0.4),
    }];
    assert!(matches!(
        sheet(e, 0.0, vec![None; n]),
        Err(E2eError::SheetDisc { .. })
    ));
}

#[test]
fn checking_a_sheet_checks_its_bounds_with_its_clamped_lower_bounds() {
    let e2e = common::paper(Reading::PAPER);
    let n = e2e.n_errors();
    let s = sheet(entries(), 0.45, vec![None; n]).unwrap();
    let settings = McSettings::new(300, 7);
    let by_sheet = e2e.vendor().check_sheet(&s, &settings).unwrap();
    let by_box = e2e
        .vendor()
        .check_tolerances(
            &e2e.linearization(),
            &vec![arcmin(0.4); n],
            &vec![arcmin(0.4); n],
            &settings,
        )
        .unwrap();
    assert_eq!(by_sheet.verdict(), by_box.verdict());
    assert_eq!(
        by_sheet.distribution().count().fraction().to_bits(),
        by_box.distribution().count().fraction().to_bits()
    );
    for (a, b) in by_sheet.outputs().iter().zip(by_box.outputs()) {
        assert_eq!(
            a.worst_case().linear_bound().to_bits(),
            b.worst_case().linear_bound().to_bits()
        );
    }
}

#[test]
fn the_model_a_sheet_supports_is_any_on_each_shaft_unless_a_vendor_quantity_implies_one() {
    let table = paper::table3();
    let n = table.n_rotation_errors();
    let mut e = entries();
    e.implied[0] = Some(ErrorVariation::Constant);
    let model = sheet(e, 0.0, vec![None; n])
        .unwrap()
        .supported_model(&table);
    let any = tt_kinematics::on_shafts(&table, |j| ErrorVariation::Any {
        joint: j.to_string(),
    });
    assert_eq!(model[0], ErrorVariation::Constant);
    assert_eq!(model[1..], any[1..]);
}
