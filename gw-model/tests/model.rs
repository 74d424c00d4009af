//! Properties of the GyroWheel model: eq 1 outputs, eq 3 inputs, eq 7-8 orientation error,
//! Table 1 values.

use approx::{assert_abs_diff_eq, assert_relative_eq};
use gw_model::units::{deg_per_h_to_rad_per_s, rad_per_s_to_deg_per_h};
use gw_model::{
    AxisCoefficients, DeltaRKind, DriftCoefficients, ModelError, OrientationAngles, Position,
    SensingAxis, Site, TABLE_1_X_DEG_PER_H, TABLE_1_Y_DEG_PER_H, TorqueScaleFactors,
};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;

/// Trigonometric identities evaluated in f64 on O(1) quantities: a few ulps. Dimensionless (g)
/// or relative.
const TRIG_TOL: f64 = 1e-14;
/// Rates of order omega_e = 7.3e-5 rad/s computed two ways: a few ulps of omega_e, rad/s.
const RATE_TOL_RAD_PER_S: f64 = 1e-18;
/// deg/h -> rad/s -> deg/h round trip of Table 1 entries (|v| < 110): relative, a few ulps.
const ROUND_TRIP_REL: f64 = 1e-14;

fn angle() -> impl Strategy<Value = f64> {
    -360.0..360.0f64
}

proptest! {
    /// Eq 3 is exactly $R_d^T v$ with $R_d = R_y(\phi_1)R_z(\phi_2)$, base frame north-west-up,
    /// specific force (0, 0, 1) g, earth rate $\omega_e(\cos\lambda, 0, \sin\lambda)$.
    #[test]
    fn eq3_components_equal_printed_formulas(p1 in angle(), p2 in angle(), lat in -90.0..90.0f64) {
        let site = Site::from_deg(lat, 7.2921159e-5).unwrap();
        let inp = site.inputs(&Position::from_deg(p1, p2).unwrap());
        let (f1, f2, l) = (p1.to_radians(), p2.to_radians(), lat.to_radians());
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
        let site = Site::paper_default();
        let pos = Position::from_deg(p1, p2).unwrap();
        let dr = Matrix3::from_row_slice(&m);
        let nominal = site.inputs(&pos);
        let actual = site.inputs_with_error(&pos, &dr);
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
        let ang = OrientationAngles::new(psi, theta, gamma).unwrap();
        let exact = ang.delta_r(DeltaRKind::Exact);
        let small = ang.delta_r(DeltaRKind::SmallAngle);
        assert_abs_diff_eq!(exact.transpose() * exact, Matrix3::identity(), epsilon = TRIG_TOL);
        let size = psi.abs().max(theta.abs()).max(gamma.abs());
        assert!((exact - small).amax() <= size * size + TRIG_TOL);
    }
}

/// Eq 7 as printed: rows (1, -dtheta, dpsi), (dtheta, 1, -dgamma), (-dpsi, dgamma, 1).
#[test]
fn eq7_small_angle_matrix_as_printed() {
    let ang = OrientationAngles::new(0.1, 0.2, 0.3).unwrap();
    let m = ang.delta_r(DeltaRKind::SmallAngle);
    let printed = Matrix3::new(1.0, -0.2, 0.1, 0.2, 1.0, -0.3, -0.1, 0.3, 1.0);
    assert_abs_diff_eq!(m, printed, epsilon = TRIG_TOL);
}

/// Table 1: values and units exactly as printed; the y cross term printed "D(y)_xy = 47.8" is
/// eq 1's D(y)_yx.
#[test]
fn table_1_values_and_units_as_printed() {
    let t = DriftCoefficients::table_1();
    for (got, want) in t.x.deg_per_h().iter().zip(TABLE_1_X_DEG_PER_H) {
        assert_relative_eq!(*got, want, max_relative = ROUND_TRIP_REL);
    }
    for (got, want) in t.y.deg_per_h().iter().zip(TABLE_1_Y_DEG_PER_H) {
        assert_relative_eq!(*got, want, max_relative = ROUND_TRIP_REL);
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
    let names = SensingAxis::Y.coefficient_names();
    assert_eq!(names[6], "D(y)_yx");
    assert_eq!(
        SensingAxis::X.coefficient_units(),
        [
            "deg/h",
            "deg/h/g",
            "deg/h/g",
            "deg/h/g",
            "deg/h/g^2",
            "deg/h/g^2",
            "deg/h/g^2"
        ]
    );
    assert_relative_eq!(
        t.x.rad_per_s()[0],
        -93.3 * std::f64::consts::PI / 180.0 / 3600.0,
        max_relative = ROUND_TRIP_REL
    );
}

/// Eq 1: the y-axis output at a pose with a_x = a_y = 1/2, a_z = 1/sqrt(2) sums every term.
#[test]
fn eq1_output_sums_every_term() {
    // phi1 = 45 deg, phi2 = -45 deg: a = (-1/2, -1/2, 1/sqrt2)... compute from eq 3.
    let site = Site::paper_default();
    let inp = site.inputs(&Position::from_deg(45.0, -45.0).unwrap());
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
    let got = rad_per_s_to_deg_per_h(DriftCoefficients::table_1().y.output_rad_per_s(&inp));
    assert_relative_eq!(got, expected_deg_per_h, max_relative = ROUND_TRIP_REL);
}

/// Bad input gives typed errors naming the field.
#[test]
fn invalid_inputs_are_rejected_with_named_fields() {
    assert_eq!(
        Site::from_deg(91.0, 7e-5),
        Err(ModelError::LatitudeOutOfRange { latitude_deg: 91.0 })
    );
    assert!(matches!(
        Site::from_deg(45.0, -1.0),
        Err(ModelError::NonPositive {
            field: "earth_rate",
            ..
        })
    ));
    assert!(matches!(
        Position::from_deg(f64::NAN, 0.0),
        Err(ModelError::NonFinite { field: "phi1", .. })
    ));
    let mut bad = TABLE_1_X_DEG_PER_H;
    bad[6] = f64::INFINITY;
    assert!(matches!(
        AxisCoefficients::from_deg_per_h(SensingAxis::X, bad),
        Err(ModelError::NonFinite {
            field: "D(x)_xy",
            ..
        })
    ));
    assert!(matches!(
        TorqueScaleFactors::from_rad_per_s_per_amp(1.0, 0.0),
        Err(ModelError::NonPositive { field: "k_y", .. })
    ));
}

/// Torque scale factors: x axis output uses k_y, y axis uses k_x (eq 1); round trip.
#[test]
fn torque_scale_factors_pair_axes_as_eq1() {
    let k = TorqueScaleFactors::from_deg_per_h_per_amp(2.0, 3.0).unwrap();
    assert_relative_eq!(
        k.of_axis(SensingAxis::X),
        deg_per_h_to_rad_per_s(3.0),
        max_relative = ROUND_TRIP_REL
    );
    let out = k.output_rad_per_s(SensingAxis::Y, 0.5);
    assert_relative_eq!(
        out,
        deg_per_h_to_rad_per_s(1.0),
        max_relative = ROUND_TRIP_REL
    );
    assert_relative_eq!(
        k.current_amp(SensingAxis::Y, out),
        0.5,
        max_relative = ROUND_TRIP_REL
    );
}
