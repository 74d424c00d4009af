//! Shared tolerances and proptest strategies for the tt-kinematics tests.
#![allow(dead_code)]

use proptest::prelude::*;
use std::f64::consts::TAU;
use tt_kinematics::units::arcmin_to_rad;
use tt_kinematics::{CHI_LEN, Pose, TurntableErrors};

/// Largest error magnitude the properties are stated for: 10 arcmin (issue 2, P1), rad.
pub const MAX_ERROR_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0 / 60.0;

/// Second-order constant of the exact chain against eq 26, unitless (rad / rad^2).
///
/// $\Delta\mathbf R$ is a product of eight elementary error rotations $e^{[u_k]_\times}$ (after
/// the $\phi_1$ rotation cancels and $R_z(\phi_2)$ conjugation, which preserves norms), with
/// $|u_k| \le m = \max_i|\chi_i|$, and eq 26 is exactly $I + \sum_k [u_k]_\times$. Expanding the
/// product and bounding every term by its norm gives, entrywise,
/// $|\Delta R_{ij} - (I + \sum_k [u_k]_\times)_{ij}| \le e^{s} - 1 - s \le \tfrac{s^2}{2}e^{s}$
/// with $s = \sum_k |u_k| \le 8m$. For $m \le 10'$ ($s \le 0.0233$, $e^s \le 1.0236$) this is
/// $\le 32.76\,m^2$, hence $K = 33$.
pub const K_EXACT: f64 = 33.0;

/// Second-order constant of the printed small-angle chain (eq 17-19 as printed) against
/// eq 26, unitless. Its three error factors $I + [v]_\times$ have norms $\le \sqrt3 m$,
/// $\sqrt2 m$, $\sqrt3 m$; the product's non-linear part is bounded by
/// $ab + bc + ca + abc = (3 + 2\sqrt6) m^2 + O(m^3) \le 7.91\,m^2$ for $m \le 10'$, hence 8.
pub const K_SMALL_ANGLE: f64 = 8.0;

/// Rounding error allowed where two computations are equal in exact arithmetic (a few ulps
/// of the unit-size matrix entries accumulated over about ten 3x3 products), rad.
pub const ROUNDING_RAD: f64 = 1e-14;

/// Orthonormality and determinant tolerance of the exact $\Delta\mathbf R$ (issue 2, P4).
pub const ORTHONORMAL_TOL: f64 = 1e-12;

/// Central finite-difference step for the Jacobian check, rad. Truncation error
/// $\approx h^2/6 \cdot |f'''| \approx 2\times10^{-13}$ and rounding $\approx \epsilon/h
/// \approx 2\times10^{-10}$.
pub const FD_STEP_RAD: f64 = 1e-6;

/// Tolerance of the Jacobian against central finite differences (unitless), 50x the
/// rounding estimate above.
pub const FD_TOL: f64 = 1e-8;

/// Any angle of a full turn, rad.
pub fn angle() -> impl Strategy<Value = f64> {
    0.0..TAU
}

/// A pose anywhere in $[0, 2\pi)^2$.
pub fn pose() -> impl Strategy<Value = Pose> {
    (angle(), angle()).prop_map(|(a, b)| Pose {
        phi1_rad: a,
        phi2_rad: b,
    })
}

/// An error vector with every component in $[-m, m]$ for `m_rad`, and an intersection
/// error up to 1 mm.
pub fn errors_up_to(m_rad: f64) -> impl Strategy<Value = TurntableErrors> {
    (prop::array::uniform8(-m_rad..=m_rad), -1e-3..=1e-3_f64).prop_map(|(chi, deta)| {
        TurntableErrors::from_rad(chi, deta).expect("finite by construction")
    })
}

/// Errors up to 10 arcmin (the range of the properties).
pub fn errors() -> impl Strategy<Value = TurntableErrors> {
    errors_up_to(MAX_ERROR_RAD)
}

/// Table 4 of the paper (arcmin, order of eq 25) as an error vector, all positive.
pub fn table4() -> TurntableErrors {
    TurntableErrors::from_rad(
        [
            0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
        ]
        .map(arcmin_to_rad),
        0.0,
    )
    .expect("finite")
}

/// Number of components.
pub const N: usize = CHI_LEN;
