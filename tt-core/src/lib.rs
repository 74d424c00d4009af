//! The shared vocabulary of the turntable error-allocation crates, so that a turntable model,
//! a sensor model, an allocation and a Monte Carlo built by different people speak of the same
//! things in the same units:
//!
//! - [`units`]: the conversions at the edges (degrees, arcminutes, arcseconds, deg/h) and the
//!   one conversion of an allocation objective $J$ from rad⁻² to arcmin⁻²;
//! - [`Axis`], [`SignedAxis`]: coordinate axes of the current frame;
//! - [`OrientationAxis`]: the angles $\psi, \theta, \gamma$, their one spelling (`"psi"`,
//!   `"theta"`, `"gamma"`) and the frame axis each turns about;
//! - [`OrientationError`]: $(\Delta\psi, \Delta\theta, \Delta\gamma)$ in radians and its matrix
//!   $\Delta\mathbf R$ ([`DeltaRKind`]: eq 7's small-angle matrix or the exact rotation);
//! - [`Requirement`]: $(I_\psi, I_\theta, I_\gamma)$ of eq 15-16, an option per angle, radians;
//! - [`Pose`]: commanded joint angles, radians;
//! - [`FieldError`] with its checks ([`finite`], [`positive`], [`non_negative`], [`length`],
//!   [`in_range`], [`count`]) and [`ErrorClass`]: every library error says whether it is the
//!   caller's input (naming the field) or internal;
//! - [`human`]: numbers and text for people (significant digits, exact round-trip digits,
//!   text from a file made safe to show), the one formatting every crate's output uses.
//!
//! Radians, rad/s and g inside; degrees and arcminutes only in names that say so.
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782 (eq 7, 15-16, 24 for the angles and the requirement).
#![forbid(unsafe_code)]

mod axis;
mod error;
pub mod human;
mod orientation;
mod pose;
mod requirement;
pub mod units;

pub use axis::{Axis, SignedAxis};
pub use error::{ErrorClass, FieldError, count, finite, in_range, length, non_negative, positive};
pub use orientation::{DeltaRKind, OrientationAxis, OrientationError};
pub use pose::Pose;
pub use requirement::Requirement;

/// The README's example, run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub(crate) struct ReadmeDoctests;
