//! Multiposition least-squares calibration of any sensor linear in its coefficients, and the
//! effect of an orientation error on it (Zhao, Zhao, Huo and Yao 2017, §2, eq 2-16,
//! Figures 4-5; the GyroWheel of eq 1 is one sensor among many).
//!
//! - [`Schedule`], [`Position`]: the test orientations (and the joint angles commanding them);
//! - [`Calibration`]: a [`gw_model::SensorModel`] on a schedule at a site, checked to identify
//!   every output's coefficients ([`CalibError::Unidentifiable`] names the output and the
//!   coefficients), regressions factored once ([`Regression`]: QR, rank, condition number,
//!   singular values by a Jacobi SVD of $\mathbf R$), simulation and calibration (eq 5-6);
//! - [`Reading`]: the 18 readings of eq 13, evaluated in one place
//!   ([`Reading::error_vector`] over [`ReadingTerms`]); [`OrientationErrorAnalysis`]: eq 7-14
//!   for one output;
//! - [`RequirementProblem`]: the surfaces of Figure 4, the lines of Figure 5 and the
//!   requirement of eq 15-16 for any sensor ([`RequirementProblem::requirement`]).
//! - [`Timing`] (dwell per position, move time, sample rate) and the covariance of a
//!   calibration under sensor noise (a `gw_model::noise::NoiseModel`): of the estimated
//!   coefficients and of the rate error at the test positions, white and correlated between
//!   positions in the visiting order ([`Regression::coefficient_covariance`],
//!   [`OutputCalibration::noise_covariance`], [`Calibration::noise_covariances`]), from the
//!   regression's pseudo-inverse, without a second solve.
//!
//! # Example
//! ```
//! use calib_lsq::{Calibration, Reading, RequirementProblem, paper};
//! use tt_core::DeltaRKind;
//!
//! // Table 1, 0.01 deg/h, Harbin, the default 32-position schedule
//! let cal = Calibration::new(&gw_model::paper::gyrowheel(), &gw_model::paper::site(), &paper::schedule())?;
//! let req = RequirementProblem::new(cal, Reading::PAPER, DeltaRKind::SmallAngle).requirement()?;
//! // Eq 16: 0.027 deg for all three angles (rounded).
//! for i in req.requirement().deg() {
//!     assert!((i.unwrap() - 0.027).abs() < 0.0005);
//! }
//! # Ok::<(), calib_lsq::CalibError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub(crate) mod analysis;
mod calibration;
mod columns;
mod error;
pub mod joint;
mod lsq;
#[cfg(feature = "paper")]
pub mod paper;
mod requirement;
mod schedule;
mod timing;

pub use analysis::{
    ErrorAnalysis, ErrorForm, ErrorWork, Estimate, OrientationErrorAnalysis, OutputsAt, Reading,
    ReadingTerms, ReadingWork,
};
pub use calibration::{
    Calibration, CalibrationResult, OutputCalibration, design_matrix, known_vector,
    simulate_outputs,
};
#[doc(hidden)]
pub use columns::InputColumns;
pub use error::CalibError;
pub use lsq::{
    CoefficientCovariance, Conditioning, LsqSolution, NULL_COMPONENT_TOL, NoiseCovariance,
    RANK_RTOL, RateErrorCovariance, Regression, jacobi_singular_values,
};
pub use requirement::{
    AxisDisagreement, DISAGREE_REL, OrientationRequirement, OutputBox, OutputRegion,
    RequirementParams, RequirementProblem, Surface,
};
pub use schedule::{Position, RateMotion, Schedule};
pub use timing::Timing;
