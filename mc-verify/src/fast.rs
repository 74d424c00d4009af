//! The fast exact evaluation of eq 23-24: quaternions of the small error rotations.
//!
//! # Formula
//! $\phi_1$ cancels exactly from eq 23 (tt-kinematics proves it), leaving
//! $$\Delta\mathbf R = \mathbf R_d^T\mathbf R_t = R_z(-\phi_2)\,\mathbf E_1\,R_z(\phi_2)\,\mathbf E_2,$$
//! $$\mathbf E_1 = R_y(\Delta\phi_{y1}) R_z(\Delta\alpha_{z1}) R_x(\Delta\alpha_{x1})
//!   R_y(\Delta\varepsilon_y) R_x(\Delta\varepsilon_x), \qquad
//!   \mathbf E_2 = R_y(\Delta\alpha_{y2}) R_z(\Delta\phi_{z2}) R_x(\Delta\alpha_{x2}).$$
//! Each elementary rotation $R_a(x)$ is the unit quaternion
//! $(\cos\tfrac x2, \sin\tfrac x2\,\hat e_a)$; right-multiplying a quaternion by it touches
//! all four components with 8 products (the quaternion analogue of "an elementary rotation
//! touches two columns", at half the cost of a 3x3 update). Conjugation by $R_z(\phi_2)$
//! keeps the scalar and $z$ parts and turns the $(x, y)$ part by $-\phi_2$. With
//! $q = (w, x, y, z)$ the quaternion of $\Delta\mathbf R$, the eq-24 read-out is
//! $$\Delta\psi = \Delta R_{13} = 2(xz + wy),\quad \Delta\theta = \Delta R_{21} = 2(xy + wz),\quad
//!   \Delta\gamma = \Delta R_{32} = 2(yz + wx).$$
//! About 70 multiplications in all, against about 300 for the ten dense 3x3 products of the
//! plain chain. $\sin\tfrac x2, \cos\tfrac x2$ of an error angle with $|x| \le$
//! [`SERIES_MAX_ABS_RAD`] are the Taylor series
//! $\sin\tfrac x2 = \tfrac x2 - \tfrac{x^3}{48} + \tfrac{x^5}{3840}$,
//! $\cos\tfrac x2 = 1 - \tfrac{x^2}{8} + \tfrac{x^4}{384}$, whose truncation errors
//! ($|x|^7/645120$ and $|x|^6/46080$) stay below $6\cdot10^{-18}$ there: exact to
//! rounding. Larger angles use `f64::sin_cos`.
//!
//! For the paper's case (all lower bounds zero, every bound within
//! [`SHORT_SERIES_MAX_ABS_RAD`]) the Monte Carlo kernel uses unnormalised quaternions
//! $(1, \tan\tfrac x2\,\hat e_a)$ instead: 4 products per factor and no cosine, with the
//! norm divided out once in the read-out (`short_tan_coefficients`).
//!
//! The result equals the plain chain ([`tt_kinematics::ExactChain`] with the eq-24 read-out)
//! to rounding; the tests check $10^{-15}$ rad per sample for errors up to 10 arcmin.
//!
//! # Reference
//! Paper eq 17-25; Table 3 (rotation order).

use tt_kinematics::{CHI_LEN, OrientationError, OrientationErrorModel, Pose, TurntableErrors};

/// Largest $|\chi_i|$ (rad, about 27.5 arcmin) for which the medium Taylor series
/// $\sin\tfrac x2 \approx \tfrac x2 - \tfrac{x^3}{48} + \tfrac{x^5}{3840}$,
/// $\cos\tfrac x2 \approx 1 - \tfrac{x^2}{8} + \tfrac{x^4}{384}$ are used; their truncation
/// errors ($|x|^7/645120$, $|x|^6/46080$) are then below $6\cdot10^{-18}$, far under one unit
/// in the last place of 1 ($2.2\cdot10^{-16}$). Larger angles use `f64::sin_cos`.
pub const SERIES_MAX_ABS_RAD: f64 = 8e-3;

/// Largest $|\chi_i|$ (rad, about 0.86 arcmin) for which the short series
/// $\sin\tfrac x2 \approx \tfrac x2 - \tfrac{x^3}{48}$, $\cos\tfrac x2 \approx 1 - \tfrac{x^2}{8}$
/// are used by a Monte Carlo run whose whole box lies inside it (Table 4 does: its largest
/// bound is 0.78 arcmin); truncation errors $|x|^5/3840$ and $|x|^4/384 \le 10^{-17}$.
pub const SHORT_SERIES_MAX_ABS_RAD: f64 = 2.5e-4;

