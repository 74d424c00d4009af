//! Properties of the sensor model and the site: eq 1 outputs, eq 3 inputs, eq 7-8 orientation
//! error, Table 1 values, and the general sensor description (regressors, validation).

use approx::{assert_abs_diff_eq, assert_relative_eq};
use gw_model::paper::{self, TABLE_1_X_DEG_PER_H, TABLE_1_Y_DEG_PER_H};
use gw_model::{
    Input, InputValues, Inputs, ModelError, Output, Regressor, SensorModel, Site, Term,
};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use tt_core::units::rad_per_s_to_deg_per_h;
use tt_core::{DeltaRKind, FieldError, OrientationError};

/// Trigonometric identities evaluated in f64 on O(1) quantities: a few ulps. Dimensionless (g)
/// or relative.
const TRIG_TOL: f64 = 1e-14;
/// Rates of order omega_e = 7.3e-5 rad/s computed two ways: a few ulps of omega_e, rad/s.
const RATE_TOL_RAD_PER_S: f64 = 1e-18;
/// Sums of a few terms of size up to 110 deg/h: relative, a few ulps.
const SUM_REL: f64 = 1e-14;

fn angle() -> impl Strategy<Value = f64> {
    -360.0..360.0f64
}

proptest! {
    /// Eq 3 is exactly $R_d^T v$ with $R_d = R_y(\phi_1)R_z(\phi_2)$, base frame north-west-up,
    /// specific force (0, 0, 1) g, earth rate $\omega_e(\cos\lambda, 0, \sin\lambda)$.
    #[test]
    fn eq3_components_equal_printed_formulas(p1 in angle(), p2 in angle(), lat in -90.0..90.0f64) {
        let site = Site::from_deg(lat, 7.2921159e-5).unwrap();
        let (f1, f2, l) = (p1.to_radians(), p2.to_radians(), lat.to_radians());
        let inp = site.inputs(&paper::base_from_sensor(f1, f2));
        let we = 7.2921159e-5;
        let a = Vector3::new(-f1.sin() * f2.cos(), f1.sin() * f2.sin(), f1.cos());
        let w = Vector3::new(
            we * f2.cos() * (f1.cos() * l.cos() - f1.sin() * l.sin()),
            we * f2.sin() * (-f1.cos() * l.cos() + f1.sin() * l.sin()),
            we * (f1.sin() * l.cos() + f1.cos() * l.sin()),
        );
        assert_abs_diff_eq!(inp.specific_force_g, a, epsilon = TRIG_TOL);
        assert_abs_diff_eq!(inp.rate_rad_per_s, w, epsilon = RATE_TOL_RAD_PER_S);
        assert_relative_eq!(inp.specific_force_g.norm(), 1.0, epsilon = TRIG_TOL);
        assert_relative_eq!(inp.rate_rad_per_s.norm(), we, max_relative = TRIG_TOL);
    }

    /// Eq 8: the actual inputs are the row vectors times $\Delta R$, i.e. $\Delta R^T R_d^T v$,
    /// for any (not necessarily orthonormal) $\Delta R$.
    #[test]
    fn eq8_actual_inputs_are_row_vector_times_delta_r(
        p1 in angle(), p2 in angle(),
        m in proptest::array::uniform9(-1.0..1.0f64),
    ) {
        let site = paper::site();
        let rd = paper::base_from_sensor(p1.to_radians(), p2.to_radians());
        let dr = Matrix3::from_row_slice(&m);
        let nominal = site.inputs(&rd);
        let actual = site.inputs_with_error(&rd, &dr);
        let row_a = nominal.specific_force_g.transpose() * dr;
        let row_w = nominal.rate_rad_per_s.transpose() * dr;
        assert_abs_diff_eq!(actual.specific_force_g, row_a.transpose(), epsilon = TRIG_TOL);
        assert_abs_diff_eq!(actual.rate_rad_per_s, row_w.transpose(), epsilon = RATE_TOL_RAD_PER_S);
    }

    /// The exact $\Delta R$ is a rotation and equals eq 7 to first order (difference of second
    /// order in the angles).
    #[test]
    fn exact_delta_r_is_rotation_matching_eq7_to_first_order(
        psi in -0.01..0.01f64, theta in -0.01..0.01f64, gamma in -0.01..0.01f64,
    ) {
        let ang = OrientationError::new(psi, theta, gamma).unwrap();
        let exact = ang.delta_r(DeltaRKind::Exact);
        let small = ang.delta_r(DeltaRKind::SmallAngle);
        assert_abs_diff_eq!(exact.transpose() * exact, Matrix3::identity(), epsilon = TRIG_TOL);
        let size = psi.abs().max(theta.abs()).max(gamma.abs());
        assert!((exact - small).amax() <= size * size + TRIG_TOL);
    }

    /// A regressor's analytic gradient equals central differences (exact for degree <= 2,
    /// O(h^2) otherwise).
    #[test]
    fn regressor_gradient_matches_central_differences(
        p in proptest::array::uniform6(0u8..=2).prop_filter("degree <= 6", |p| p.iter().map(|&x| u32::from(x)).sum::<u32>() <= 6),
        u in proptest::array::uniform6(-1.5..1.5f64),
    ) {
        let text: Vec<String> = Input::ALL.iter().zip(p).filter(|(_, p)| *p > 0)
            .map(|(i, p)| format!("{}^{p}", i.symbol())).collect();
        let r = Regressor::parse(&if text.is_empty() { "1".into() } else { text.join("*") }).unwrap();
        let v = InputValues(u);
        let g = r.gradient(&v);
        let h = 1e-5;
        for j in 0..6 {
            let mut a = u; a[j] += h;
            let mut b = u; b[j] -= h;
            let fd = (r.eval(&InputValues(a)) - r.eval(&InputValues(b))) / (2.0 * h);
            prop_assert!((g[j] - fd).abs() <= 1e-7 * (1.0 + g[j].abs()), "{j}: {} vs {fd}", g[j]);
        }
    }

    /// The second-order remainder bound of a regressor holds at every point of its box.
    #[test]
    fn regressor_remainder_bound_is_rigorous(
        p in proptest::array::uniform6(0u8..=3),
        u in proptest::array::uniform6(-1.0..1.0f64),
        d in proptest::array::uniform6(-0.1..0.1f64),
    ) {
        let mut r = Regressor::ONE;
        for (i, &pi) in Input::ALL.iter().zip(&p) {
            for _ in 0..pi { r = r.times(Regressor::input(*i)); }
        }
        let m = u.map(f64::abs);
        let dd = d.map(f64::abs);
        let v = InputValues(u);
        let moved = InputValues(std::array::from_fn(|j| u[j] + d[j]));
        let g = r.gradient(&v);
        let lin: f64 = (0..6).map(|j| g[j] * d[j]).sum();
        let rem = (r.eval(&moved) - r.eval(&v) - lin).abs();
        prop_assert!(rem <= r.remainder_bound(&m, &dd) * (1.0 + 1e-12) + 1e-15);
    }
}

