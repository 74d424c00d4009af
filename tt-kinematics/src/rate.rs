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
        self.check_step(step)?;
        self.check_errors(errors)?;
        finite("accuracy", rate_errors.accuracy)?;
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

/// The box of errors a rate step's remainder is bounded over
/// ([`RateStepFrames::remainder_bound`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RateErrorBox {
    /// $s$: the rotation angles of the angular errors sum to at most this (rad).
    pub angle_sum_rad: f64,
    /// $L$: the translation errors' absolute values sum to at most this (m; each acts along a
    /// unit vector).
    pub translation_sum_m: f64,
    /// $E$: $|\varepsilon| \le E$ (relative).
    pub accuracy: f64,
    /// $Q$: $\rho = \sqrt{\rho_c^2+\rho_s^2} \le Q < 1$ (relative).
    pub ripple: f64,
}

/// A bound of a rate step's averaged inputs' second-order remainder and change over a
/// [`RateErrorBox`] ([`RateStepFrames::remainder_bound`]); Euclidean norms of the 3-vectors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RateRemainder {
    /// $|\langle\mathbf f\rangle - \mathbf f_0 - \mathrm d\mathbf f| \le$ this (g).
    pub specific_force_g: f64,
    /// $|\langle\boldsymbol\omega\rangle - \boldsymbol\omega_0 - \mathrm d\boldsymbol\omega|
    /// \le$ this (rad/s).
    pub rate_rad_per_s: f64,
    /// $|\langle\mathbf f\rangle - \mathbf f_0| \le$ this (g).
    pub specific_force_change_g: f64,
    /// $|\langle\boldsymbol\omega\rangle - \boldsymbol\omega_0| \le$ this (rad/s).
    pub rate_change_rad_per_s: f64,
}

/// One factor $\mathbf F = \mathbf F_0 + \mathbf L + \mathbf R$ of a multilinear term:
/// $(|\mathbf F_0|, |\mathbf L + \mathbf R|, |\mathbf R|)$ bounds.
type Factor3 = (f64, f64, f64);

/// The multilinear lemma of [`RateStepFrames::remainder_bound`]: for factors
/// $(a_k, b_k, c_k)$, the bound of the remainder
/// $\sum_k c_k\prod_{l\ne k}a_l + \sum_{|K|\ge 2}\prod_{k\in K}b_k\prod_{l\notin K}a_l$ and of
/// the change $\prod_k(a_k+b_k) - \prod_k a_k$ (every subset summed term by term: no
/// cancellation).
fn multilinear_remainder(f: &[Factor3]) -> (f64, f64) {
    let n = f.len();
    let (mut rem, mut change) = (0.0, 0.0);
    for mask in 1_u32..(1 << n) {
        let term: f64 = (0..n)
            .map(|k| if mask & (1 << k) != 0 { f[k].1 } else { f[k].0 })
            .product();
        change += term;
        if mask.count_ones() >= 2 {
            rem += term;
        }
    }
    for k in 0..n {
        rem += f[k].2 * (0..n).filter(|&l| l != k).map(|l| f[l].0).product::<f64>();
    }
    (rem, change)
}