/// Which evaluation of $(\sin\tfrac x2, \cos\tfrac x2)$ a block kernel uses (chosen once per
/// run from the largest bound of the box, so the kernel has no per-sample branch).
pub(crate) const TIER_SHORT: u8 = 0;
pub(crate) const TIER_MEDIUM: u8 = 1;
pub(crate) const TIER_ANY: u8 = 2;
/// The zero-lower-bound short tier (the paper's case: all $\mathrm{LB}_i = 0$, every bound
/// within [`SHORT_SERIES_MAX_ABS_RAD`]) evaluates the chain with *unnormalised* quaternions
/// $(1, \tau\,\hat e_a) = (\cos\tfrac x2)^{-1}(\cos\tfrac x2, \sin\tfrac x2\,\hat e_a)$,
/// $\tau = \tan\tfrac x2$: a right product by one costs 4 products instead of 8 and no
/// cosine is needed. Their product $\tilde q$ is $q$ times the positive factor
/// $\prod_i (\cos\tfrac{x_i}{2})^{-1}$, which the read-out removes exactly:
/// $\Delta\mathbf R_{13} = 2(\tilde x\tilde z + \tilde w\tilde y)/|\tilde q|^2$, and so on.
/// $\tau$ comes straight from the half-integer $t$ of the word ($\chi_i = t\,s_i$,
/// $s_i = \mathrm{UB}_i 2^{-31}$): $\tan\tfrac{\chi}{2} \approx t(\tfrac{s}{2} + t^2
/// \tfrac{s^3}{24})$, truncation $|\chi|^5/240 \le 4\cdot10^{-21}$ rad.
///
/// Coefficients per component: $(s/2, s^3/24)$.
pub(crate) fn short_tan_coefficients(scale_rad: &[f64; CHI_LEN]) -> [[f64; 2]; CHI_LEN] {
    scale_rad.map(|s| [0.5 * s, s * s * s / 24.0])
}

/// Block kernel of the zero-lower-bound short tier ([`short_tan_coefficients`]): `t[i]` is
/// the half-integer of the word of $\chi_i$.
#[inline(always)]
pub(crate) fn delta_from_t(
    s2: f64,
    c2: f64,
    t: [f64; CHI_LEN],
    k: &[[f64; 2]; CHI_LEN],
) -> [f64; 3] {
    let tau = std::array::from_fn(|i| t[i] * (k[i][0] + (t[i] * t[i]) * k[i][1]));
    delta_from_tan_half_angles(s2, c2, &tau)
}

/// The chain with unnormalised quaternions: `tau[i]` $= \tan\tfrac{\chi_i}{2}$ in the order
/// of eq 25; `(s2, c2) = (sin phi2, cos phi2)`. Returns `[dpsi, dtheta, dgamma]` (eq 24),
/// rad. Same factor order as [`delta_from_half_angles`].
#[inline(always)]
pub(crate) fn delta_from_tan_half_angles(s2: f64, c2: f64, tau: &[f64; CHI_LEN]) -> [f64; 3] {
    let [ta, tg, tc, tb, th, tf, te, td] = *tau;
    // E1 = Ry(a) Rz(b) Rx(c) Ry(d) Rx(e), each factor (1, tau e_axis)
    let (w, x, y, z) = (1.0, ta * tb, ta, tb);
    // * Rx(c)
    let (w, x, y, z) = (w - x * tc, w * tc + x, y + z * tc, z - y * tc);
    // * Ry(d)
    let (w, x, y, z) = (w - y * td, x - z * td, w * td + y, x * td + z);
    // * Rx(e)
    let (w, x, y, z) = (w - x * te, w * te + x, y + z * te, z - y * te);
    // conjugation Rz(-phi2) E1 Rz(phi2): vector part turned by -phi2 about z
    let (x, y) = (c2 * x + s2 * y, c2 * y - s2 * x);
    // * E2 = Ry(f) Rz(g) Rx(h)
    let (w, x, y, z) = (w - y * tf, x - z * tf, w * tf + y, x * tf + z);
    let (w, x, y, z) = (w - z * tg, x + y * tg, y - x * tg, w * tg + z);
    let (w, x, y, z) = (w - x * th, w * th + x, y + z * th, z - y * th);
    // read-out of the unit quaternion q~/|q~|
    let r = 2.0 / ((w * w + x * x) + (y * y + z * z));
    [
        r * (x * z + w * y),
        r * (x * y + w * z),
        r * (y * z + w * x),
    ]
}