/// Eq 7 as printed: rows (1, -dtheta, dpsi), (dtheta, 1, -dgamma), (-dpsi, dgamma, 1).
#[test]
fn eq7_small_angle_matrix_as_printed() {
    let ang = OrientationError::new(0.1, 0.2, 0.3).unwrap();
    let m = ang.delta_r(DeltaRKind::SmallAngle);
    let printed = Matrix3::new(1.0, -0.2, 0.1, 0.2, 1.0, -0.3, -0.1, 0.3, 1.0);
    assert_abs_diff_eq!(m, printed, epsilon = TRIG_TOL);
}

/// Table 1 as a sensor description: values and units exactly as printed; the y cross term
/// printed "D(y)_xy = 47.8" is eq 1's D(y)_yx; each output has its known rate term.
#[test]
fn table_1_values_and_units_as_printed() {
    let s = paper::gyrowheel();
    assert_eq!(s.n_outputs(), 2);
    for (o, values) in s
        .outputs()
        .iter()
        .zip([TABLE_1_X_DEG_PER_H, TABLE_1_Y_DEG_PER_H])
    {
        assert_eq!(o.estimated_values(), values.to_vec());
        assert_eq!(o.unit, "deg_per_h");
        assert_relative_eq!(o.accuracy, 0.01);
        let known: Vec<_> = o.known_terms().collect();
        assert_eq!(known.len(), 1);
        assert_relative_eq!(known[0].value, 1.0);
        let units: Vec<String> = o.estimated().map(|t| o.coefficient_unit(t)).collect();
        assert_eq!(
            units,
            [
                "deg_per_h",
                "deg_per_h/(g)",
                "deg_per_h/(g)",
                "deg_per_h/(g)",
                "deg_per_h/(g^2)",
                "deg_per_h/(g^2)",
                "deg_per_h/(g^2)"
            ]
        );
    }
    // Golden values, Table 1 as printed (compared as text: exactly the printed digits).
    assert_eq!(
        format!("{TABLE_1_X_DEG_PER_H:?}"),
        "[-93.3, -43.2, 3.5, -1.2, 2.1, -0.089, 17.4]"
    );
    assert_eq!(
        format!("{TABLE_1_Y_DEG_PER_H:?}"),
        "[105.3, 2.2, -33.2, -0.1, -10.6, -10.38, 47.8]"
    );
    let y = &s.outputs()[1];
    assert_eq!(y.estimated_names()[6], "dy_yx");
    assert_eq!(
        y.estimated().nth(6).unwrap().regressor.to_string(),
        "a_x*a_y"
    );
    assert_eq!(y.estimated().nth(4).unwrap().regressor.to_string(), "a_y^2");
}

