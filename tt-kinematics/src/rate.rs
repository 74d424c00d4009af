//! Rate steps: one joint turns at a constant commanded rate for a whole number of revolutions,
//! the other joints held at given angles, and the inputs a sensor on the platform feels,
//! averaged over those revolutions (the rate-transfer tests of IEEE Std 952 / 1431).
//!
//! # Formula
//! Split the actual chain at the turning joint $j$ (axis $\hat u$, signed as described,
//! angle $\theta$): $\mathbf T_t = \mathbf T_P\,\mathbf T_{\hat u}(\theta)\,\mathbf T_S$, where
//! $\mathbf T_P$ holds every factor before the joint and $\mathbf T_S$ every factor after it
//! (the other joints at their angles, every error rotation $\chi$ and translation as given),
//! $\mathbf P$ and $\mathbf S$ their rotations. In the frame $J$ just after the joint (which
//! turns with it) the sensor's origin, a lever arm $\mathbf l$ (platform frame) from the
//! platform's origin, sits at $\mathbf r = \mathbf T_S(\mathbf l, 1)$, a point the axis
//! through $J$'s origin carries round: the description's translation errors after the joint
//! (a non-intersection of axes) and the lever arm set the radius
//! $\mathbf r_\perp = \mathbf r - \hat u\hat u^T\mathbf r$.
//!
//! The table turns at $\Omega(\theta) = \bar\Omega\,(1 + \rho_c\cos\theta + \rho_s\sin\theta)$:
//! its rate averaged over whole revolutions (in time, as a lab's counter measures it) is
//! $\langle\Omega\rangle = \Omega_c(1+\varepsilon)$ ($\Omega_c$ commanded, $\varepsilon$ the rate
//! accuracy error), and $(\rho_c, \rho_s)$ is the rate ripple over the revolution (first
//! harmonic of the shaft angle, $\rho = \sqrt{\rho_c^2+\rho_s^2} < 1$). A time average over
//! whole revolutions weighs each angle by $\mathrm d t = \mathrm d\theta/\Omega(\theta)$, so
//! with $\kappa = -1/(1+\sqrt{1-\rho^2})$
//! $$\langle\cos\theta\rangle = \kappa\rho_c,\quad \langle\sin\theta\rangle = \kappa\rho_s,\quad
//! \langle\Omega^2\rangle = \frac{\langle\Omega\rangle^2}{\sqrt{1-\rho^2}},$$
//! and $\mathbf M = \langle\mathbf R_{\hat u}(\theta)^T\rangle = \hat u\hat u^T +
//! \langle\cos\theta\rangle(\mathbf I - \hat u\hat u^T) - \langle\sin\theta\rangle[\hat u]_\times$
//! (exact: $\int_0^{2\pi}\cos x/(1+\rho\cos x)\,\mathrm dx = \tfrac{2\pi}{\rho}(1 -
//! 1/\sqrt{1-\rho^2})$). In the sensor frame, with $\boldsymbol\omega_e$ the earth's rate and
//! $\hat{\mathbf g}$ the reaction to gravity (1 g up) in the base frame, $g_0$ standard gravity:
//! $$\langle\boldsymbol\omega\rangle = \mathbf S^T\big(\langle\Omega\rangle\hat u +
//!   \mathbf M\mathbf P^T\boldsymbol\omega_e\big),$$
//! $$\langle\mathbf f\rangle = \mathbf S^T\Big(\mathbf M\mathbf P^T\hat{\mathbf g} +
//!   \tfrac{1}{g_0}\big(-\langle\Omega^2\rangle\,\mathbf r_\perp + 2\langle\Omega\rangle\,
//!   (\hat u\hat u^T\mathbf P^T\boldsymbol\omega_e)\times(\hat u\times\mathbf r)\big)\Big).$$
//!
//! # What averages out, what stays
//! - The gyro sees the commanded rate about the joint's **actual** axis $\mathbf S^T\hat u$
//!   (tilted by every error after the joint) scaled by the rate accuracy, plus the earth's rate
//!   projected on the actual axis: the components of the earth's rate and of gravity
//!   perpendicular to the turning axis average out over whole revolutions, up to the ripple's
//!   weighting ($\kappa\rho$, about $\rho/2$ of the perpendicular component: a ripple of
//!   $10^{-3}$ leaves 0.5 mg of a horizontal 1 g).
//! - The accelerometers see the gravity component along the actual axis, the centripetal
//!   acceleration $-\langle\Omega^2\rangle\mathbf r_\perp$ of the sensor's offset from the
//!   axis (constant in the sensor frame), and the Coriolis acceleration of the sensor's
//!   velocity in the earth's frame, whose average is the along-axis earth rate times the
//!   circular velocity (a few micro-g at 1 rev/s and 5 cm; the perpendicular part averages
//!   out).
//! - The tangential acceleration $\dot\Omega\,\hat u\times\mathbf r$ of the ripple averages to
//!   exactly zero over whole revolutions (the rate returns to its value); the earth's
//!   centripetal acceleration at the offset ($\omega_e^2 r \approx 3\cdot10^{-10}$ g at 5 cm) is
//!   neglected (it belongs to the local gravity).
//! - Errors are constant over the revolution (a wobble that varies with the turning shaft's
//!   angle is not modelled at a rate step).

