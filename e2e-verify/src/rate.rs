//! Rate steps end to end: the schedule entries at which a joint turns
//! ([`calib_lsq::RateMotion`]), evaluated through the exact chain
//! ([`tt_kinematics::RateStepFrames`]), and the table errors only rotation exposes.
//!
//! # The errors of a study with rate steps
//! A static position sees the orientation alone, so the error vector is $\chi$ (the angular
//! errors, rad). Once the schedule has a rate step, three more kinds of table error act, the
//! extra errors of [`crate::EndToEnd`] (in this order; [`ExtraError`]):
//! - every translation error of the description (m): a non-intersection of the axes puts the
//!   sensor off the turning axis, and the accelerometers feel $\Omega^2 r$;
//! - per turning joint, its rate accuracy $\varepsilon$ (relative; a sheet's ppm / $10^6$):
//!   the rate averaged over whole revolutions is $\Omega_c(1+\varepsilon)$, so a gyro's scale
//!   factor estimated from it is off by $\varepsilon$ to first order;
//! - per turning joint, its rate ripple $(\rho_c, \rho_s)$ (relative, first harmonic of the
//!   shaft angle): the time average weighs the angles unevenly and leaves $\rho/2$ of gravity
//!   and of the earth's rate across the axis.
//!
//! Every evaluation of $\chi$ holds them at [`crate::EndToEnd::extra_values`] (zero: an ideal
//! rate table); [`RateTolerances`] bound them like the angles, and the worst case, the
//! allocation and the Monte Carlo of this module take both boxes at once. A study without
//! rate steps has no extra error and keeps its answers exactly.

use calib_lsq::Calibration;
use gw_model::InputValues;
use nalgebra::{Matrix3, Vector3};
use tt_kinematics::{Pose, RateEnvironment, RateErrorValues, RateStep, RateStepFrames, Turntable};

use crate::error::E2eError;

/// A table error beyond the angular errors $\chi$, appended to $\chi$ when the schedule has a
/// rate step (see the [module](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExtraError {
    /// The translation error of this index (m).
    Translation(usize),
    /// The rate accuracy of this joint (relative).
    RateAccuracy(usize),
    /// The cosine part of this joint's rate ripple (relative).
    RippleCos(usize),
    /// The sine part of this joint's rate ripple (relative).
    RippleSin(usize),
}

impl ExtraError {
    /// The name of the error: the translation's name, `<joint>_rate_accuracy`,
    /// `<joint>_rate_ripple_cos`, `<joint>_rate_ripple_sin`.
    #[must_use]
    pub fn name(&self, turntable: &Turntable) -> String {
        let joint = |j: usize| turntable.joints()[j].name.clone();
        match *self {
            ExtraError::Translation(i) => turntable.translation_errors()[i].name.clone(),
            ExtraError::RateAccuracy(j) => format!("{}_rate_accuracy", joint(j)),
            ExtraError::RippleCos(j) => format!("{}_rate_ripple_cos", joint(j)),
            ExtraError::RippleSin(j) => format!("{}_rate_ripple_sin", joint(j)),
        }
    }

    /// Whether the error is a translation (m); otherwise a relative rate error.
    #[must_use]
    pub fn is_translation(&self) -> bool {
        matches!(self, ExtraError::Translation(_))
    }
}

/// One rate step compiled for the fast path.
#[derive(Debug, Clone)]
pub(crate) struct RateEntry {
    pub(crate) frames: RateStepFrames,
    pub(crate) env: RateEnvironment,
    /// Index in the extra errors of the joint's rate accuracy (ripple cos, sin follow).
    pub(crate) rate_index: usize,
}

/// The rate steps of a schedule and the extra errors they expose.
#[derive(Debug, Clone, Default)]
pub(crate) struct RatePlan {
    /// One per position; `None` for a static position.
    pub(crate) entries: Vec<Option<RateEntry>>,
    /// The extra errors, after $\chi$.
    pub(crate) extra: Vec<ExtraError>,
}

impl RatePlan {
    /// The plan of `calibration`'s schedule on `turntable` at `poses` (empty for a static
    /// schedule).
    pub(crate) fn new(
        turntable: &Turntable,
        calibration: &Calibration,
        poses: &[Pose],
    ) -> Result<Self, E2eError> {
        let positions = calibration.schedule().positions();
        if !calibration.schedule().has_rate_steps() {
            return Ok(Self {
                entries: vec![None; positions.len()],
                extra: Vec::new(),
            });
        }
        let mut joints: Vec<usize> = positions
            .iter()
            .filter_map(|p| p.motion().map(|m| m.joint))
            .collect();
        joints.sort_unstable();
        joints.dedup();
        let mut extra: Vec<ExtraError> = (0..turntable.n_translation_errors())
            .map(ExtraError::Translation)
            .collect();
        for &j in &joints {
            extra.extend([
                ExtraError::RateAccuracy(j),
                ExtraError::RippleCos(j),
                ExtraError::RippleSin(j),
            ]);
        }
        let site = calibration.site();
        let entries = positions
            .iter()
            .zip(poses)
            .map(|(p, pose)| {
                let Some(m) = p.motion() else {
                    return Ok(None);
                };
                let step = RateStep {
                    joint: m.joint,
                    rate_rad_per_s: m.rate_rad_per_s,
                    pose: pose.clone(),
                    revolutions: m.revolutions,
                };
                let rate_index = extra
                    .iter()
                    .position(|e| *e == ExtraError::RateAccuracy(m.joint))
                    .unwrap_or_default();
                Ok(Some(RateEntry {
                    frames: turntable.rate_step_frames(&step)?,
                    env: RateEnvironment {
                        specific_force_base_g: site.specific_force_base_g(),
                        earth_rate_base_rad_per_s: site.earth_rate_base_rad_per_s(),
                        lever_arm_m: Vector3::from(m.lever_arm_m),
                    },
                    rate_index,
                }))
            })
            .collect::<Result<Vec<_>, E2eError>>()?;
        Ok(Self { entries, extra })
    }

    /// Whether the schedule has a rate step.
    pub(crate) fn is_active(&self) -> bool {
        !self.extra.is_empty() || self.entries.iter().any(Option::is_some)
    }

    /// The averaged inputs (g, deg/h) at rate entry `entry` for the extra errors `extra`,
    /// with the angular errors' rotations `rotations` ([`Turntable::error_rotations`]).
    pub(crate) fn inputs(
        &self,
        entry: &RateEntry,
        rotations: &[Matrix3<f64>],
        extra: &[f64],
        n_translations: usize,
    ) -> Result<InputValues, E2eError> {
        let (translations, x) = (&extra[..n_translations], extra);
        let k = entry.rate_index;
        let re = RateErrorValues {
            accuracy: x[k],
            ripple: [x[k + 1], x[k + 2]],
        };
        let avg = entry
            .frames
            .average(rotations, translations, &re, &entry.env)?;
        Ok(InputValues::new(
            &avg.specific_force_g,
            &avg.rate_rad_per_s
                .map(tt_core::units::rad_per_s_to_deg_per_h),
        ))
    }
}