/// Eq 1: the y-axis output at a pose with a_x = a_y = 1/2, a_z = 1/sqrt(2) sums every term.
#[test]
fn eq1_output_sums_every_term() {
    let site = paper::site();
    let inp = site.inputs(&paper::base_from_sensor(
        45f64.to_radians(),
        (-45f64).to_radians(),
    ));
    let a = inp.specific_force_g;
    let d = TABLE_1_Y_DEG_PER_H;
    let expected_deg_per_h = rad_per_s_to_deg_per_h(inp.rate_rad_per_s.y)
        + d[0]
        + d[1] * a.x
        + d[2] * a.y
        + d[3] * a.z
        + d[4] * a.y * a.y
        + d[5] * a.z * a.z
        + d[6] * a.x * a.y;
    let got = paper::gyrowheel().outputs()[1].value(&InputValues::from_inputs(&inp));
    assert_relative_eq!(got, expected_deg_per_h, max_relative = SUM_REL);
}

#[test]
fn regressors_parse_display_and_units_round_trip() {
    for (text, canonical, unit) in [
        ("1", "1", "1"),
        ("a_x", "a_x", "g"),
        ("a_y * a_x", "a_x*a_y", "g^2"),
        ("a_z^2", "a_z^2", "g^2"),
        ("a_z*a_z", "a_z^2", "g^2"),
        ("w_x*a_y", "a_y*w_x", "deg/h*g"),
    ] {
        let r = Regressor::parse(text).unwrap();
        assert_eq!(r.to_string(), canonical);
        assert_eq!(Regressor::parse(canonical).unwrap(), r);
        assert_eq!(r.unit(), unit);
    }
    for (bad, why) in [
        ("a_q", "unknown input symbol `a_q`"),
        ("", "empty regressor"),
        ("a_x^0", "positive integer"),
        ("a_x^x", "positive integer"),
        ("1*a_x", "`1` cannot be a factor"),
        ("a_x^7", "above the limit"),
    ] {
        let e = Regressor::parse(bad).unwrap_err();
        assert!(e.contains(why), "{bad}: {e}");
    }
}

fn term(c: &str, r: &str, v: f64, known: bool) -> Term {
    Term {
        coefficient: c.into(),
        regressor: Regressor::parse(r).unwrap(),
        value: v,
        known,
    }
}

fn sensor_error(outputs: Vec<Output>) -> (String, String) {
    match SensorModel::new(outputs).unwrap_err() {
        ModelError::Sensor { key, reason } => (key, reason),
        other => panic!("{other}"),
    }
}