use crate::error::{KinematicsError, finite};
use crate::pose::TurntableErrors;
use crate::rotation::{homogeneous, skew, translation};
use crate::turntable::{Factor, Turntable};
use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};
use tt_core::Pose;

/// Standard gravity $g_0$ (m/s$^2$ per g; ISO 80000-3): converts the centripetal and Coriolis
/// accelerations to the accelerometers' g.
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.806_65;

/// One rate step of a schedule: joint `joint` turns at `rate_rad_per_s` (signed: about the
/// joint's axis as described, or against it) for `revolutions` whole revolutions, the other
/// joints at the angles of `pose` (the turning joint's entry is where it starts, which whole
/// revolutions average away).
#[derive(Debug, Clone, PartialEq)]
pub struct RateStep {
    /// Index of the turning joint (pose order).
    pub joint: usize,
    /// Commanded rate, rad/s (non-zero).
    pub rate_rad_per_s: f64,
    /// The angles of every joint (rad).
    pub pose: Pose,
    /// Whole revolutions (at least one).
    pub revolutions: u32,
}

impl RateStep {
    /// The time the step takes at the commanded rate (s): $2\pi N/|\Omega_c|$.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        std::f64::consts::TAU * f64::from(self.revolutions) / self.rate_rad_per_s.abs()
    }
}

/// The turning joint's rate errors at a rate step (dimensionless, relative to the commanded
/// rate).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RateErrorValues {
    /// Rate accuracy error $\varepsilon$: the rate averaged over whole revolutions is
    /// $\Omega_c(1+\varepsilon)$.
    pub accuracy: f64,
    /// Rate ripple $(\rho_c, \rho_s)$: the rate over the revolution is
    /// $\bar\Omega(1 + \rho_c\cos\theta + \rho_s\sin\theta)$; $\sqrt{\rho_c^2+\rho_s^2} < 1$.
    pub ripple: [f64; 2],
}

/// What the site and the mounting give a rate step: the base-frame vectors and the sensor's
/// lever arm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateEnvironment {
    /// Reaction to gravity in the base frame, g ($(0, 0, 1)$ for north-west-up).
    pub specific_force_base_g: Vector3<f64>,
    /// Earth's rate in the base frame, rad/s.
    pub earth_rate_base_rad_per_s: Vector3<f64>,
    /// The sensor's origin in the platform frame (m): its mounting lever arm.
    pub lever_arm_m: Vector3<f64>,
}

/// The sensor-frame inputs averaged over a rate step's whole revolutions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateAverage {
    /// Specific force, g.
    pub specific_force_g: Vector3<f64>,
    /// Angular rate, rad/s.
    pub rate_rad_per_s: Vector3<f64>,
}

/// The time averages of $\cos\theta$, $\sin\theta$ and the factor
/// $\langle\Omega^2\rangle/\langle\Omega\rangle^2$ under a ripple $(\rho_c, \rho_s)$ (see the
/// [module](self)).
///
/// # Errors
/// [`KinematicsError::Field`] naming `ripple` unless finite with $\rho < 1$.
pub fn ripple_averages(ripple: [f64; 2]) -> Result<(f64, f64, f64), KinematicsError> {
    finite("ripple", ripple[0])?;
    finite("ripple", ripple[1])?;
    let rho2 = ripple[0] * ripple[0] + ripple[1] * ripple[1];
    if rho2 >= 1.0 {
        return Err(tt_core::FieldError::OutOfRange {
            field: "ripple".into(),
            value: rho2.sqrt(),
            range: "[0, 1): a relative rate ripple".into(),
        }
        .into());
    }
    let root = (1.0 - rho2).sqrt();
    let kappa = -1.0 / (1.0 + root);
    Ok((kappa * ripple[0], kappa * ripple[1], 1.0 / root))
}

/// One step of a [`RateStepFrames`] chain.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    /// A product of nominal rotations (joints at the step's angles, fixed rotations).
    Nominal(Matrix3<f64>),
    /// The rotation of angular error `chi` ([`Turntable::error_rotations`]).
    Error(usize),
    /// The translation error `index` along a unit vector.
    Translate(usize, Vector3<f64>),
}