/// The tier valid for every $|x| \le$ `max_abs_rad`.
pub(crate) fn tier_for(max_abs_rad: f64) -> u8 {
    if max_abs_rad <= SHORT_SERIES_MAX_ABS_RAD {
        TIER_SHORT
    } else if max_abs_rad <= SERIES_MAX_ABS_RAD {
        TIER_MEDIUM
    } else {
        TIER_ANY
    }
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ by the short series; valid for $|x| \le$
/// [`SHORT_SERIES_MAX_ABS_RAD`].
#[inline(always)]
fn half_sin_cos_short(x: f64) -> (f64, f64) {
    let x2 = x * x;
    (x * (0.5 - x2 * (1.0 / 48.0)), 1.0 - x2 * 0.125)
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ by the medium series; valid for $|x| \le$ [`SERIES_MAX_ABS_RAD`].
#[inline(always)]
fn half_sin_cos_series(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let s = x * (0.5 + x2 * (-1.0 / 48.0 + x2 * (1.0 / 3840.0)));
    let c = 1.0 + x2 * (-0.125 + x2 * (1.0 / 384.0));
    (s, c)
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ for any finite $x$.
#[inline(always)]
fn half_sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= SERIES_MAX_ABS_RAD {
        half_sin_cos_series(x)
    } else {
        (0.5 * x).sin_cos()
    }
}

/// The quaternion chain. `h[i] = (sin chi_i/2, cos chi_i/2)` in the order of eq 25;
/// `(s2, c2) = (sin phi2, cos phi2)`. Returns `[dpsi, dtheta, dgamma]` (eq 24), rad.
#[inline(always)]
pub(crate) fn delta_from_half_angles(s2: f64, c2: f64, h: &[(f64, f64); CHI_LEN]) -> [f64; 3] {
    let (sa, ca) = h[0]; // Ry(dphi_y1)
    let (sg, cg) = h[1]; // Rz(dphi_z2)
    let (sc, cc) = h[2]; // Rx(dalpha_x1)
    let (sb, cb) = h[3]; // Rz(dalpha_z1)
    let (sh, ch) = h[4]; // Rx(dalpha_x2)
    let (sf, cf) = h[5]; // Ry(dalpha_y2)
    let (se, ce) = h[6]; // Rx(deps_x)
    let (sd, cd) = h[7]; // Ry(deps_y)

    // E1 = Ry(a) Rz(b) Rx(c) Ry(d) Rx(e)
    let (w, x, y, z) = (ca * cb, sa * sb, sa * cb, ca * sb);
    // * Rx(c)
    let (w, x, y, z) = (
        w * cc - x * sc,
        w * sc + x * cc,
        y * cc + z * sc,
        z * cc - y * sc,
    );
    // * Ry(d)
    let (w, x, y, z) = (
        w * cd - y * sd,
        x * cd - z * sd,
        w * sd + y * cd,
        x * sd + z * cd,
    );
    // * Rx(e)
    let (w1, x, y, z1) = (
        w * ce - x * se,
        w * se + x * ce,
        y * ce + z * se,
        z * ce - y * se,
    );
    // conjugation Rz(-phi2) E1 Rz(phi2): vector part turned by -phi2 about z
    let (x1, y1) = (c2 * x + s2 * y, c2 * y - s2 * x);

    // * E2 = Ry(f) Rz(g) Rx(h), one factor at a time
    let (w, x, y, z) = (w1, x1, y1, z1);
    // * Ry(f)
    let (w, x, y, z) = (
        w * cf - y * sf,
        x * cf - z * sf,
        w * sf + y * cf,
        x * sf + z * cf,
    );
    // * Rz(g)
    let (w, x, y, z) = (
        w * cg - z * sg,
        x * cg + y * sg,
        y * cg - x * sg,
        w * sg + z * cg,
    );
    // * Rx(h)
    let (w, x, y, z) = (
        w * ch - x * sh,
        w * sh + x * ch,
        y * ch + z * sh,
        z * ch - y * sh,
    );

    [
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        2.0 * (y * z + w * x),
    ]
}

/// The eq-24 angles `[dpsi, dtheta, dgamma]` (rad) of the exact chain at inner-axis angle
/// `phi2_rad` for errors `chi_rad` (order of eq 25), by the fast quaternion evaluation.
///
/// # Formula
/// See the [module documentation](self).
///
/// # Reference
/// Paper eq 17-25.
#[must_use]
pub fn fast_delta_rad(phi2_rad: f64, chi_rad: &[f64; CHI_LEN]) -> [f64; 3] {
    let (s2, c2) = phi2_rad.sin_cos();
    delta_from_half_angles(s2, c2, &chi_rad.map(half_sin_cos))
}

/// Block kernel: every `chi[i]` must lie inside the range of tier `TIER` (guaranteed by the
/// caller from the error box).
#[inline(always)]
pub(crate) fn delta_block_sample<const TIER: u8>(
    s2: f64,
    c2: f64,
    chi: [f64; CHI_LEN],
) -> [f64; 3] {
    let h = match TIER {
        TIER_SHORT => chi.map(half_sin_cos_short),
        TIER_MEDIUM => chi.map(half_sin_cos_series),
        _ => chi.map(half_sin_cos),
    };
    delta_from_half_angles(s2, c2, &h)
}

/// Entries of the pose table: $(\sin, \cos)$ of $2\pi j / 256$.
const TURN_TABLE_LEN: usize = 256;

/// $(\sin, \cos)$ of $2\pi j / 256$, $j = 0 \dots 255$, from `f64::sin_cos`.
pub(crate) fn turn_table() -> &'static [(f64, f64); TURN_TABLE_LEN] {
    static TABLE: std::sync::OnceLock<[(f64, f64); TURN_TABLE_LEN]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|j| {
            (std::f64::consts::TAU * j as f64 / TURN_TABLE_LEN as f64).sin_cos()
        })
    })
}

