//! Geometric error model of a two-axis turntable (Zhao, Zhao, Huo and Yao 2017, §3).
//!
//! A two-axis turntable orients a sensor with an outer axis (rotation $\phi_1$ about $y$) and an
//! inner axis (rotation $\phi_2$ about $z$). Its geometric errors (Table 2 of the paper) make the
//! sensor's actual orientation differ from the intended one by a small rotation
//! $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ (eq 23), read out as the three angles
//! $\Delta\psi$ (about $y$), $\Delta\theta$ (about $z$) and $\Delta\gamma$ (about $x$) (eq 24).
//!
//! This crate gives that error three ways, behind one trait, [`OrientationErrorModel`]:
//!
//! | implementation | paper | what it is |
//! |---|---|---|
//! | [`ExactChain`] | eq 17-24 with finite rotations | every error a finite rotation, in Table 3's order |
//! | [`SmallAngleChain`] | eq 17-24 as printed | the printed $I + [\delta]_\times$ error matrices multiplied out |
//! | [`ClosedForm`] | eq 26-27 | the first-order model, linear in the errors |
//!
//! and the sensitivities of eq 28 ([`sensitivity`]): the analytic Jacobian of the exact chain and
//! its average over the rotation angles (the data of Figure 8), in closed form and numerically.
//!
//! # Frames, rotation order and signs
//! $\mathcal F_0$ base, $\mathcal F_1$ outer axis, $\mathcal F_2$ inner-axis reference,
//! $\mathcal F_3$ inner axis, $\mathcal F_4$ GyroWheel ($= \mathcal F_3$, eq 20). Rotations are
//! right-handed and active, composed by post-multiplication in the order of Table 3:
//!
//! $$\mathbf R_t = R_y(\phi_1) R_y(\Delta\phi_{y1}) R_z(\Delta\alpha_{z1}) R_x(\Delta\alpha_{x1})
//!   \cdot R_y(\Delta\varepsilon_y) R_x(\Delta\varepsilon_x)
//!   \cdot R_z(\phi_2) R_y(\Delta\alpha_{y2}) R_z(\Delta\phi_{z2}) R_x(\Delta\alpha_{x2}),$$
//!
//! $$\mathbf R_d = R_y(\phi_1) R_z(\phi_2).$$
//!
//! # Example
//! ```
//! use tt_kinematics::{ClosedForm, ExactChain, OrientationErrorModel, Pose, TurntableErrors};
//!
//! // Table 4 of the paper, arcminutes, in the order of chi (eq 25); intersection error 0.1 mm.
//! let chi = TurntableErrors::from_arcmin(
//!     [0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233], 1e-4)?;
//! let pose = Pose::from_deg(30.0, 45.0)?;
//! let exact = ExactChain::default().orientation_error(&pose, &chi);
//! let linear = ClosedForm.orientation_error(&pose, &chi);
//! // Both agree to second order in the (sub-arcminute) errors.
//! assert!((exact.delta_psi_rad - linear.delta_psi_rad).abs() < 1e-7);
//! # Ok::<(), tt_kinematics::KinematicsError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![forbid(unsafe_code)]

mod chain;
mod error;
mod errors;
mod linear;
mod model;
mod pose;
pub mod rotation;
pub mod sensitivity;
pub mod units;

pub use chain::{
    ChainKind, Factor, actual_transform, delta_r, exact_factors, ideal_transform, link_transforms,
};
pub use error::KinematicsError;
pub use errors::{CHI_LEN, ErrorComponent, TurntableErrors};
pub use linear::{LinearModel, OrientationAxis, WorstPose};
pub use model::{
    ClosedForm, ExactChain, OrientationError, OrientationErrorModel, ReadOut, SmallAngleChain,
};
pub use pose::Pose;
