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
//! rate table); [`RateTolerance`]s bound them like the angles, and the worst case, the
//! allocation and the Monte Carlo of this module take both boxes at once. A study without
//! rate steps has no extra error and keeps its answers exactly.

use calib_lsq::Calibration;
use gw_model::InputValues;
use nalgebra::{Matrix3, Vector3};
use tt_kinematics::{Pose, RateEnvironment, RateErrorValues, RateStep, RateStepFrames, Turntable};

use crate::error::E2eError;
use crate::linear::terms_remainder;

/// Rounding allowance of one evaluation of a rate step's inputs in the certified bound,
/// relative to the inputs' size: $2^{-40}$, about 80 times the rounding of the few dozen
/// operations of the compiled chain ($\approx 100\,\epsilon$, $\epsilon = 2^{-53}$).
const FD_ROUNDING_REL: f64 = 1.0 / (1u64 << 40) as f64;

/// What the direct allocation with the rate tolerances ([`crate::RateQuestions::allocate_direct_rate`])
/// checks and why that is not a certificate; the certificate is
/// [`crate::RateQuestions::allocate_direct_rate_certified`].
pub const NOT_CERTIFIED_AT_RATE_STEPS: &str = "the direct allocation with the rate tolerances is checked on the exact chain at each output's worst vertex, with the margin stated, which is not a certificate (the other vertices and the interior of the box are bounded to first order only); the certified allocation keeps the derived second-order bound of the revolution averages free and is a certificate";

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
    /// The plan of a static schedule of `n` positions: no rate step, no extra error.
    pub(crate) fn static_schedule(n: usize) -> Self {
        Self {
            entries: vec![None; n],
            extra: Vec::new(),
        }
    }

    /// The plan of `calibration`'s schedule on `turntable` at `poses` (empty for a static
    /// schedule).
    pub(crate) fn new(
        turntable: &Turntable,
        calibration: &Calibration,
        poses: &[Pose],
    ) -> Result<Self, E2eError> {
        let positions = calibration.schedule().positions();
        if !calibration.schedule().has_rate_steps() {
            return Ok(Self::static_schedule(positions.len()));
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

/// The worst case of one output over the angular box and the extra errors' box together
/// ([`crate::RateQuestions::worst_case_with_extra`]): `linear_bound` is
/// $\max_i \big(\sum_j |M_{ij}|\,\mathrm{UB}_j + \sum_e |N_{ie}|\,T_e\big)$ (output unit,
/// exact for the linearised model), `position` the entry (position or rate step) where it is
/// reached, `exact_at_vertex` $\Delta\omega_k$ on the exact chain at the worst vertex (the
/// larger of it and its negative).
pub type ExtraOutputWorstCase = crate::OutputWorstCase<ExtraDetail>;

/// What the worst case with the extra errors adds ([`ExtraOutputWorstCase`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct ExtraDetail {
    /// The angular errors' part of the linear bound at the worst entry.
    pub(crate) angular_part: f64,
    /// Each extra error's part of it there, $|N_{ie}|\,T_e$ (order of
    /// [`crate::EndToEnd::extra_errors`]).
    pub(crate) extra_parts: Vec<f64>,
}

/// Read access to the extra errors' data.
impl ExtraOutputWorstCase {
    /// The angular errors' part of the linear bound at the worst entry.
    #[must_use]
    pub fn angular_part(&self) -> f64 {
        self.detail.angular_part
    }

    /// Each extra error's part of it there, $|N_{ie}|\,T_e$ (order of
    /// [`crate::EndToEnd::extra_errors`]).
    #[must_use]
    pub fn extra_parts(&self) -> &[f64] {
        &self.detail.extra_parts
    }
}

impl ExtraOutputWorstCase {
    /// The extra errors' total part at the worst entry.
    #[must_use]
    pub fn extra_part(&self) -> f64 {
        self.detail.extra_parts.iter().sum()
    }
}

/// Check extra-error bounds: one per extra error, finite and non-negative.
fn check_extra_bounds(e2e: &crate::EndToEnd, bounds: &[f64]) -> Result<(), E2eError> {
    tt_core::length("extra error bounds", e2e.extra_errors().len(), bounds.len())
        .map_err(|e| E2eError::Kinematics(e.into()))?;
    for (name, b) in e2e.extra_names().into_iter().zip(bounds) {
        if !b.is_finite() {
            return Err(tt_core::FieldError::NonFinite {
                field: name,
                value: *b,
            }
            .into());
        }
        if *b < 0.0 {
            return Err(tt_core::FieldError::NotPositive {
                field: name,
                value: *b,
            }
            .into());
        }
    }
    Ok(())
}

impl crate::RateQuestions<'_> {
    /// The Jacobian $\mathbf N$ of every output's error vector with respect to the extra
    /// errors ([`crate::EndToEnd::extra_errors`]; per metre or per unit of relative rate error),
    /// at $\chi = 0$ and the extra errors at [`crate::EndToEnd::extra_values`]: zero rows at
    /// the static positions.
    #[must_use]
    pub fn extra_linearization(&self) -> crate::Linearization {
        let du = self.extra_input_derivatives();
        self.linearization_with(self.extra_errors().len(), |i, j, _| du[i][j])
    }

    /// The derivative of each entry's six inputs with respect to each extra error
    /// (`[entry][extra error]`, zero at the static positions): what the extra errors'
    /// linearisations ([`crate::RateQuestions::extra_linearization`],
    /// [`crate::RateQuestions::extra_coefficient_linearization`]) are built from.
    pub(crate) fn extra_input_derivatives(&self) -> Vec<Vec<[f64; 6]>> {
        let n_extra = self.extra_errors().len();
        (0..self.len())
            .map(|i| {
                (0..n_extra)
                    .map(|j| self.rate_input_derivative(i, j, true).unwrap_or([0.0; 6]))
                    .collect()
            })
            .collect()
    }

    /// The worst case over the angular box $|\chi_j| \le \mathrm{UB}_j$ and the extra
    /// errors' box $|x_e| \le T_e$ together, per output: exact for the linearised model
    /// ($\mathbf M$ of [`crate::EndToEnd::linearization`], $\mathbf N$ of
    /// [`crate::RateQuestions::extra_linearization`]), confirmed on the exact chain at the worst
    /// vertex, with each extra error's part. With every $T_e = 0$ it is
    /// [`crate::EndToEnd::worst_case`]'s linear bound.
    ///
    /// # Errors
    /// [`E2eError::Field`] naming a bad bound; as [`crate::EndToEnd::delta_omega`].
    pub fn worst_case_with_extra(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        ub_rad: &[f64],
        extra_bounds: &[f64],
    ) -> Result<Vec<ExtraOutputWorstCase>, E2eError> {
        self.check_bounds(linear, ub_rad)?;
        check_extra_bounds(self, extra_bounds)?;
        let angular = linear.row_worst_cases(ub_rad);
        let extra = extra_linear.row_worst_cases(extra_bounds);
        let n = self.len();
        let mut work = self.work();
        (0..self.n_outputs())
            .map(|k| {
                let (position, bound) = (0..n)
                    .map(|i| (i, angular[k * n + i] + extra[k * n + i]))
                    .fold((0, f64::NEG_INFINITY), |b, c| if c.1 > b.1 { c } else { b });
                let vertex = |row: Vec<f64>, bounds: &[f64]| -> Vec<f64> {
                    row.iter()
                        .zip(bounds)
                        .map(|(m, u)| match (u.is_finite(), *m < 0.0) {
                            (false, _) => 0.0,
                            (true, true) => -u,
                            (true, false) => *u,
                        })
                        .collect()
                };
                let chi = vertex(linear.row(k, position), ub_rad);
                let x = vertex(extra_linear.row(k, position), extra_bounds);
                self.delta_omega_extra_into(&chi, &x, &mut work)?;
                let plus = work.delta_omega[k];
                let neg = |v: &[f64]| v.iter().map(|a| -a).collect::<Vec<f64>>();
                self.delta_omega_extra_into(&neg(&chi), &neg(&x), &mut work)?;
                let minus = work.delta_omega[k];
                let precision = self.precisions()[k];
                Ok(ExtraOutputWorstCase {
                    output: k,
                    linear_bound: crate::resolved(bound, precision),
                    position,
                    exact_at_vertex: crate::resolved(plus.max(minus), precision),
                    detail: ExtraDetail {
                        angular_part: angular[k * n + position],
                        extra_parts: extra_linear
                            .row(k, position)
                            .iter()
                            .zip(extra_bounds)
                            .map(|(m, t)| m.abs() * t)
                            .collect(),
                    },
                })
            })
            .collect()
    }

    /// Direct allocation of the angular errors with the extra errors at their bounds
    /// `extra_bounds`: each output keeps free the largest part the extra errors' box takes at
    /// any entry, $\max_i\sum_e |N_{ie}|\,T_e$ (a safe margin: at most that row's share), and
    /// the angles get the rest ([`crate::EndToEnd::allocate_direct`] otherwise).
    ///
    /// # Errors
    /// As [`crate::EndToEnd::allocate_direct`]; [`E2eError::MarginExceedsAccuracy`] when the
    /// extra errors alone take an output's whole accuracy; a bad bound.
    pub fn allocate_direct_with_extra(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        extra_bounds: &[f64],
    ) -> Result<crate::DirectAllocation, E2eError> {
        check_extra_bounds(self, extra_bounds)?;
        let rows = extra_linear.row_worst_cases(extra_bounds);
        let n = self.len();
        let margins: Vec<f64> = (0..self.n_outputs())
            .map(|k| rows.rows(k * n, n).max())
            .collect();
        self.allocate_direct_keeping(linear, lower_bounds_rad, &margins)
    }

    /// Monte Carlo over both boxes: `settings.samples` turntables, each angular error with
    /// $|\chi_j|$ uniform in $[\mathrm{LB}_j, \mathrm{UB}_j]$ and a fair random sign (the law of
    /// [`crate::MonteCarloQuestions::rate_distribution`]), each extra error uniform in $[-T_e, T_e]$;
    /// returns how many meet every accuracy and the largest $\Delta\omega_k$ seen. One
    /// ChaCha8 stream per block of `EXTRA_MC_BLOCK` draws (seed, block), run in block
    /// order: the result does not depend on the thread count; memory does not grow with the
    /// count.
    ///
    /// # Errors
    /// A bad bound or setting; as [`crate::EndToEnd::delta_omega`].
    pub fn meeting_count_with_extra(
        &self,
        ub_rad: &[f64],
        lower_bounds_rad: &[f64],
        extra_bounds: &[f64],
        settings: &crate::McSettings,
    ) -> Result<(u64, Vec<f64>), E2eError> {
        use rand_core::{Rng, SeedableRng};
        settings.validate()?;
        check_extra_bounds(self, extra_bounds)?;
        crate::allocate::check_lower_bounds(self.turntable(), lower_bounds_rad)?;
        tt_core::length("upper bounds", self.n_errors(), ub_rad.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let acc = self.accuracies();
        let mut work = self.work();
        let (mut chi, mut x) = (vec![0.0; self.n_errors()], vec![0.0; extra_bounds.len()]);
        let (mut meets, mut max) = (0u64, vec![0.0f64; self.n_outputs()]);
        let uniform = |rng: &mut rand_chacha::ChaCha8Rng| {
            (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
        };
        let mut done = 0u64;
        let mut block = 0u64;
        while done < settings.samples {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(block);
            let count = EXTRA_MC_BLOCK.min(settings.samples - done);
            for _ in 0..count {
                for ((c, u), l) in chi.iter_mut().zip(ub_rad).zip(lower_bounds_rad) {
                    let u = if u.is_finite() { *u } else { 0.0 };
                    let magnitude = l + (u - l).max(0.0) * uniform(&mut rng);
                    *c = if rng.next_u32() & 1 == 0 {
                        magnitude
                    } else {
                        -magnitude
                    };
                }
                for (v, t) in x.iter_mut().zip(extra_bounds) {
                    *v = t * (2.0 * uniform(&mut rng) - 1.0);
                }
                self.delta_omega_extra_into(&chi, &x, &mut work)?;
                let mut ok = true;
                for (k, d) in work.delta_omega.iter().enumerate() {
                    let d = crate::resolved(*d, self.precisions()[k]);
                    max[k] = max[k].max(d);
                    ok &= d <= acc[k];
                }
                meets += u64::from(ok);
            }
            done += count;
            block += 1;
        }
        Ok((meets, max))
    }
}

/// Draws per random stream of [`crate::RateQuestions::meeting_count_with_extra`].
pub(crate) const EXTRA_MC_BLOCK: u64 = 4096;

/// A tolerance of the errors only rotation exposes, as a rate table's sheet gives it: one per
/// translation (m), and per turning joint its rate accuracy and its rate ripple (relative; the
/// ripple's one bound holds both parts, cosine and sine, of the first harmonic).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RateTolerance {
    /// The translation error of this index (m).
    Translation(usize),
    /// The rate accuracy of this joint (relative).
    RateAccuracy(usize),
    /// The rate ripple of this joint, each part of its first harmonic (relative).
    Ripple(usize),
}

impl RateTolerance {
    /// The tolerance an extra error is bounded by.
    #[must_use]
    pub fn of(x: ExtraError) -> Self {
        match x {
            ExtraError::Translation(i) => RateTolerance::Translation(i),
            ExtraError::RateAccuracy(j) => RateTolerance::RateAccuracy(j),
            ExtraError::RippleCos(j) | ExtraError::RippleSin(j) => RateTolerance::Ripple(j),
        }
    }

    /// The sheet's key name: the translation's name, `<joint>_rate_accuracy`,
    /// `<joint>_rate_ripple`.
    #[must_use]
    pub fn name(&self, turntable: &Turntable) -> String {
        let joint = |j: usize| turntable.joints()[j].name.clone();
        match *self {
            RateTolerance::Translation(i) => turntable.translation_errors()[i].name.clone(),
            RateTolerance::RateAccuracy(j) => format!("{}_rate_accuracy", joint(j)),
            RateTolerance::Ripple(j) => format!("{}_rate_ripple", joint(j)),
        }
    }

    /// Whether the tolerance is a translation (m); otherwise a relative rate error.
    #[must_use]
    pub fn is_translation(&self) -> bool {
        matches!(self, RateTolerance::Translation(_))
    }
}

/// The direct allocation of a study with rate steps: the angular errors and the rate
/// tolerances ([`RateTolerance`]) allocated together, checked on the exact chain at each
/// output's worst vertex ([`crate::RateQuestions::allocate_direct_rate`]) or certified over the
/// whole box ([`crate::RateQuestions::allocate_direct_rate_certified`], with a
/// [`RateAllocation::certificate`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RateAllocation {
    /// The allocation over the joint vector $(\chi, T)$: `upper_bounds_rad` holds the angular
    /// errors' bounds (rad) and then the tolerances' (m or relative, order of
    /// [`RateAllocation::tolerances`]); `objective` is $J$ over both (rad$^{-2}$, the
    /// tolerances' terms on the angles' scale, see [`crate::RateQuestions::rate_tolerance_weights`]);
    /// `second_order_margins` the room kept for the exact chain (at the worst vertex, or the
    /// second-order bound of a certified allocation).
    pub(crate) combined: crate::DirectAllocation,
    /// The tolerances allocated, in order.
    pub(crate) tolerances: Vec<RateTolerance>,
    /// Their weights $w_t$ (unit of the tolerance per rad).
    pub(crate) weights: Vec<f64>,
    /// Per output, the worst case over both boxes (the angular box and every extra error
    /// within its tolerance), linearised and on the exact chain at its worst vertex (empty
    /// for a certified allocation: its certificate bounds the whole box).
    pub(crate) worst_cases: Vec<ExtraOutputWorstCase>,
    /// Re-solves that kept room for the exact chain at the worst vertex (0: the first-order
    /// allocation already met every accuracy there; 0 for a certified allocation).
    pub(crate) exact_rounds: usize,
    /// The certificate: every turntable of the box meets every accuracy on the exact chain
    /// (`None` for the check at the worst vertex).
    pub(crate) certificate: Option<RateCertificate>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RateAllocation {
    /// The allocation over the joint vector $(\chi, T)$: `upper_bounds_rad` holds the angular
    /// errors' bounds (rad) and then the tolerances' (m or relative, order of
    /// [`RateAllocation::tolerances`]); `objective` is $J$ over both (rad$^{-2}$, the
    /// tolerances' terms on the angles' scale, see [`crate::RateQuestions::rate_tolerance_weights`]);
    /// `second_order_margins` the room kept for the exact chain (at the worst vertex, or the
    /// second-order bound of a certified allocation).
    #[must_use]
    pub fn combined(&self) -> &crate::DirectAllocation {
        &self.combined
    }

    /// The tolerances allocated, in order.
    #[must_use]
    pub fn tolerances(&self) -> &[RateTolerance] {
        &self.tolerances
    }

    /// Their weights $w_t$ (unit of the tolerance per rad).
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Per output, the worst case over both boxes (the angular box and every extra error
    /// within its tolerance), linearised and on the exact chain at its worst vertex (empty
    /// for a certified allocation: its certificate bounds the whole box).
    #[must_use]
    pub fn worst_cases(&self) -> &[ExtraOutputWorstCase] {
        &self.worst_cases
    }

    /// Re-solves that kept room for the exact chain at the worst vertex (0: the first-order
    /// allocation already met every accuracy there; 0 for a certified allocation).
    #[must_use]
    pub fn exact_rounds(&self) -> usize {
        self.exact_rounds
    }

    /// The certificate: every turntable of the box meets every accuracy on the exact chain
    /// (`None` for the check at the worst vertex).
    #[must_use]
    pub fn certificate(&self) -> Option<&RateCertificate> {
        self.certificate.as_ref()
    }
}

impl RateAllocation {
    /// The angular errors' bounds (rad; `+inf` for an error no output depends on).
    #[must_use]
    pub fn angles_rad(&self) -> &[f64] {
        &self.combined.upper_bounds_rad
            [..self.combined.upper_bounds_rad.len() - self.tolerances.len()]
    }

    /// The tolerances' bounds (m, relative; `+inf` for one no output depends on).
    #[must_use]
    pub fn tolerance_bounds(&self) -> &[f64] {
        &self.combined.upper_bounds_rad
            [self.combined.upper_bounds_rad.len() - self.tolerances.len()..]
    }
}

/// The largest relative rate accuracy or ripple an allocation hands out: where the outputs
/// barely depend on one (a ripple averaged over whole revolutions), the first-order
/// allocation would give it far beyond the rate-step model's domain (a ripple of 1 stops the
/// table); such a tolerance is lowered to this ceiling, which no precision rate table comes
/// near (their sheets state 1e-3 to 1e-6), so it reads "not limiting up to 1 %". A tighter
/// bound keeps every accuracy met; the exact chain is then evaluated inside its domain.
pub const RATE_TOLERANCE_CEILING: f64 = 0.01;

/// The largest angular tolerance the allocation with rate tolerances hands out (rad, 1 deg):
/// an error the outputs barely depend on to first order (a rotation about the vertical for
/// an accelerometer, a joint's zero offset under a revolution's average) would get tens of
/// degrees, where the second order of the chain dominates and the exact chain at the worst
/// vertex fails every accuracy whatever the margins. Held here it reads "not limiting up to
/// 1 deg"; no precision turntable's sheet comes near it (arcseconds to arcminutes).
pub(crate) const ANGLE_TOLERANCE_CEILING_RAD: f64 = std::f64::consts::PI / 180.0;

/// Relative room kept below each accuracy when the exact chain at the worst vertex of the
/// first-order allocation exceeds it: the second-order excess measured there is kept free,
/// plus this share of the accuracy (dimensionless; the excess changes slightly with the
/// re-solved box, 1e-3 covers that change for boxes whose second-order terms are small).
const RATE_EXACT_ROOM_REL: f64 = 1e-3;

/// Re-solves of [`crate::RateQuestions::allocate_direct_rate`] that keep room for the exact chain.
const RATE_EXACT_ROUNDS: usize = 4;

impl crate::RateQuestions<'_> {
    /// The rate tolerances of the study's extra errors, in the order the extra errors first
    /// name them (translations, then per turning joint its rate accuracy and ripple).
    #[must_use]
    pub(crate) fn rate_tolerances(&self) -> Vec<RateTolerance> {
        let mut out: Vec<RateTolerance> = Vec::new();
        for x in self.extra_errors() {
            let t = RateTolerance::of(*x);
            if !out.contains(&t) {
                out.push(t);
            }
        }
        out
    }

    /// The columns of the combined linearisation over $(\chi, T)$ with a ceiling: every
    /// angle at [`ANGLE_TOLERANCE_CEILING_RAD`], every relative rate tolerance at
    /// [`RATE_TOLERANCE_CEILING`]; translations have none.
    fn rate_ceilings(&self) -> Vec<(usize, f64)> {
        let n = self.n_errors();
        (0..n)
            .map(|j| (j, ANGLE_TOLERANCE_CEILING_RAD))
            .chain(
                self.rate_tolerances()
                    .iter()
                    .enumerate()
                    .filter(|(_, t)| !t.is_translation())
                    .map(|(i, _)| (n + i, RATE_TOLERANCE_CEILING)),
            )
            .collect()
    }

    /// The sheet's names of [`crate::RateQuestions::rate_tolerances`].
    #[must_use]
    pub fn rate_tolerance_names(&self) -> Vec<String> {
        let t = self.turntable();
        self.rate_tolerances().iter().map(|x| x.name(t)).collect()
    }

    /// The extra errors' bounds of the tolerances `bounds` (order of
    /// [`crate::RateQuestions::rate_tolerances`]): each extra error within its tolerance; a
    /// tolerance without a bound (`+inf`, no output depends on it) holds its errors at 0.
    #[must_use]
    pub fn extra_bounds_of(&self, bounds: &[f64]) -> Vec<f64> {
        let tols = self.rate_tolerances();
        self.extra_errors()
            .iter()
            .map(|x| {
                let t = tols
                    .iter()
                    .position(|t| *t == RateTolerance::of(*x))
                    .unwrap_or_default();
                let b = bounds.get(t).copied().unwrap_or(0.0);
                if b.is_finite() { b } else { 0.0 }
            })
            .collect()
    }

    /// The linearisation over $(\chi, T)$: $\mathbf M$ beside one column per rate tolerance,
    /// $\sum_{e \in t} |N_{re}|$ (a tolerance bounding two errors, the ripple's parts, takes
    /// both at its bound in the worst case: their parts add). Rows as $\mathbf M$'s.
    #[must_use]
    pub(crate) fn rate_linearization(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
    ) -> crate::Linearization {
        let tols = self.rate_tolerances();
        let (m, nx) = (linear.matrix(), extra_linear.matrix());
        let (nm, nn) = (linear.rounding(), extra_linear.rounding());
        let cols = m.ncols() + tols.len();
        let mut a = nalgebra::DMatrix::zeros(m.nrows(), cols);
        let mut noise = nalgebra::DMatrix::zeros(nm.nrows().max(linear.outputs()), cols);
        a.view_mut((0, 0), (m.nrows(), m.ncols())).copy_from(m);
        if nm.ncols() == m.ncols() && nm.nrows() == noise.nrows() {
            noise.view_mut((0, 0), nm.shape()).copy_from(nm);
        }
        for (e, x) in self.extra_errors().iter().enumerate() {
            let t = m.ncols()
                + tols
                    .iter()
                    .position(|t| *t == RateTolerance::of(*x))
                    .unwrap_or_default();
            for r in 0..a.nrows() {
                a[(r, t)] += nx[(r, e)].abs();
            }
            if nn.ncols() == nx.ncols() && nn.nrows() == noise.nrows() {
                for k in 0..noise.nrows() {
                    noise[(k, t)] += nn[(k, e)];
                }
            }
        }
        crate::Linearization::from_parts(a, linear.positions(), linear.outputs(), noise)
    }

    /// The weights of the rate tolerances in $J$, on the angles' scale ("like every other
    /// error").
    ///
    /// # Choice
    /// An error's end-to-end natural scale is
    /// $c_j = \sqrt{\sum_k (\omega_{m,k}/\overline{|A_{kj}|})^2}$: per output $k$ the error
    /// that, at its average sensitivity $\overline{|A_{kj}|}$ (over the entries where the error
    /// acts: every entry for an angle, the rate steps for a rate tolerance), takes the whole
    /// accuracy; the outputs combined as eq 28 combines the angles. It has the error's own
    /// unit (rad, m, relative) whatever the outputs' units. The angles keep their eq-28
    /// weights $w_j$ ([`crate::EndToEnd::combined_weights`]); a rate tolerance gets
    /// $w_t = r\,c_t$ with $r$ the geometric mean over the angles of $w_j / c_j$
    /// (rad$^{-1}$): a tolerance costs in $J$ what an angle of the same end-to-end influence
    /// costs, and $w_t/T_t$ has the unit of $w_j/\mathrm{UB}_j$. No sheet's unit (ppm, mm)
    /// enters: the allocation is the same in any unit. A tolerance no output depends on gets
    /// weight 0 (no bound).
    #[must_use]
    pub fn rate_tolerance_weights(&self, combined: &crate::Linearization) -> Vec<f64> {
        let n_angles = self.n_errors();
        let acc = self.accuracies();
        let a = combined.matrix();
        let n = combined.positions();
        let unconstrained = combined.unconstrained();
        let scale = |j: usize| -> Option<f64> {
            if unconstrained.contains(&j) {
                return None;
            }
            let acting: Vec<usize> = (0..n)
                .filter(|&i| (0..acc.len()).any(|k| a[(k * n + i, j)] != 0.0))
                .collect();
            if acting.is_empty() {
                return None;
            }
            let mut sum = 0.0;
            for (k, ak) in acc.iter().enumerate() {
                let avg = acting.iter().map(|&i| a[(k * n + i, j)].abs()).sum::<f64>()
                    / acting.len() as f64;
                if avg > combined.rounding()[(k, j)] && avg > 0.0 {
                    sum += (ak / avg).powi(2);
                }
            }
            (sum > 0.0 && sum.is_finite()).then(|| sum.sqrt())
        };
        let w = self.combined_weights();
        let logs: Vec<f64> = (0..n_angles)
            .filter_map(|j| match (scale(j), w.get(j)) {
                (Some(c), Some(&wj)) if wj > 0.0 && wj.is_finite() => Some((wj / c).ln()),
                _ => None,
            })
            .collect();
        // no angle to compare with: the tolerances' natural scales themselves
        let r = if logs.is_empty() {
            1.0
        } else {
            (logs.iter().sum::<f64>() / logs.len() as f64).exp()
        };
        (n_angles..a.ncols())
            .map(|j| scale(j).map_or(0.0, |c| r * c))
            .collect()
    }

    /// Direct allocation of the angular errors and the rate tolerances together (a study with
    /// rate steps): $\min \sum_j w_j^2/\mathrm{UB}_j^2 + \sum_t w_t^2/T_t^2$ subject to every
    /// row's worst case over both boxes, $\sum_j |M_{rj}|\,\mathrm{UB}_j +
    /// \sum_t |A_{rt}|\,T_t \le \omega_{m,k}$ ([`crate::RateQuestions::rate_linearization`],
    /// weights [`crate::RateQuestions::rate_tolerance_weights`]), $\mathrm{UB} \ge \mathrm{LB}$,
    /// $T \ge 0$; a bound above its ceiling ([`ANGLE_TOLERANCE_CEILING_RAD`],
    /// [`RATE_TOLERANCE_CEILING`]: an error the outputs barely see, "not limiting") is held at
    /// it. The box is then checked on the exact chain at each output's worst vertex
    /// ([`crate::RateQuestions::worst_case_with_extra`]); where the exact chain exceeds an
    /// accuracy the excess plus $10^{-3}$ of the accuracy is kept free and the
    /// allocation solved again (at most 4 times). This is a check at the
    /// worst vertex, not a certificate: see [`NOT_CERTIFIED_AT_RATE_STEPS`] and
    /// [`crate::RateQuestions::allocate_direct_rate_certified`].
    ///
    /// # Errors
    /// As [`crate::EndToEnd::allocate_direct`]; [`E2eError::NoConvergence`] when the exact
    /// chain at the worst vertex still exceeds an accuracy after the re-solves.
    pub fn allocate_direct_rate(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
    ) -> Result<RateAllocation, E2eError> {
        self.allocate_direct_rate_specified(linear, extra_linear, lower_bounds_rad, &[])
    }

    /// [`crate::RateQuestions::allocate_direct_rate`] constrained by every specification as well
    /// (issue 34 item 6): the rows `spec_rows` over the angles and the rate tolerances
    /// ([`crate::RateQuestions::rate_specification_rows`]) beside eq 14's rows. Without rows it is
    /// [`crate::RateQuestions::allocate_direct_rate`].
    ///
    /// # Errors
    /// As [`crate::RateQuestions::allocate_direct_rate`];
    /// [`E2eError::NoTableSuffices`] naming a specification whose noise part alone fills its
    /// limit.
    pub fn allocate_direct_rate_specified(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        spec_rows: &[crate::budget::SpecificationRow],
    ) -> Result<RateAllocation, E2eError> {
        let none = vec![0.0; self.n_outputs()];
        self.with_rate_setup(
            linear,
            extra_linear,
            lower_bounds_rad,
            |setup, combined, lb| {
                self.exact_rounds(linear, extra_linear, setup, combined, lb, &none, spec_rows)
            },
        )
    }

    /// [`crate::RateQuestions::allocate_direct_rate`] with the noise part kept free (issue 35):
    /// every row over both boxes held to $\omega_{m,k} - \kappa\sigma_k$ and the exact chain
    /// at each output's worst vertex checked against the same, so the angles and the rate
    /// tolerances get what the noise leaves; or the outputs whose noise part (with the lower
    /// bounds' table part) leaves no room, as [`crate::NoiseQuestions::allocate_direct_with_noise`].
    ///
    /// With `certify`, [`crate::RateQuestions::allocate_direct_rate_certified`] with the noise
    /// part kept free, its search tuned by `certify`: every turntable of the returned boxes
    /// has an exact-chain error within $\omega_{m,k} - \kappa\sigma_k$ (a study with rate
    /// steps; a static study's answer is [`crate::NoiseQuestions::allocate_direct_with_noise`]
    /// with `certify`).
    ///
    /// # Errors
    /// As [`crate::RateQuestions::allocate_direct_rate`] (with `certify`, as
    /// [`crate::RateQuestions::allocate_direct_rate_certified`]); [`E2eError::Field`] for a bad
    /// `k_sigma`.
    pub fn allocate_direct_rate_with_noise(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        budget: &crate::NoiseBudget,
        k_sigma: f64,
        certify: Option<&crate::CertifyParams>,
    ) -> Result<Result<RateAllocation, Vec<crate::NoRoom>>, E2eError> {
        let noise = match self.rate_noise_margins(linear, lower_bounds_rad, budget, k_sigma)? {
            Ok(m) => m,
            Err(blocked) => return Ok(Err(blocked)),
        };
        match certify {
            None => self.with_rate_setup(
                linear,
                extra_linear,
                lower_bounds_rad,
                |setup, combined, lb| {
                    self.exact_rounds(linear, extra_linear, setup, combined, lb, &noise, &[])
                },
            ),
            Some(params) => {
                self.certified_rate_keeping(linear, extra_linear, lower_bounds_rad, &noise, params)
            }
        }
        .map(Ok)
    }

    /// The noise parts $\kappa\sigma_k$ of `budget`, or the outputs they leave no room.
    fn rate_noise_margins(
        &self,
        linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        budget: &crate::NoiseBudget,
        k_sigma: f64,
    ) -> Result<Result<Vec<f64>, Vec<crate::NoRoom>>, E2eError> {
        crate::noise::check_k_sigma(k_sigma)?;
        crate::allocate::check_lower_bounds(self.turntable(), lower_bounds_rad)?;
        let margins = budget.margins(k_sigma);
        let blocked = self.noise().no_room(linear, lower_bounds_rad, &margins);
        Ok(if blocked.is_empty() {
            Ok(margins)
        } else {
            Err(blocked)
        })
    }

    /// The allocation problem over $(\chi, T)$ of [`crate::RateQuestions::allocate_direct_rate`]
    /// handed to `f` with the combined linearisation and the lower bounds.
    fn with_rate_setup<T>(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        f: impl FnOnce(
            &crate::allocate::DirectSetup<'_>,
            &crate::Linearization,
            &[f64],
        ) -> Result<T, E2eError>,
    ) -> Result<T, E2eError> {
        crate::allocate::check_lower_bounds(self.turntable(), lower_bounds_rad)?;
        let combined = self.rate_linearization(linear, extra_linear);
        let tolerances = self.rate_tolerances();
        let tol_weights = self.rate_tolerance_weights(&combined);
        let mut weights = self.combined_weights();
        weights.extend(&tol_weights);
        let mut names = self.error_names();
        names.extend(self.rate_tolerance_names());
        let mut lb = lower_bounds_rad.to_vec();
        lb.extend(std::iter::repeat_n(0.0, tolerances.len()));
        let acc = self.accuracies();
        let output_names: Vec<&str> = self
            .calibration()
            .outputs()
            .iter()
            .map(|o| o.output().name.as_str())
            .collect();
        let setup = crate::allocate::DirectSetup {
            error_names: &names,
            weights: &weights,
            accuracies: &acc,
            output_names: &output_names,
        };
        f(&setup, &combined, &lb)
    }

    /// The re-solves of [`crate::RateQuestions::allocate_direct_rate`] keeping room for the exact
    /// chain at the worst vertex (with `spec_rows` beside eq 14's rows).
    #[allow(clippy::too_many_arguments)]
    fn exact_rounds(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        setup: &crate::allocate::DirectSetup<'_>,
        combined: &crate::Linearization,
        lb: &[f64],
        noise: &[f64],
        spec_rows: &[crate::budget::SpecificationRow],
    ) -> Result<RateAllocation, E2eError> {
        let tolerances = self.rate_tolerances();
        let tol_weights = self.rate_tolerance_weights(combined);
        let acc = self.accuracies();
        let n_angles = self.n_errors();
        let mut margins = noise.to_vec();
        let ceilings = self.rate_ceilings();
        for round in 0..=RATE_EXACT_ROUNDS {
            let d = setup.capped(
                setup.allocate_with_rows(combined, lb, &margins, None, spec_rows)?,
                &ceilings,
                combined,
            );
            let ub: Vec<f64> = d.upper_bounds_rad[..n_angles]
                .iter()
                .map(|u| if u.is_finite() { *u } else { 0.0 })
                .collect();
            let extra = self.extra_bounds_of(&d.upper_bounds_rad[n_angles..]);
            let worst_cases = self.worst_case_with_extra(linear, extra_linear, &ub, &extra)?;
            let mut over = false;
            for w in &worst_cases {
                let k = w.output;
                if w.exact_at_vertex + noise[k] > acc[k] {
                    over = true;
                    margins[k] +=
                        w.exact_at_vertex + noise[k] - acc[k] + RATE_EXACT_ROOM_REL * acc[k];
                }
            }
            if !over {
                return Ok(RateAllocation {
                    combined: d,
                    tolerances,
                    weights: tol_weights,
                    worst_cases,
                    exact_rounds: round,
                    certificate: None,
                });
            }
        }
        Err(E2eError::NoConvergence {
            what: "direct allocation with rate tolerances (the exact chain at the worst vertex exceeds an accuracy after keeping its excess free)",
            iterations: RATE_EXACT_ROUNDS,
            change: margins.iter().fold(0.0, |a: f64, b| a.max(*b)),
        })
    }
}

/// Decades below [`ANGLE_TOLERANCE_CEILING_RAD`] the certified allocation with rate
/// tolerances searches for an angle ceiling whose box it can certify (down to 1e-6 deg).
const CEILING_SEARCH_DECADES: f64 = 6.0;

/// Bisection steps of that search (on the logarithm: 2^-20 of 6 decades, about 1.3e-5
/// relative on the ceiling).
const CEILING_SEARCH_STEPS: usize = 20;

/// Re-solves of [`crate::RateQuestions::allocate_direct_rate_certified`] that keep the
/// second-order bound free.
const RATE_CERTIFY_ROUNDS: usize = 12;

/// The certificate of a [`RateAllocation`] over the whole box
/// ([`crate::RateQuestions::allocate_direct_rate_certified`]): every turntable of the angular box
/// with every extra error within its tolerance meets every accuracy on the exact chain.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RateCertificate {
    /// Per output, the first-order worst case over both boxes (output unit).
    pub(crate) linear_bounds: Vec<f64>,
    /// Per output, the derived second-order bound $\tau_k$ of the box
    /// ([`crate::RateQuestions::second_order_bound_with_extra`]; output unit).
    pub(crate) second_order_bounds: Vec<f64>,
    /// Re-solves that kept room for the bound (0: the direct allocation with the rate
    /// tolerances was already certified).
    pub(crate) rounds: usize,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RateCertificate {
    /// Per output, the first-order worst case over both boxes (output unit).
    #[must_use]
    pub fn linear_bounds(&self) -> &[f64] {
        &self.linear_bounds
    }

    /// Per output, the derived second-order bound $\tau_k$ of the box
    /// ([`crate::RateQuestions::second_order_bound_with_extra`]; output unit).
    #[must_use]
    pub fn second_order_bounds(&self) -> &[f64] {
        &self.second_order_bounds
    }

    /// Re-solves that kept room for the bound (0: the direct allocation with the rate
    /// tolerances was already certified).
    #[must_use]
    pub fn rounds(&self) -> usize {
        self.rounds
    }

    /// The certified bound of output `k`: first-order worst case plus $\tau_k$.
    #[must_use]
    pub fn certified_bound(&self, k: usize) -> f64 {
        self.linear_bounds[k] + self.second_order_bounds[k]
    }
}

impl crate::RateQuestions<'_> {
    /// The derived second-order bound $\tau_k$ (output unit) of a schedule with rate steps:
    /// $\lVert\Delta\hat{\boldsymbol\omega}_k(\chi, x) - \mathbf M_k\chi - \mathbf N_k x
    /// \rVert_\infty$ over every $\chi$ whose rotation angles sum to at most `angle_sum_rad`
    /// ([`tt_kinematics::ScheduleErrorModel::angle_sum_bound`]) and every extra error
    /// $|x_e| \le$ `extra_bounds[e]` ([`crate::EndToEnd::extra_errors`]); `None` for the
    /// readings [`crate::EndToEnd::second_order_bound`] gives none for, or extra errors
    /// held away from zero. For a static schedule it is
    /// [`crate::EndToEnd::second_order_bound`].
    ///
    /// # Formula
    /// The static bound's derivation, entry by entry: at entry $i$ the inputs move by at most
    /// $d_{i,j}$ and leave a second-order remainder of at most $\rho_{i,j}$ (input $j$), about
    /// nominal inputs of size $m_{i,j}$. At a static position $m = (1, 1, 1, \omega_e,
    /// \omega_e, \omega_e)$, $d = s\,m$, $\rho = \tfrac12 s^2 e^s m$ (as
    /// [`crate::EndToEnd::second_order_bound`]); at a rate step $m_{i,j} = |u_{0,j}|$ (the
    /// nominal averages) and $d$, $\rho$ the change and remainder bounds of
    /// [`tt_kinematics::RateStepFrames::remainder_bound`] over the box
    /// ($s$; $L = \sum$ of the translations' bounds; $E$ the joint's rate-accuracy bound;
    /// $Q = \sqrt{T_c^2 + T_s^2}$ of its ripple parts' bounds), the same for each component.
    /// A term $\beta_t r_t$ leaves at most $|\beta_t|\big(\mathrm{rem}_t(m_i, d_i) +
    /// \sum_j|\partial_j r_t|(m_i)\,\rho_{i,j}\big)$
    /// ([`gw_model::Regressor::remainder_bound`]); the sums over the known and the estimated
    /// terms give the vectors $r_e$, $r_g$ over the entries, and the reading maps them as the
    /// static bound does with $\lVert\mathbf X\rVert_\infty r$ replaced by
    /// $\max_i\sum_l|X_{il}|\,r_l$ (e.g. actual outputs, printed:
    /// $\tau = \max_i \sum_l \big(|(\mathbf I-\mathbf P)_{il}|\,r_{g,l} +
    /// |\mathbf P_{il}|\,r_{e,l}\big)$).
    ///
    /// The first-order part at the rate steps is the linearisation's, whose input derivatives
    /// are central differences $D_h$ of step $h$ (`RATE_DERIVATIVE_STEP`). Their
    /// truncation is bounded by the same remainder: $u(\pm h\,e_j) = u_0 \pm h\,u'_j +
    /// R_j(\pm h)$ with $|R_j| \le \rho_j(h)$, the remainder over the box of error $j$ alone at
    /// size $h$, so $|D_h - u'_j| \le \rho_j(h)/h$; weighted by the box's bounds ($s$, $L$,
    /// $E$ and the ripple parts' sum) it is added to $\rho$ at each rate step, with an
    /// allowance for the rounding of the two evaluations of $2^{-40}$ of the inputs' size
    /// each.
    ///
    /// # Errors
    /// [`E2eError::Field`] naming a bad bound (as [`crate::EndToEnd::second_order_bound`];
    /// a ripple bound $Q \ge 1$) or a missing output.
    pub fn second_order_bound_with_extra(
        &self,
        output: usize,
        angle_sum_rad: f64,
        extra_bounds: &[f64],
    ) -> Result<Option<f64>, E2eError> {
        use calib_lsq::{ErrorForm, Estimate, OutputsAt};
        if !self.has_rate_steps() {
            return self.second_order_bound(output, angle_sum_rad);
        }
        check_extra_bounds(self, extra_bounds)?;
        let (s, cal) = self.bound_arguments(output, angle_sum_rad)?;
        let reading = self.reading();
        if reading.estimate != Estimate::Beta1
            || reading.form == ErrorForm::DeltaBeta
            || self.extra_values().iter().any(|v| *v != 0.0)
        {
            return Ok(None);
        }
        let plan = self.rate_plan();
        let table = self.turntable();
        let n_tr = table.n_translation_errors();
        let translation_sum: f64 = extra_bounds[..n_tr].iter().sum();
        let we = tt_core::units::rad_per_s_to_deg_per_h(
            self.calibration().site().earth_rate_rad_per_s(),
        );
        let sigma = 0.5 * s * s * s.exp();
        let static_m = [1.0, 1.0, 1.0, we, we, we];
        let identity = vec![Matrix3::identity(); table.n_rotation_errors()];
        let zeros = vec![0.0; extra_bounds.len()];
        let mut r_e = Vec::with_capacity(plan.entries.len());
        let mut r_g = Vec::with_capacity(plan.entries.len());
        for entry in &plan.entries {
            let (m, d, rho) = match entry {
                None => (
                    static_m,
                    static_m.map(|v| s * v),
                    static_m.map(|v| sigma * v),
                ),
                Some(e) => {
                    let k = e.rate_index;
                    let b = tt_kinematics::RateErrorBox {
                        angle_sum_rad: s,
                        translation_sum_m: translation_sum,
                        accuracy: extra_bounds[k],
                        ripple: extra_bounds[k + 1].hypot(extra_bounds[k + 2]),
                    };
                    let rem = e.frames.remainder_bound(&b, &e.env)?;
                    let u0 = plan.inputs(e, &identity, &zeros, n_tr)?;
                    let to_dph = tt_core::units::rad_per_s_to_deg_per_h;
                    let (df, dw) = (
                        rem.specific_force_change_g,
                        to_dph(rem.rate_change_rad_per_s),
                    );
                    // The first-order part at a rate step is the linearisation's central
                    // difference D_h of step h: u(+-h e_j) = u0 +- h u'_j + R_j(+-h) with
                    // |R_j| <= rho_j(h), the remainder over the box of error j alone at size h,
                    // so |D_h - u'_j| <= rho_j(h)/h. Weighted by the errors' bounds (the box's
                    // sums) this joins the remainder, with a rounding allowance of the two
                    // evaluations (FD_ROUNDING_REL of the inputs' size each).
                    let h = crate::simulate::RATE_DERIVATIVE_STEP;
                    let ripple_sum = extra_bounds[k + 1] + extra_bounds[k + 2];
                    let alone = |i: usize| tt_kinematics::RateErrorBox {
                        angle_sum_rad: if i == 0 { h } else { 0.0 },
                        translation_sum_m: if i == 1 { h } else { 0.0 },
                        accuracy: if i == 2 { h } else { 0.0 },
                        ripple: if i == 3 { h } else { 0.0 },
                    };
                    let weights = [s, translation_sum, extra_bounds[k], ripple_sum];
                    let (mut fd_f, mut fd_w) = (0.0, 0.0);
                    for (i, w) in weights.iter().enumerate() {
                        if *w > 0.0 {
                            let r = e.frames.remainder_bound(&alone(i), &e.env)?;
                            fd_f += w * r.specific_force_g / h;
                            fd_w += w * r.rate_rad_per_s / h;
                        }
                    }
                    let size = crate::simulate::max_abs;
                    let round = weights.iter().sum::<f64>() * FD_ROUNDING_REL / h;
                    let (rf, rw) = (
                        rem.specific_force_g + fd_f + round * size(&u0.0[..3]),
                        to_dph(rem.rate_rad_per_s + fd_w) + round * size(&u0.0[3..]),
                    );
                    (
                        u0.0.map(f64::abs),
                        [df, df, df, dw, dw, dw],
                        [rf, rf, rf, rw, rw, rw],
                    )
                }
            };
            r_e.push(terms_remainder(cal.output(), true, &m, &d, &rho));
            r_g.push(terms_remainder(cal.output(), false, &m, &d, &rho));
        }
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        let sum =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + y).collect() };
        let r_ge = sum(&r_g, &r_e);
        // |P| r and |I - P| r row by row (never the n x n projector P = A A^+)
        let reg = cal.regression();
        Ok(match (reading.outputs, reading.form) {
            (OutputsAt::Intended, ErrorForm::Printed) => Some(max(&r_e)),
            (OutputsAt::Intended, ErrorForm::NominalRate) => Some(0.0),
            (OutputsAt::Intended, ErrorForm::ActualRegressors) => Some(max(&r_ge)),
            (OutputsAt::Intended, ErrorForm::ActualRegressorsNominalRate) => Some(max(&r_g)),
            (OutputsAt::Actual, ErrorForm::Printed) => {
                let (p_re, ip_rg) = reg.projector_row_sums(&r_e, &r_g);
                Some(max(&sum(&ip_rg, &p_re)))
            }
            (OutputsAt::Actual, ErrorForm::NominalRate) => {
                Some(max(&reg.projector_row_sums(&r_ge, &r_ge).1))
            }
            _ => None,
        })
    }

    /// $\tau_k$ of every output for the box of angular bounds `ub_rad` (`+inf` held at 0)
    /// and extra-error bounds `extra_bounds`.
    fn rate_taus(&self, ub_rad: &[f64], extra_bounds: &[f64]) -> Result<Vec<f64>, E2eError> {
        let none = || E2eError::NoSecondOrderBound {
            reading: self.reading().to_string(),
        };
        let s = self.angle_sum(ub_rad)?.ok_or_else(none)?;
        (0..self.n_outputs())
            .map(|k| {
                self.second_order_bound_with_extra(k, s, extra_bounds)?
                    .ok_or_else(none)
            })
            .collect()
    }

    /// The certified direct allocation of the angular errors and the rate tolerances: the
    /// allocation of [`crate::RateQuestions::allocate_direct_rate`] whose first-order worst case
    /// over both boxes plus the derived second-order bound
    /// ([`crate::RateQuestions::second_order_bound_with_extra`]) is within every accuracy (less
    /// [`crate::CertifyParams::round_trip_rel`] of it), the certificate of
    /// [`crate::EndToEnd::allocate_direct_certified`] with the extra errors in the box.
    ///
    /// # Method
    /// Solve with each output's margin $\mu_k$ (from 0), compute $\tau_k$ of the box found;
    /// while the box is not certified, raise $\mu_k$ to $\tau_k$ plus the round-trip share
    /// (margins only grow; $\tau$ shrinks with the box) and solve again, at most
    /// 12 times. Every angle is held at [`ANGLE_TOLERANCE_CEILING_RAD`] and every relative
    /// rate tolerance at [`RATE_TOLERANCE_CEILING`]; when a margin would exceed its largest
    /// share, the angles' ceiling is lowered by bisection on its logarithm (down to six
    /// decades below) to the largest one whose box is certified, as the static certificate
    /// lowers its $\ell_1$ budget. The returned box is certified by the check, whatever the
    /// rounds.
    ///
    /// # Errors
    /// As [`crate::RateQuestions::allocate_direct_rate`]; [`E2eError::NoSecondOrderBound`] for a
    /// reading without a bound; [`E2eError::NoConvergence`] when a margin would exceed
    /// [`crate::CertifyParams::max_margin`] of the accuracy or the rounds run out.
    pub fn allocate_direct_rate_certified(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
    ) -> Result<RateAllocation, E2eError> {
        self.certified_rate_keeping(
            linear,
            extra_linear,
            lower_bounds_rad,
            &vec![0.0; self.n_outputs()],
            &crate::CertifyParams::default(),
        )
    }

    /// [`crate::RateQuestions::allocate_direct_rate_certified`] keeping `noise[k]` (output unit)
    /// of each accuracy free besides the second-order bound, its search tuned by `params`.
    fn certified_rate_keeping(
        &self,
        linear: &crate::Linearization,
        extra_linear: &crate::Linearization,
        lower_bounds_rad: &[f64],
        noise: &[f64],
        params: &crate::CertifyParams,
    ) -> Result<RateAllocation, E2eError> {
        if !self.has_rate_steps() {
            // no rate tolerance: the static certificate itself
            let d = self.certified_keeping(linear, lower_bounds_rad, noise, params)?;
            let n = self.len();
            let rows = linear.row_worst_cases(&d.upper_bounds_rad);
            let linear_bounds: Vec<f64> = (0..self.n_outputs())
                .map(|k| rows.rows(k * n, n).max())
                .collect();
            let taus = self.rate_taus(&d.upper_bounds_rad, &[])?;
            return Ok(RateAllocation {
                combined: d,
                tolerances: Vec::new(),
                weights: Vec::new(),
                worst_cases: Vec::new(),
                exact_rounds: 0,
                certificate: Some(RateCertificate {
                    linear_bounds,
                    second_order_bounds: taus,
                    rounds: 0,
                }),
            });
        }
        self.with_rate_setup(
            linear,
            extra_linear,
            lower_bounds_rad,
            |setup, combined, lb| {
                // the angles' ceiling: 1 deg, lowered by bisection (on its logarithm) while the
                // second-order bound of the box takes more than an accuracy's largest margin,
                // as the static certificate lowers its l1 budget
                let first = self.certified_rate_rounds(
                    setup,
                    combined,
                    lb,
                    ANGLE_TOLERANCE_CEILING_RAD,
                    noise,
                    params,
                );
                if !matches!(first, Err(E2eError::NoConvergence { .. })) {
                    return first;
                }
                let (mut lo, mut hi) = (
                    ANGLE_TOLERANCE_CEILING_RAD.ln() - CEILING_SEARCH_DECADES * 10f64.ln(),
                    ANGLE_TOLERANCE_CEILING_RAD.ln(),
                );
                let mut best = None;
                for _ in 0..CEILING_SEARCH_STEPS {
                    let mid = 0.5 * (lo + hi);
                    match self.certified_rate_rounds(setup, combined, lb, mid.exp(), noise, params)
                    {
                        Ok(a) => {
                            best = Some(a);
                            lo = mid;
                        }
                        Err(E2eError::NoConvergence { .. }) => hi = mid,
                        Err(e) => return Err(e),
                    }
                }
                match best {
                    Some(a) => Ok(a),
                    None => {
                        self.certified_rate_rounds(setup, combined, lb, lo.exp(), noise, params)
                    }
                }
            },
        )
    }

    /// The re-solves of [`crate::RateQuestions::allocate_direct_rate_certified`] with every angle
    /// held at `angle_ceiling_rad` (and the relative rate tolerances at
    /// [`RATE_TOLERANCE_CEILING`]), the round-trip share and the largest margin from `params`.
    fn certified_rate_rounds(
        &self,
        setup: &crate::allocate::DirectSetup<'_>,
        combined: &crate::Linearization,
        lb: &[f64],
        angle_ceiling_rad: f64,
        noise: &[f64],
        params: &crate::CertifyParams,
    ) -> Result<RateAllocation, E2eError> {
        {
            let acc = self.accuracies();
            let n = self.len();
            let n_angles = self.n_errors();
            let room = |k: usize| acc[k] * (1.0 - params.round_trip_rel) - noise[k];
            let mut margins = noise.to_vec();
            let ceilings: Vec<(usize, f64)> = self
                .rate_ceilings()
                .into_iter()
                .map(|(j, c)| {
                    (
                        j,
                        if j < n_angles {
                            angle_ceiling_rad.max(lb[j])
                        } else {
                            c
                        },
                    )
                })
                .collect();
            for round in 0..=RATE_CERTIFY_ROUNDS {
                let d = setup.capped(
                    setup.allocate(combined, lb, &margins, None)?,
                    &ceilings,
                    combined,
                );
                let extra = self.extra_bounds_of(&d.upper_bounds_rad[n_angles..]);
                let taus = self.rate_taus(&d.upper_bounds_rad[..n_angles], &extra)?;
                let rows = combined.row_worst_cases(&d.upper_bounds_rad);
                let linear_bounds: Vec<f64> =
                    (0..acc.len()).map(|k| rows.rows(k * n, n).max()).collect();
                if (0..acc.len()).all(|k| linear_bounds[k] + taus[k] <= room(k)) {
                    let mut combined_d = d;
                    combined_d.second_order_margins.clone_from(&margins);
                    return Ok(RateAllocation {
                        combined: combined_d,
                        tolerances: self.rate_tolerances(),
                        weights: setup.weights[n_angles..].to_vec(),
                        worst_cases: Vec::new(),
                        exact_rounds: 0,
                        certificate: Some(RateCertificate {
                            linear_bounds,
                            second_order_bounds: taus,
                            rounds: round,
                        }),
                    });
                }
                for k in 0..acc.len() {
                    let excess = linear_bounds[k] + taus[k] - room(k);
                    if excess > 0.0 {
                        let want = noise[k] + taus[k] + acc[k] * params.round_trip_rel;
                        margins[k] = if want > margins[k] {
                            want
                        } else {
                            margins[k] + excess
                        };
                        if margins[k] - noise[k] >= params.max_margin * (acc[k] - noise[k]) {
                            return Err(E2eError::NoConvergence {
                                what: "certified direct allocation with rate tolerances (the second-order bound takes more than the largest margin of an accuracy)",
                                iterations: round,
                                change: margins[k],
                            });
                        }
                    }
                }
            }
            Err(E2eError::NoConvergence {
                what: "certified direct allocation with rate tolerances (the box is not certified after keeping the second-order bound free)",
                iterations: RATE_CERTIFY_ROUNDS,
                change: margins.iter().fold(0.0, |a: f64, b| a.max(*b)),
            })
        }
    }
}
