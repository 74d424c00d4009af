//! GyroWheel rate-sensing model (Zhao, Zhao, Huo and Yao 2017, §2.1, eq 1, 3, 7-8, Table 1).
//!
//! The GyroWheel senses the rates $\omega_x$, $\omega_y$ through torque-coil currents; each
//! axis's output carries a drift that depends on the specific force $\mathbf a$ (eq 1):
//!
//! $$k_y i_y = \omega_x + D(x)_F + D(x)_x a_x + D(x)_y a_y + D(x)_z a_z + D(x)_{xx} a_x^2 +
//!   D(x)_{zz} a_z^2 + D(x)_{xy} a_x a_y,$$
//! $$k_x i_x = \omega_y + D(y)_F + D(y)_x a_x + D(y)_y a_y + D(y)_z a_z + D(y)_{yy} a_y^2 +
//!   D(y)_{zz} a_z^2 + D(y)_{yx} a_x a_y.$$
//!
//! This crate holds that model ([`AxisCoefficients`], [`DriftCoefficients`], Table 1 as
//! [`DriftCoefficients::table_1`]), the test site ([`Site`]: latitude and earth rate, base frame
//! north-west-up) and the inputs at a two-axis-turntable [`Position`] (eq 3), with or without an
//! orientation error $\Delta\mathbf R$ (eq 7-8, [`OrientationAngles`], [`Site::inputs_with_error`]).
//!
//! # Units
//! Radians, rad/s and g inside. Degrees and deg/h (deg/h/g, deg/h/g²) only in constructor and
//! accessor names that say so (`from_deg`, `from_deg_per_h`, `deg_per_h`).
//!
//! # Frames
//! Base frame north-west-up. $\mathbf R_d = R_y(\phi_1) R_z(\phi_2)$ maps GyroWheel (body)
//! coordinates to base coordinates; the body-frame inputs are $\mathbf R_d^T \mathbf v$ (exactly
//! eq 3). An orientation error $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ (eq 7/23) turns them
//! into $\Delta\mathbf R^T \mathbf R_d^T \mathbf v$, eq 8's row-vector form.
//!
//! # Example
//! ```
//! use gw_model::{DriftCoefficients, OrientationAngles, DeltaRKind, Position, SensingAxis, Site};
//! use gw_model::units::rad_per_s_to_deg_per_h;
//!
//! let site = Site::paper_default(); // Harbin, 45.75 deg N, WGS-84 earth rate
//! let pos = Position::from_deg(90.0, 0.0)?; // outer axis at 90 deg: body x points up
//! let inputs = site.inputs(&pos);
//! assert!((inputs.specific_force_g.x + 1.0).abs() < 1e-15); // a_x = -sin(phi1) cos(phi2)
//!
//! let table1 = DriftCoefficients::table_1();
//! let out = table1.x.output_rad_per_s(&inputs);
//! // D(x)_F + D(x)_x * (-1) + D(x)_xx * 1 = -93.3 + 43.2 + 2.1 deg/h, plus omega_x.
//! let omega_x = rad_per_s_to_deg_per_h(inputs.rate_rad_per_s.x);
//! assert!((rad_per_s_to_deg_per_h(out) - (-48.0 + omega_x)).abs() < 1e-9);
//!
//! // The same position turned by 0.027 deg about y (eq 7-8).
//! let err = OrientationAngles::from_deg(0.027, 0.0, 0.0)?;
//! let actual = site.inputs_with_error(&pos, &err.delta_r(DeltaRKind::SmallAngle));
//! assert!(actual.rate_rad_per_s.x != inputs.rate_rad_per_s.x);
//! # Ok::<(), gw_model::ModelError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![forbid(unsafe_code)]

mod coefficients;
mod error;
mod site;
pub mod units;

pub use coefficients::{
    AxisCoefficients, DriftCoefficients, N_COEFFICIENTS, SensingAxis, TABLE_1_X_DEG_PER_H,
    TABLE_1_Y_DEG_PER_H, TorqueScaleFactors, regressors,
};
pub use error::ModelError;
pub use site::{DeltaRKind, HARBIN_LATITUDE_DEG, Inputs, OrientationAngles, Position, Site};