/// A rate step compiled for many turntables (the pose-dependent products once, as
/// [`crate::PoseFrames`] for static positions): [`RateStepFrames::average`] equals
/// [`Turntable::rate_step_average`] to rounding.
#[derive(Debug, Clone, PartialEq)]
pub struct RateStepFrames {
    before: Vec<Op>,
    after: Vec<Op>,
    axis: Vector3<f64>,
    rate_rad_per_s: f64,
}

fn push_nominal(ops: &mut Vec<Op>, m: Matrix3<f64>) {
    if let Some(Op::Nominal(last)) = ops.last_mut() {
        *last *= m;
    } else {
        ops.push(Op::Nominal(m));
    }
}

impl RateStepFrames {
    /// The averaged inputs for the rotations of every angular error `rotations`
    /// ([`Turntable::error_rotations`]), the translations (m), the rate errors and `env`.
    ///
    /// # Errors
    /// As [`ripple_averages`]; [`KinematicsError::Field`] naming `accuracy` when not finite.
    pub fn average(
        &self,
        rotations: &[Matrix3<f64>],
        translations_m: &[f64],
        rate_errors: &RateErrorValues,
        env: &RateEnvironment,
    ) -> Result<RateAverage, KinematicsError> {
        finite("accuracy", rate_errors.accuracy)?;
        let ripple = ripple_averages(rate_errors.ripple)?;
        let mut p = Matrix3::identity();
        for op in &self.before {
            match *op {
                Op::Nominal(m) => p *= m,
                Op::Error(e) => p *= rotations[e],
                Op::Translate(..) => {}
            }
        }
        let (mut s, mut t) = (Matrix3::identity(), Vector3::zeros());
        for op in &self.after {
            match *op {
                Op::Nominal(m) => s *= m,
                Op::Error(e) => s *= rotations[e],
                Op::Translate(i, d) => t += s * (d * translations_m[i]),
            }
        }
        let r = t + s * env.lever_arm_m;
        Ok(average(
            &p,
            &s,
            &r,
            &self.axis,
            self.rate_rad_per_s * (1.0 + rate_errors.accuracy),
            ripple,
            env,
        ))
    }
}

/// The formula of the [module](self) from the split chain.
fn average(
    p: &Matrix3<f64>,
    s: &Matrix3<f64>,
    r: &Vector3<f64>,
    u: &Vector3<f64>,
    omega: f64,
    (cos_avg, sin_avg, omega2_factor): (f64, f64, f64),
    env: &RateEnvironment,
) -> RateAverage {
    let uu = u * u.transpose();
    let m = uu + (Matrix3::identity() - uu) * cos_avg - skew(u) * sin_avg;
    let we = p.tr_mul(&env.earth_rate_base_rad_per_s);
    let rate = s.tr_mul(&(u * omega + m * we));
    let r_perp = r - u * u.dot(r);
    let centripetal = -(omega * omega * omega2_factor) * r_perp;
    let coriolis = 2.0 * omega * (uu * we).cross(&u.cross(r));
    let f = m * p.tr_mul(&env.specific_force_base_g)
        + (centripetal + coriolis) / STANDARD_GRAVITY_M_PER_S2;
    RateAverage {
        specific_force_g: s.tr_mul(&f),
        rate_rad_per_s: rate,
    }
}

impl Turntable {
    /// The rotation of every angular error into `out` (order of $\chi$), for
    /// [`RateStepFrames::average`].
    ///
    /// # Errors
    /// [`KinematicsError::Field`] for a $\chi$ or an `out` of the wrong length.
    pub fn error_rotations(
        &self,
        chi: &[f64],
        out: &mut [Matrix3<f64>],
    ) -> Result<(), KinematicsError> {
        crate::error::length("chi", self.n_rotation_errors(), chi.len())?;
        crate::error::length("error rotations", self.n_rotation_errors(), out.len())?;
        for ((e, o), x) in self.rotation_errors().iter().zip(out.iter_mut()).zip(chi) {
            *o = crate::rotation::rot_signed(e.axis, *x);
        }
        Ok(())
    }

    /// A rate step compiled for [`RateStepFrames::average`].
    ///
    /// # Errors
    /// As [`Turntable::rate_step_average`] for the step itself.
    pub fn rate_step_frames(&self, step: &RateStep) -> Result<RateStepFrames, KinematicsError> {
        self.check_step(step)?;
        let at = self.joints()[step.joint].factor;
        let pose = step.pose.angles_rad();
        let mut before = Vec::new();
        let mut after = Vec::new();
        for (k, f) in self.factors().iter().enumerate() {
            if k == at {
                continue;
            }
            let ops = if k < at { &mut before } else { &mut after };
            match *f {
                Factor::Rotation { error, .. } => ops.push(Op::Error(error)),
                Factor::Translation { error, along } => {
                    ops.push(Op::Translate(error, along.unit()));
                }
                _ => push_nominal(ops, self.factor_rotation(f, pose, None)),
            }
        }
        Ok(RateStepFrames {
            before,
            after,
            axis: self.joints()[step.joint].about.unit(),
            rate_rad_per_s: step.rate_rad_per_s,
        })
    }

