//! Geometric error model of any serial turntable (one, two or three axes), described as data;
//! the paper's two-axis table (Zhao, Zhao, Huo and Yao 2017, §3) is one instance
//! (module `paper`, behind the `paper` feature).
//!
//! A turntable orients a sensor through joints. Its geometric errors (position errors,
//! wobbles, orthogonality and intersection errors; Table 2 of the paper for a two-axis table)
//! make the platform's actual orientation differ from the intended one by a small rotation
//! $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ (eq 23), read out as the three angles
//! $\Delta\psi$ (about $y$), $\Delta\theta$ (about $z$) and $\Delta\gamma$ (about $x$) (eq 24).
//!
//! - [`TurntableDescription`]: an ordered list of factors from the base to the platform
//!   (joints, error rotations, error translations, fixed rotations), validated and compiled by
//!   [`Turntable::new`] into the exact and small-angle chains, the analytic Jacobian
//!   ([`Turntable::jacobian`]) and a flat evaluation plan for hot loops ([`Turntable::plan`]);
//! - [`OrientationErrorModel`]: pose and errors to $(\Delta\psi, \Delta\theta, \Delta\gamma)$,
//!   implemented by [`ExactChain`], [`SmallAngleChain`], [`LinearChain`] and the paper's
//!   `paper::ClosedForm` (eq 26); its conformance suite is library code
//!   (`conformance` feature) so another implementation can run it;
//! - [`LinearModel`]: the first-order model of any description, its worst case over the poses
//!   (Lemma 1's quantity) and its average sensitivities (eq 28, Figure 8);
//! - [`Turntable::proportional_groups`]: the errors that act only together (one rotation to
//!   first order, e.g. a wobble about the next joint's axis and that joint's position error),
//!   found exactly from the description ([`groups`]);
//! - [`variation`]: errors that vary with a shaft angle (harmonics of a joint, or any bounded
//!   function of it), expanded into coefficients with the dual norm of each error's bound set.
//!
//! # Frames, rotation order and signs
//! Rotations are right-handed and active, composed by post-multiplication in the order of the
//! description (base first): each factor turns about (or moves along) an axis of the frame the
//! previous factors produced. $\mathbf R_d$ and $\mathbf R_t$ map platform coordinates to base
//! coordinates. For the paper's Table 3:
//!
//! $$\mathbf R_t = R_y(\phi_1) R_y(\Delta\phi_{y1}) R_z(\Delta\alpha_{z1}) R_x(\Delta\alpha_{x1})
//!   \cdot R_y(\Delta\varepsilon_y) R_x(\Delta\varepsilon_x)
//!   \cdot R_z(\phi_2) R_y(\Delta\alpha_{y2}) R_z(\Delta\phi_{z2}) R_x(\Delta\alpha_{x2}),
//!   \qquad \mathbf R_d = R_y(\phi_1) R_z(\phi_2).$$
//!
//! # Example: describe your own table
//! ```
//! use tt_kinematics::{ExactChain, FactorSpec, OrientationErrorModel, Pose, SignedAxis,
//!     Turntable, TurntableDescription, TurntableErrors};
//! let j = FactorSpec::joint;
//! let e = FactorSpec::error;
//! // A three-axis table: outer about z, middle about x, inner about y.
//! let table = Turntable::new(&TurntableDescription::new(vec![
//!     j("outer", SignedAxis::Z), e("d_outer", SignedAxis::Z),
//!     e("perp_om", SignedAxis::Y),
//!     j("middle", SignedAxis::X), e("d_middle", SignedAxis::X),
//!     e("perp_mi", SignedAxis::Z),
//!     j("inner", SignedAxis::Y), e("d_inner", SignedAxis::Y),
//! ]))?;
//! let chi = TurntableErrors::from_arcmin(&[0.5, 0.2, 0.5, 0.2, 0.5], &[])?;
//! let pose = Pose::from_deg(&[30.0, 45.0, 60.0])?;
//! let err = ExactChain::new(&table).orientation_error(&pose, &chi)?;
//! assert!(err.delta_psi_rad.abs() < 1e-3);
//! # Ok::<(), tt_kinematics::KinematicsError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

#[cfg(feature = "conformance")]
pub mod conformance;
mod error;
pub mod groups;
pub mod linear;
mod model;
#[cfg(feature = "paper")]
pub mod paper;
mod pose;
pub mod rate;
pub mod rotation;
mod schedule;
pub mod sensitivity;
pub mod turntable;
pub mod variation;

pub use error::KinematicsError;
pub use groups::{ErrorGroup, GROUP_AXIS_TOLERANCE};
pub use linear::{
    AVERAGE_GRID_POINTS, CERTIFY_MAX_EVALUATIONS, CERTIFY_REL_GAP, LinearModel, POSE_GRID_POINTS,
    POSE_REFINE_STEPS, STRUCTURAL_ZERO, WorstPose, max_harmonic_sum, mean_abs_harmonic,
};
pub use model::{
    AtPoses, DERIVED_FIRST_ORDER_TOLERANCE, ExactChain, FIRST_ORDER_STEP_RAD, LinearChain,
    OrientationErrorModel, ReadOut, ScheduleErrorModel, SmallAngleChain, delta_r_of_angles,
    derived_first_order,
};
pub use pose::TurntableErrors;
pub use rate::{
    RateAverage, RateEnvironment, RateErrorBox, RateErrorValues, RateRemainder, RateStep,
    RateStepFrames, STANDARD_GRAVITY_M_PER_S2, ripple_averages,
};
pub use schedule::TurntableSchedule;
/// The shared vocabulary this crate's API speaks ([`tt_core`]), re-exported.
pub use tt_core::{Axis, OrientationAxis, OrientationError, Pose, SignedAxis};
pub use turntable::{
    ChainKind, ErrorInfo, Factor, FactorSpec, Joint, PlanStep, PoseFrames, Turntable,
    TurntableDescription, is_valid_name, quat_conjugate_axis, quat_mul_axis, quat_readout,
};
pub use variation::{
    BoundGroup, ErrorVariation, Expansion, GroupShape, HarmonicDualNorm, draw_disc_pair, on_shafts,
    validate_variations,
};