impl RateStepFrames {
    /// A rigorous bound of the second-order remainder of the averaged inputs
    /// ([`RateStepFrames::average`]) over every error of the box `b` (expanded about zero
    /// errors), and of their change.
    ///
    /// # Formula
    /// Conjugating the nominal factors through, $\mathbf P = \mathbf P_0\,\Delta\mathbf P$
    /// and $\mathbf S = \mathbf S_0\,\Delta\mathbf S$, each $\Delta$ a product of rotations
    /// whose angles sum to at most $s$, so (as for the static bound)
    /// $\lVert\Delta - \mathbf I\rVert_2 \le s$ and
    /// $\lVert\Delta - \mathbf I - [\boldsymbol\delta]_\times\rVert_2 \le e^s - 1 - s \le
    /// \sigma = \tfrac12 s^2 e^s$. Every input of the [module](self)'s formula is a sum of
    /// multilinear terms $B(\mathbf F_1, \dots, \mathbf F_n)$ with
    /// $|B(\mathbf x_1,\dots)| \le \prod|\mathbf x_k|$, each factor
    /// $\mathbf F_k = \mathbf F_{k0} + \mathbf L_k + \mathbf R_k$ (nominal, linear part,
    /// remainder) with $|\mathbf F_{k0}| \le a_k$, $|\mathbf L_k + \mathbf R_k| \le b_k$,
    /// $|\mathbf R_k| \le c_k$. Expanding, the term's remainder is at most
    /// $$\sum_k c_k\prod_{l\ne k}a_l + \sum_{|K|\ge2}\ \prod_{k\in K}b_k\prod_{l\notin K}a_l,$$
    /// and its change at most $\prod_k(a_k+b_k) - \prod_k a_k$ (a factor occurring twice,
    /// $\Delta\mathbf S$ in $\mathbf S^T$ and in $\mathbf r$, is taken as two independent
    /// factors: the bound covers the correlated case). The factors:
    /// - $\Delta\mathbf S^T$, $\Delta\mathbf P^T$: $(1, s, \sigma)$;
    /// - $1+\varepsilon$: $(1, E, 0)$ (the centripetal term's $(1+\varepsilon)^2$ as two);
    /// - $\mathbf M = \hat u\hat u^T + \kappa(\rho_c(\mathbf I - \hat u\hat u^T) -
    ///   \rho_s[\hat u]_\times)$, whose bracket has norm $\rho$, linear part $-\tfrac12$ of it:
    ///   $(1, |\kappa|Q, Q(\tfrac12 - |\kappa|)) = (1, \frac{Q}{1+q},
    ///   \frac{Q^3}{2(1+q)^2})$, $q = \sqrt{1-Q^2}$ (both grow with $Q$);
    /// - $\langle\Omega^2\rangle/\langle\Omega\rangle^2 = 1/\sqrt{1-\rho^2}$, no linear part:
    ///   $(1, \phi, \phi)$, $\phi = 1/q - 1 = Q^2/(q(1+q))$;
    /// - $\mathbf r = \mathbf t + \mathbf S_0\Delta\mathbf S\,\mathbf l$ with
    ///   $\mathbf t = \sum_i \mathbf S_{0,i}\Delta\mathbf S_i\,\mathbf d_i t_i$ (the partial
    ///   products, again rotations of angle sum at most $s$):
    ///   $(|\mathbf l|,\ L + s|\mathbf l|,\ \sigma|\mathbf l| + sL)$.
    ///
    /// The terms (the fixed unit vectors and projections have norm at most 1):
    /// $\boldsymbol\omega$: $|\Omega_c|\,[\Delta\mathbf S^T, 1+\varepsilon]$ and
    /// $|\boldsymbol\omega_e|\,[\Delta\mathbf S^T, \mathbf M, \Delta\mathbf P^T]$;
    /// $\mathbf f$: $|\hat{\mathbf g}|\,[\Delta\mathbf S^T, \mathbf M, \Delta\mathbf P^T]$,
    /// centripetal $\frac{\Omega_c^2}{g_0}[\Delta\mathbf S^T, 1+\varepsilon, 1+\varepsilon,
    /// \phi, \mathbf r]$, Coriolis $\frac{2|\Omega_c||\boldsymbol\omega_e|}{g_0}
    /// [\Delta\mathbf S^T, 1+\varepsilon, \Delta\mathbf P^T, \mathbf r]$. The bounds are the
    /// sums over the terms.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] naming the bound unless every bound is finite and
    /// non-negative and $Q < 1$.
    pub fn remainder_bound(
        &self,
        b: &RateErrorBox,
        env: &RateEnvironment,
    ) -> Result<RateRemainder, KinematicsError> {
        for (name, v) in [
            ("angle_sum_rad", b.angle_sum_rad),
            ("translation_sum_m", b.translation_sum_m),
            ("accuracy", b.accuracy),
            ("ripple", b.ripple),
        ] {
            finite(name, v)?;
            if v < 0.0 {
                return Err(tt_core::FieldError::NotPositive {
                    field: name.into(),
                    value: v,
                }
                .into());
            }
        }
        if b.ripple >= 1.0 {
            return Err(tt_core::FieldError::OutOfRange {
                field: "ripple".into(),
                value: b.ripple,
                range: "[0, 1): a relative rate ripple".into(),
            }
            .into());
        }
        let s = b.angle_sum_rad;
        let sigma = 0.5 * s * s * s.exp();
        let rot = (1.0, s, sigma);
        let one_e = (1.0, b.accuracy, 0.0);
        let q = (1.0 - b.ripple * b.ripple).sqrt();
        let m = (
            1.0,
            b.ripple / (1.0 + q),
            b.ripple.powi(3) / (2.0 * (1.0 + q) * (1.0 + q)),
        );
        let phi = b.ripple * b.ripple / (q * (1.0 + q));
        let l = env.lever_arm_m.norm();
        let r = (
            l,
            b.translation_sum_m + s * l,
            sigma * l + s * b.translation_sum_m,
        );
        let omega = self.rate_rad_per_s.abs();
        let we = env.earth_rate_base_rad_per_s.norm();
        let g = env.specific_force_base_g.norm();
        let terms = |list: &[(f64, &[Factor3])]| -> (f64, f64) {
            list.iter().fold((0.0, 0.0), |(r0, c0), (coef, f)| {
                let (r1, c1) = multilinear_remainder(f);
                (r0 + coef * r1, c0 + coef * c1)
            })
        };
        let (rate_rem, rate_change) = terms(&[(omega, &[rot, one_e]), (we, &[rot, m, rot])]);
        let (f_rem, f_change) = terms(&[
            (g, &[rot, m, rot]),
            (
                omega * omega / STANDARD_GRAVITY_M_PER_S2,
                &[rot, one_e, one_e, (1.0, phi, phi), r],
            ),
            (
                2.0 * omega * we / STANDARD_GRAVITY_M_PER_S2,
                &[rot, one_e, rot, r],
            ),
        ]);
        Ok(RateRemainder {
            specific_force_g: f_rem,
            rate_rad_per_s: rate_rem,
            specific_force_change_g: f_change,
            rate_change_rad_per_s: rate_change,
        })
    }
}
