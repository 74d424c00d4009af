//! Sensors as data: any sensor whose outputs are linear in their coefficients, the inputs it
//! feels on a turntable at a test site, with or without an orientation error. The GyroWheel
//! of Zhao, Zhao, Huo and Yao 2017 (§2.1, eq 1, 3, 7-8, Table 1) is one instance
//! (`paper::gyrowheel`).
//!
//! - [`SensorModel`]: outputs, each $y = \sum_t \beta_t r_t(\mathbf a, \boldsymbol\omega)$ with
//!   regressors $r_t$ that are $1$ or monomials of the specific force (g) and the angular rate
//!   (deg/h) in the sensor frame ([`Regressor`]); known terms (the rate input, a unit scale
//!   factor) and estimated terms; an accuracy per output (the $\omega_m$ of the paper);
//! - [`Site`]: latitude and earth rate, base frame north-west-up; [`Site::inputs`] gives the
//!   inputs at an intended orientation (eq 3 for the paper's table) and
//!   [`Site::inputs_with_error`] at an orientation off by $\Delta\mathbf R$ (eq 8);
//! - an orientation error is [`tt_core::OrientationError`], whose matrix (eq 7) turns the
//!   inputs through [`Site::inputs_with_error`].
//! - [`noise`]: the noise of an output (white density, Gauss-Markov bias instability,
//!   quantization), datasheet units converted to the output's unit, and the variance and
//!   covariance of its averages over the windows a calibration dwells at each position.
//!
//! For eq 1 the outputs are
//! $$k_y i_y = \omega_x + D(x)_F + D(x)_x a_x + D(x)_y a_y + D(x)_z a_z + D(x)_{xx} a_x^2 +
//!   D(x)_{zz} a_z^2 + D(x)_{xy} a_x a_y,$$
//! and likewise $k_x i_x$ for $y$.
//!
//! # Units
//! Angles in radians, rates in rad/s and specific force in g inside; a sensor's outputs and
//! coefficients are in the units its description names (deg/h for the GyroWheel), with
//! angular-rate regressors in deg/h.
//!
//! # Frames
//! Base frame north-west-up. $\mathbf R_d$ maps sensor coordinates to base coordinates; the
//! sensor-frame inputs are $\mathbf R_d^T\mathbf v$ (eq 3); an orientation error
//! $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ (eq 7/23) turns them into
//! $\Delta\mathbf R^T \mathbf R_d^T \mathbf v$, eq 8's row-vector form.
//!
//! # Example
//! ```
//! use gw_model::{paper, InputValues};
//! use tt_core::{DeltaRKind, OrientationError};
//!
//! let site = paper::site(); // Harbin, 45.75 deg N, WGS-84 earth rate (our assumption)
//! let rd = paper::base_from_sensor(90f64.to_radians(), 0.0); // outer axis at 90 deg
//! let inputs = site.inputs(&rd);
//! assert!((inputs.specific_force_g.x + 1.0).abs() < 1e-15); // a_x = -sin(phi1) cos(phi2)
//!
//! let sensor = paper::gyrowheel();
//! let x = &sensor.outputs()[0];
//! let v = InputValues::from_inputs(&inputs);
//! // D(x)_F + D(x)_x * (-1) + D(x)_xx * 1 = -93.3 + 43.2 + 2.1 deg/h, plus omega_x.
//! assert!((x.value(&v) - (-48.0 + v.0[3])).abs() < 1e-9);
//!
//! // The same position turned by 0.027 deg about y (eq 7-8).
//! let err = OrientationError::from_deg(0.027, 0.0, 0.0)?;
//! let actual = site.inputs_with_error(&rd, &err.delta_r(DeltaRKind::SmallAngle));
//! assert!(actual.rate_rad_per_s.x != inputs.rate_rad_per_s.x);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod error;
pub mod noise;
#[cfg(feature = "paper")]
pub mod paper;
mod sensor;
mod site;
pub mod spec;

pub use error::ModelError;
pub use sensor::{Input, InputValues, MAX_REGRESSOR_DEGREE, Output, Regressor, SensorModel, Term};
pub use site::{Inputs, Site, WGS84_EARTH_RATE_RAD_PER_S};