    fn check_step(&self, step: &RateStep) -> Result<(), KinematicsError> {
        self.check_pose(&step.pose)?;
        if step.joint >= self.n_joints() {
            return Err(tt_core::FieldError::OutOfRange {
                field: "joint".into(),
                value: step.joint as f64,
                range: format!("a joint of the turntable (0..{})", self.n_joints()),
            }
            .into());
        }
        finite("rate_rad_per_s", step.rate_rad_per_s)?;
        if step.rate_rad_per_s == 0.0 {
            return Err(tt_core::FieldError::OutOfRange {
                field: "rate_rad_per_s".into(),
                value: 0.0,
                range: "non-zero".into(),
            }
            .into());
        }
        Ok(())
    }

    /// The inputs averaged over the whole revolutions of a rate step, through the exact chain
    /// with `errors` (angular errors and translations), the turning joint's rate errors and
    /// the site and mounting of `env` (formula in the [module](self)).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] for a joint index out of range, a pose or errors of the wrong
    /// length, a zero or non-finite rate, or a ripple of 1 or more.
    pub fn rate_step_average(
        &self,
        step: &RateStep,
        errors: &TurntableErrors,
        rate_errors: &RateErrorValues,
        env: &RateEnvironment,
    ) -> Result<RateAverage, KinematicsError> {
        self.check_pose(&step.pose)?;
        self.check_errors(errors)?;
        if step.joint >= self.n_joints() {
            return Err(tt_core::FieldError::OutOfRange {
                field: "joint".into(),
                value: step.joint as f64,
                range: format!("a joint of the turntable (0..{})", self.n_joints()),
            }
            .into());
        }
        finite("rate_rad_per_s", step.rate_rad_per_s)?;
        finite("accuracy", rate_errors.accuracy)?;
        if step.rate_rad_per_s == 0.0 {
            return Err(tt_core::FieldError::OutOfRange {
                field: "rate_rad_per_s".into(),
                value: 0.0,
                range: "non-zero".into(),
            }
            .into());
        }
        let (cos_avg, sin_avg, omega2_factor) = ripple_averages(rate_errors.ripple)?;
        let (p, s, t_s, u) = self.split_at_joint(step.joint, step.pose.angles_rad(), errors);
        let omega = step.rate_rad_per_s * (1.0 + rate_errors.accuracy);
        let uu = u * u.transpose();
        let m = uu + (Matrix3::identity() - uu) * cos_avg - skew(&u) * sin_avg;
        let we = p.tr_mul(&env.earth_rate_base_rad_per_s);
        let rate = s.tr_mul(&(u * omega + m * we));
        let r = (t_s * Vector4::new(env.lever_arm_m.x, env.lever_arm_m.y, env.lever_arm_m.z, 1.0))
            .xyz();
        let r_perp = r - u * u.dot(&r);
        let centripetal = -(omega * omega * omega2_factor) * r_perp;
        let coriolis = 2.0 * omega * (uu * we).cross(&u.cross(&r));
        let f = m * p.tr_mul(&env.specific_force_base_g)
            + (centripetal + coriolis) / STANDARD_GRAVITY_M_PER_S2;
        Ok(RateAverage {
            specific_force_g: s.tr_mul(&f),
            rate_rad_per_s: rate,
        })
    }

    /// $(\mathbf P, \mathbf S, \mathbf T_S, \hat u)$ of the chain split at joint `joint` (see
    /// the [module](self)), for checked inputs.
    fn split_at_joint(
        &self,
        joint: usize,
        pose: &[f64],
        errors: &TurntableErrors,
    ) -> (Matrix3<f64>, Matrix3<f64>, Matrix4<f64>, Vector3<f64>) {
        let at = self.joints()[joint].factor;
        let (chi, tr) = (errors.chi_rad(), errors.translations_m());
        let factors = self.factors();
        let p = factors[..at].iter().fold(Matrix3::identity(), |m, f| {
            m * self.factor_rotation(f, pose, Some(chi))
        });
        let t_s = factors[at + 1..]
            .iter()
            .fold(Matrix4::identity(), |m, f| match *f {
                Factor::Translation { error, along } => {
                    m * translation(&(along.unit() * tr[error]))
                }
                _ => m * homogeneous(&self.factor_rotation(f, pose, Some(chi))),
            });
        let s = t_s.fixed_view::<3, 3>(0, 0).into_owned();
        let u = self.joints()[joint].about.unit();
        (p, s, t_s, u)
    }
}
