//! Shared tolerances, tables and proptest strategies for the tt-kinematics tests.
#![allow(dead_code)]

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use tt_core::units::arcmin_to_rad;
use tt_kinematics::{Pose, Turntable, TurntableErrors, paper};

/// Largest error magnitude the properties are stated for: 10 arcmin (issue 2, P1), rad.
pub(crate) const MAX_ERROR_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0 / 60.0;

/// Second-order constant of the exact chain against eq 26, unitless (rad / rad^2).
///
/// $\Delta\mathbf R$ is a product of eight elementary error rotations $e^{[u_k]_\times}$ (after
/// the $\phi_1$ rotation cancels and $R_z(\phi_2)$ conjugation, which preserves norms), with
/// $|u_k| \le m = \max_i|\chi_i|$, and eq 26 is exactly $I + \sum_k [u_k]_\times$. Expanding the
/// product and bounding every term by its norm gives, entrywise,
/// $|\Delta R_{ij} - (I + \sum_k [u_k]_\times)_{ij}| \le e^{s} - 1 - s \le \tfrac{s^2}{2}e^{s}$
/// with $s = \sum_k |u_k| \le 8m$. For $m \le 10'$ ($s \le 0.0233$, $e^s \le 1.0236$) this is
/// $\le 32.76\,m^2$, hence $K = 33$.
pub(crate) const K_EXACT: f64 = 33.0;

/// Second-order constant of the printed small-angle chain (eq 17-19 as printed) against
/// eq 26, unitless. Its three error factors $I + [v]_\times$ have norms $\le \sqrt3 m$,
/// $\sqrt2 m$, $\sqrt3 m$; the product's non-linear part is bounded by
/// $ab + bc + ca + abc = (3 + 2\sqrt6) m^2 + O(m^3) \le 7.91\,m^2$ for $m \le 10'$, hence 8.
pub(crate) const K_SMALL_ANGLE: f64 = 8.0;

/// Rounding error allowed where two computations are equal in exact arithmetic (a few ulps
/// of the unit-size matrix entries accumulated over about ten 3x3 products), rad.
pub(crate) const ROUNDING_RAD: f64 = 1e-14;

/// The bound for recovering eq 26 and Figure 8 from the description, unitless.
pub(crate) const RECOVER_TOL: f64 = 1e-12;

/// Orthonormality and determinant tolerance of the exact $\Delta\mathbf R$ (issue 2, P4).
pub(crate) const ORTHONORMAL_TOL: f64 = 1e-12;

/// Central finite-difference step for the Jacobian check, rad. Truncation error
/// $\approx h^2/6 \cdot |f'''| \approx 2\times10^{-13}$ and rounding $\approx \epsilon/h
/// \approx 2\times10^{-10}$.
pub(crate) const FD_STEP_RAD: f64 = 1e-6;

/// Tolerance of the Jacobian against central finite differences (unitless), 50x the
/// rounding estimate above.
pub(crate) const FD_TOL: f64 = 1e-8;

/// The paper's table (Table 3).
pub(crate) fn table3() -> Turntable {
    paper::table3()
}

/// The three-axis table of the suite: [`tt_kinematics::conformance::three_axis_description`].
#[allow(unused_imports)] // each test binary uses a part of this module
pub(crate) use tt_kinematics::conformance::{three_axis, three_axis_description};

/// A pose of `n` joints anywhere in $[0, 2\pi)^n$.
pub(crate) fn pose_of(n: usize) -> impl Strategy<Value = Pose> {
    prop::collection::vec(0.0..std::f64::consts::TAU, n).prop_map(|a| Pose::new(a).unwrap())
}

/// A pose of the paper's table.
pub(crate) fn pose() -> impl Strategy<Value = Pose> {
    pose_of(2)
}

/// Errors of a table with `n` angular errors in $[-m, m]$ and `t` translations up to 1 mm.
pub(crate) fn errors_of(n: usize, t: usize, m_rad: f64) -> impl Strategy<Value = TurntableErrors> {
    (
        prop::collection::vec(-m_rad..=m_rad, n),
        prop::collection::vec(-1e-3..=1e-3_f64, t),
    )
        .prop_map(|(chi, tr)| TurntableErrors::new(chi, tr).expect("finite by construction"))
}

/// Errors of the paper's table up to `m_rad`.
pub(crate) fn errors_up_to(m_rad: f64) -> impl Strategy<Value = TurntableErrors> {
    errors_of(8, 1, m_rad)
}

/// Errors up to 10 arcmin (the range of the properties).
pub(crate) fn errors() -> impl Strategy<Value = TurntableErrors> {
    errors_up_to(MAX_ERROR_RAD)
}

/// $\chi$ of the paper's table as a fixed array.
pub(crate) fn chi8(e: &TurntableErrors) -> [f64; 8] {
    e.chi_rad().try_into().expect("eight errors")
}

/// Table 4 of the paper (arcmin, order of eq 25) as an error vector, all positive.
pub(crate) fn table4() -> TurntableErrors {
    TurntableErrors::new(
        [
            0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
        ]
        .map(arcmin_to_rad)
        .to_vec(),
        vec![0.0],
    )
    .expect("finite")
}

/// The three-axis chain built independently of the library: nalgebra axis-angle rotations
/// multiplied in the order of `common::three_axis_description`, written out by hand.
pub(crate) fn three_axis_by_axis_angle(pose: &[f64], chi: &[f64]) -> Matrix3<f64> {
    let r = |axis: Vector3<f64>, a: f64| {
        Rotation3::from_axis_angle(&Unit::new_normalize(axis), a).into_inner()
    };
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    // chi order = order of appearance: dphi_o, dalpha_ox, dalpha_oy, deps_om_y, deps_om_z,
    // dphi_m, dalpha_my, dalpha_mz, deps_mi_z, deps_mi_x, dphi_i, dalpha_ix, dalpha_iz
    let rt = r(z, pose[0])
        * r(z, chi[0])
        * r(x, chi[1])
        * r(y, chi[2])
        * r(y, chi[3])
        * r(z, chi[4])
        * r(x, pose[1])
        * r(x, chi[5])
        * r(y, chi[6])
        * r(z, chi[7])
        * r(z, chi[8])
        * r(x, chi[9])
        * r(y, pose[2])
        * r(y, chi[10])
        * r(x, chi[11])
        * r(z, chi[12]);
    let rd = r(z, pose[0]) * r(x, pose[1]) * r(y, pose[2]);
    rd.transpose() * rt
}
