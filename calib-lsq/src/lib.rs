//! Multiposition least-squares calibration of a GyroWheel and the effect of an orientation
//! error on it (Zhao, Zhao, Huo and Yao 2017, §2, eq 2-16, Figures 4-5).
//!
//! - [`Schedule`]: turntable positions, checked to identify all seven coefficients of each axis
//!   ([`CalibError::Unidentifiable`] names the ones they cannot); a documented default
//!   ([`Schedule::paper_default`]).
//! - [`calibrate`], [`Regression`], [`LsqSolution`]: eq 5-6 by QR, never forming
//!   $\mathbf A^T\mathbf A$, with residuals, rank and condition number.
//! - [`simulate_outputs`]: the outputs $\mathbf b_1$ for any per-position $\Delta\mathbf R$
//!   (eq 8-9), e.g. the exact turntable error of eq 23.
//! - [`OrientationErrorAnalysis`]: eq 7-14 for one axis under an explicit [`Reading`] of eq 13
//!   (see [`analysis`] for all readings and what each gives).
//! - [`RequirementProblem`]: surfaces $\Gamma_1$, $\Gamma_2$ ([`PlaneProblem::surface`]), the
//!   lines of Figure 5 ([`PlaneProblem::boundary`]) and the requirement of eq 15-16
//!   ([`RequirementProblem::requirement`]).
//!
//! # Example
//! ```
//! use calib_lsq::{RequirementProblem, Reading};
//!
//! let problem = RequirementProblem::paper(); // Table 1, 0.01 deg/h, Harbin, default schedule
//! assert_eq!(problem.reading, Reading::PAPER);
//! let req = problem.requirement()?;
//! let [psi, theta, gamma] = req.deg();
//! // Eq 16: 0.027 deg for all three angles (rounded).
//! for i in [psi, theta, gamma] {
//!     assert!((i - 0.027).abs() < 0.0005, "{i}");
//! }
//! # Ok::<(), calib_lsq::CalibError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![forbid(unsafe_code)]

pub mod analysis;
mod error;
mod lsq;
mod requirement;
mod schedule;

pub use analysis::{
    ErrorAnalysis, ErrorForm, Estimate, OrientationErrorAnalysis, OutputsAt, Reading,
};
pub use error::CalibError;
pub use lsq::{LsqSolution, NULL_COMPONENT_TOL, RANK_RTOL, Regression, solve_least_squares};
pub use requirement::{
    BOUNDARY_CHECK_POINTS, DIRECTION_SCAN, DIRECTION_TOL_RAD, OrientationRequirement,
    PAPER_OMEGA_M_DEG_PER_H, PlaneProblem, RADIUS_TOL_RAD, Rectangle, RequirementProblem,
    SEARCH_LIMIT_RAD, Surface,
};
pub use schedule::{
    Calibration, DEFAULT_PHI_1_DEG, DEFAULT_PHI_2_DEG, Schedule, actual_inputs, calibrate,
    calibrate_simulated, rate_vector, regression_matrix, simulate_outputs,
};