/// [`sin_cos_turn`] with the table passed in (the hot loop fetches it once per block).
#[inline(always)]
pub(crate) fn sin_cos_turn_with(table: &[(f64, f64); TURN_TABLE_LEN], w: u32) -> (f64, f64) {
    // nearest table angle 2 pi j / 256 (top 8 bits, rounded), remainder |d| <= pi / 256
    let j = (w.wrapping_add(1 << 23) >> 24) as usize;
    let r = w.wrapping_sub((j as u32) << 24) as i32;
    let d = f64::from(r) * crate::sampler::RAD_PER_TURN_WORD;
    let d2 = d * d;
    let sd = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))));
    let cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)));
    let (sj, cj) = table[j & (TURN_TABLE_LEN - 1)];
    (sj * cd + cj * sd, cj * cd - sj * sd)
}

/// $(\sin\phi, \cos\phi)$ of the pose angle $\phi = 2\pi\,w\,2^{-32}$, from the integer `w`.
///
/// The nearest of 256 table angles $2\pi j/256$ is taken from the top bits of `w`, exactly;
/// the remainder $|\delta| \le \pi/256$ is formed with one rounding; $\sin\delta, \cos\delta$
/// are Taylor polynomials of degree 7 and 6 (truncation below $10^{-19}$); the angle-sum
/// formula combines them with the table's `f64::sin_cos` values. Agrees with
/// `f64::sin_cos(phi)` to a few $10^{-16}$ (tested) at a fraction of its cost.
#[must_use]
pub fn sin_cos_turn(w: u32) -> (f64, f64) {
    sin_cos_turn_with(turn_table(), w)
}

/// The exact chain with the eq-24 read-out, evaluated by [`fast_delta_rad`]: a drop-in
/// [`OrientationErrorModel`] equal to [`tt_kinematics::ExactChain::default()`] to rounding
/// (the intersection error $\Delta\eta$ has no effect on the orientation).
///
/// # Formula
/// See the [module documentation](self).
///
/// # Reference
/// Paper eq 17-25.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FastChain;

impl OrientationErrorModel for FastChain {
    fn orientation_error(&self, pose: &Pose, errors: &TurntableErrors) -> OrientationError {
        OrientationError::from_array(fast_delta_rad(pose.phi2_rad, &errors.chi_rad()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use tt_kinematics::ExactChain;

    /// Fast paths against the plain chain, rad (the per-sample bound).
    const FAST_VS_PLAIN_ABS_RAD: f64 = 1e-15;

    proptest! {
        /// The unnormalised-quaternion kernel of the zero-lower-bound short tier, from the
        /// words' half-integers, equals the plain chain (eq 17-24) within 1e-15 rad for any
        /// box inside the short range and any word.
        #[test]
        fn tangent_kernel_from_words_equals_plain_chain(
            ub in proptest::array::uniform8(0.0..=SHORT_SERIES_MAX_ABS_RAD),
            words in proptest::array::uniform8(any::<u32>()),
            phi2 in 0.0..std::f64::consts::TAU,
        ) {
            let scale = ub.map(|u| u / 2_147_483_648.0);
            let t = words.map(|w| f64::from(w as i32) + 0.5);
            let chi: [f64; CHI_LEN] = std::array::from_fn(|i| t[i] * scale[i]);
            let (s2, c2) = phi2.sin_cos();
            let fast = delta_from_t(s2, c2, t, &short_tan_coefficients(&scale));
            let pose = Pose::new(0.0, phi2).unwrap();
            let errors = TurntableErrors::from_rad(chi, 0.0).unwrap();
            let plain = ExactChain::default().orientation_error(&pose, &errors).to_array();
            for k in 0..3 {
                prop_assert!((fast[k] - plain[k]).abs() <= FAST_VS_PLAIN_ABS_RAD,
                    "axis {k}: fast {} plain {}", fast[k], plain[k]);
            }
        }
    }
}
