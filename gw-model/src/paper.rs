//! The paper's sensor and site (Zhao et al. 2017, §2.1-2.3, eq 1, eq 3, Table 1) as one
//! instance of the general model, with the values the paper leaves open marked as ours.
//!
//! The same sensor is written in the paper's study file (`studies/gyrowheel-2017.toml`); this
//! module lets the library's claim tests use it without a file.

use crate::sensor::{Input, Output, Regressor, SensorModel, Term};
use crate::site::Site;
use crate::site::WGS84_EARTH_RATE_RAD_PER_S;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Latitude of the authors' site, Harbin (Harbin Institute of Technology), degrees north.
/// The paper gives no latitude (NOTES item 8): our assumption.
pub const HARBIN_LATITUDE_DEG: f64 = 45.75;

/// The required calibration accuracy of §2.3 and §4.3, deg/h.
pub const OMEGA_M_DEG_PER_H: f64 = 0.01;

/// Table 1, $x$ axis, deg/h, deg/h/g, deg/h/g², in the order of eq 1:
/// $D(x)_F, D(x)_x, D(x)_y, D(x)_z, D(x)_{xx}, D(x)_{zz}, D(x)_{xy}$.
pub const TABLE_1_X_DEG_PER_H: [f64; 7] = [-93.3, -43.2, 3.5, -1.2, 2.1, -0.089, 17.4];

/// Table 1, $y$ axis, in the order of eq 1: $D(y)_F, D(y)_x, D(y)_y, D(y)_z, D(y)_{yy},
/// D(y)_{zz}, D(y)_{yx}$ (the last printed "$D(y)_{xy}$" in Table 1; it is the coefficient of
/// $a_xa_y$ in the $y$ model either way).
pub const TABLE_1_Y_DEG_PER_H: [f64; 7] = [105.3, 2.2, -33.2, -0.1, -10.6, -10.38, 47.8];

/// Coefficient names of the $x$ axis as used in the study file (eq 1 order).
pub const X_NAMES: [&str; 7] = ["dx_f", "dx_x", "dx_y", "dx_z", "dx_xx", "dx_zz", "dx_xy"];

/// Coefficient names of the $y$ axis as used in the study file (eq 1 order).
pub const Y_NAMES: [&str; 7] = ["dy_f", "dy_x", "dy_y", "dy_z", "dy_yy", "dy_zz", "dy_yx"];

/// The regressors of eq 1 (eq 2 with NOTES item 2 corrected): $x$: $1, a_x, a_y, a_z, a_x^2,
/// a_z^2, a_xa_y$; $y$: $1, a_x, a_y, a_z, a_y^2, a_z^2, a_xa_y$.
#[must_use]
pub fn regressors(x_axis: bool) -> [Regressor; 7] {
    let a = Regressor::input;
    let quad = if x_axis {
        a(Input::Ax).times(a(Input::Ax))
    } else {
        a(Input::Ay).times(a(Input::Ay))
    };
    [
        Regressor::ONE,
        a(Input::Ax),
        a(Input::Ay),
        a(Input::Az),
        quad,
        a(Input::Az).times(a(Input::Az)),
        a(Input::Ax).times(a(Input::Ay)),
    ]
}

/// The GyroWheel of eq 1 with Table 1's values and $\omega_m = 0.01$ deg/h per output:
/// outputs `x` ($k_y i_y = \omega_x + D(x)_F + \dots$) and `y`, each with the known rate term
/// ($w_x$ or $w_y$, coefficient 1) and seven estimated drift coefficients.
///
/// # Reference
/// Eq 1, Table 1, §2.3.
#[must_use]
pub fn gyrowheel() -> SensorModel {
    let output = |name: &str, rate: Input, names: [&str; 7], values: [f64; 7], x_axis: bool| {
        let mut terms = vec![Term {
            coefficient: format!("omega_{name}"),
            regressor: Regressor::input(rate),
            value: 1.0,
            known: true,
        }];
        terms.extend(regressors(x_axis).into_iter().zip(names).zip(values).map(
            |((regressor, coefficient), value)| Term {
                coefficient: coefficient.into(),
                regressor,
                value,
                known: false,
            },
        ));
        Output {
            name: name.into(),
            unit: "deg_per_h".into(),
            accuracy: OMEGA_M_DEG_PER_H,
            terms,
        }
    };
    SensorModel::new(vec![
        output("x", Input::Wx, X_NAMES, TABLE_1_X_DEG_PER_H, true),
        output("y", Input::Wy, Y_NAMES, TABLE_1_Y_DEG_PER_H, false),
    ])
    .unwrap_or_else(|e| unreachable!("Table 1 is a valid sensor: {e}"))
}

/// Harbin and the WGS-84 earth rate $7.292\,115\,9\times10^{-5}$ rad/s; the paper states
/// neither (NOTES items 8-9).
#[must_use]
pub fn site() -> Site {
    Site::from_deg(HARBIN_LATITUDE_DEG, WGS84_EARTH_RATE_RAD_PER_S)
        .unwrap_or_else(|e| unreachable!("valid constants: {e}"))
}

/// The paper's intended orientation $\mathbf R_d = R_y(\phi_1) R_z(\phi_2)$ (eq 21, sensor to
/// base), angles in radians.
#[must_use]
pub fn base_from_sensor(phi1_rad: f64, phi2_rad: f64) -> Matrix3<f64> {
    let ry = Rotation3::from_axis_angle(&Vector3::y_axis(), phi1_rad);
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), phi2_rad);
    (ry * rz).into_inner()
}
