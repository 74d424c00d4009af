//! Elementary rotations, signed axes and skew matrices (right-handed, active).
//!
//! $$R_x(a) = \begin{bmatrix}1&0&0\\0&\cos a&-\sin a\\0&\sin a&\cos a\end{bmatrix},\quad
//!   R_y(a) = \begin{bmatrix}\cos a&0&\sin a\\0&1&0\\-\sin a&0&\cos a\end{bmatrix},\quad
//!   R_z(a) = \begin{bmatrix}\cos a&-\sin a&0\\\sin a&\cos a&0\\0&0&1\end{bmatrix}.$$
//!
//! These are the matrices of eq 17, 19 and 21 of the paper. A rotation about a negative axis
//! $-x$ by $a$ is the rotation about $x$ by $-a$.

use nalgebra::{Matrix3, Matrix4, Vector3};
pub(crate) use tt_core::{Axis, SignedAxis};

/// Rotation by `angle_rad` about `axis`.
#[must_use]
pub fn rot(axis: Axis, angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    rot_sc(axis, s, c)
}

/// Rotation by `angle_rad` about a signed axis.
#[must_use]
pub(crate) fn rot_signed(axis: SignedAxis, angle_rad: f64) -> Matrix3<f64> {
    rot(axis.axis, axis.sign() * angle_rad)
}

/// The rotation about `axis` whose angle has sine `s` and cosine `c` (given exactly, so that
/// quarter turns give exact zeros).
#[must_use]
pub(crate) fn rot_sc(axis: Axis, s: f64, c: f64) -> Matrix3<f64> {
    match axis {
        Axis::X => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        Axis::Y => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        Axis::Z => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

/// The skew (cross-product) matrix $\lbrack v\rbrack_\times$, so that $\lbrack v\rbrack_\times w = v \times w$.
///
/// $$\lbrack v\rbrack_\times = \begin{bmatrix}0&-v_z&v_y\\v_z&0&-v_x\\-v_y&v_x&0\end{bmatrix}.$$
#[must_use]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The small-angle error matrix $I + \lbrack v\rbrack_\times$ of eq 17-19 (not orthonormal).
///
/// With $v = (\Delta\alpha_{x1}, \Delta\phi_{y1}, \Delta\alpha_{z1})$ this is the second factor of
/// eq 17; with $(\Delta\varepsilon_x, \Delta\varepsilon_y, 0)$ the first of eq 18; with
/// $(\Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\phi_{z2})$ the second of eq 19.
#[must_use]
pub fn small_angle(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() + skew(v)
}

/// Embed a rotation (or any 3x3 block) in a homogeneous transform with zero translation.
#[must_use]
pub(crate) fn homogeneous(r: &Matrix3<f64>) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    t.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    t
}

/// A pure translation as a homogeneous transform.
#[must_use]
pub(crate) fn translation(d: &Vector3<f64>) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    t.fixed_view_mut::<3, 1>(0, 3).copy_from(d);
    t
}

/// The rotation vector (axis times angle) of a rotation matrix, accurate for small angles.
///
/// With $v = \tfrac12\operatorname{vee}(R - R^T) = \sin\vartheta\,\hat n$ and
/// $\cos\vartheta = \tfrac12(\operatorname{tr}R - 1)$, $\vartheta = \operatorname{atan2}(|v|, \cos\vartheta)$
/// keeps full relative precision near $\vartheta = 0$ (unlike $\arccos$). Valid for
/// $\vartheta < \pi$, which holds for every turntable error of interest.
#[must_use]
pub(crate) fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let angle = s.atan2(c);
    if s == 0.0 { v } else { v * (angle / s) }
}