/// Bad sensors and sites give typed errors naming the key or field.
#[test]
fn invalid_inputs_are_rejected_with_named_fields() {
    assert_eq!(
        Site::from_deg(91.0, 7e-5),
        Err(ModelError::LatitudeOutOfRange { latitude_deg: 91.0 })
    );
    assert!(
        matches!(Site::from_deg(45.0, -1.0), Err(ModelError::Field(FieldError::NotPositive { ref field, .. })) if field == "earth_rate")
    );
    assert!(
        matches!(OrientationError::new(f64::NAN, 0.0, 0.0), Err(FieldError::NonFinite { ref field, .. }) if field == "delta_psi")
    );

    let ok = |name: &str, terms: Vec<Term>| Output {
        name: name.into(),
        unit: "g".into(),
        accuracy: 1e-4,
        terms,
    };
    let good = || vec![term("b", "1", 0.1, false), term("s", "a_x", 1.0, true)];

    assert_eq!(sensor_error(vec![]).0, "outputs");
    let (key, reason) = sensor_error(vec![
        ok("ax", good()),
        ok("ax", vec![term("c", "1", 0.0, false)]),
    ]);
    assert_eq!(key, "outputs[1].name");
    assert!(reason.contains("already the name of outputs[0]"));
    let (key, reason) = sensor_error(vec![
        ok("ax", good()),
        ok("ay", vec![term("b", "1", 0.0, false)]),
    ]);
    assert_eq!(key, "outputs[1].terms[0].coefficient");
    assert!(
        reason.contains("already the coefficient of outputs[0].terms[0]"),
        "{reason}"
    );
    let mut o = ok("ax", good());
    o.accuracy = 0.0;
    assert_eq!(sensor_error(vec![o]).0, "outputs[0].accuracy");
    let mut o = ok("ax", good());
    o.terms[0].value = f64::NAN;
    assert_eq!(sensor_error(vec![o]).0, "outputs[0].terms[0].value");
    let (key, reason) = sensor_error(vec![ok("ax", vec![term("s", "a_x", 1.0, true)])]);
    assert_eq!(key, "outputs[0].terms");
    assert!(reason.contains("no estimated term"));
    // two estimated coefficients of one regressor: two equal columns of A (the known term
    // between them does not matter)
    let (key, reason) = sensor_error(vec![ok(
        "ax",
        vec![
            term("b", "a_x", 0.1, false),
            term("s", "a_x", 1.0, true),
            term("c", "a_x", 0.2, false),
        ],
    )]);
    assert_eq!(key, "outputs[0].terms[2].regressor");
    assert!(
        reason.contains("already the regressor of the estimated terms[0]")
            && reason.contains("two estimated coefficients of one regressor"),
        "{reason}"
    );
    assert_eq!(sensor_error(vec![ok("Ax", good())]).0, "outputs[0].name");
}

/// The most common gyro and accelerometer model: a known input term and an estimated
/// scale-factor error on the same regressor (issue 19 §6). The known term only shifts the
/// measurement (b2); the estimated one is a column of A and is identifiable. The output sums
/// both; only the estimated term is estimated.
#[test]
fn a_known_input_and_an_estimated_scale_factor_error_may_share_a_regressor() {
    let out = Output {
        name: "ax".into(),
        unit: "g".into(),
        accuracy: 1e-4,
        terms: vec![
            term("ax_in", "a_x", 1.0, true),
            term("ax_b", "1", 0.001, false),
            term("ax_sf", "a_x", 0.0015, false),
        ],
    };
    let sensor = SensorModel::new(vec![out]).expect("a known input and its scale-factor error");
    let o = &sensor.outputs()[0];
    assert_eq!(o.estimated_names(), ["ax_b", "ax_sf"]);
    let v = InputValues::from_inputs(&Inputs {
        specific_force_g: Vector3::new(0.5, 0.0, 0.0),
        rate_rad_per_s: Vector3::zeros(),
    });
    assert_abs_diff_eq!(o.known_part(&v), 0.5, epsilon = TRIG_TOL);
    let row: Vec<f64> = o.regressor_row(&v).collect();
    assert_eq!(row.len(), 2);
    assert_abs_diff_eq!(row[0], 1.0, epsilon = TRIG_TOL);
    assert_abs_diff_eq!(row[1], 0.5, epsilon = TRIG_TOL);
    assert_abs_diff_eq!(o.value(&v), 0.5 + 0.001 + 0.0015 * 0.5, epsilon = TRIG_TOL);
    // two known terms of one regressor only add up: accepted too
    let mut terms = o.terms.clone();
    terms.push(term("ax_in2", "a_x", 0.5, true));
    SensorModel::new(vec![Output { terms, ..o.clone() }]).expect("two known terms");
}
