//! The homogeneous-transform chain of eq 17-23, exact and as printed (small-angle).
//!
//! # Formula
//! $$\mathbf T_t = {}^0\mathbf T_1\,{}^1\mathbf T_2\,{}^2\mathbf T_3\,{}^3\mathbf T_4 \quad (22),
//! \qquad \mathbf T_d = \mathrm{Rot}_y(\phi_1)\,\mathrm{Rot}_z(\phi_2) \quad (21),
//! \qquad \Delta\mathbf R = \mathbf R_d^T \mathbf R_t \quad (23).$$
//!
//! | link | exact ([`ChainKind::Exact`]) | as printed ([`ChainKind::SmallAngle`]) |
//! |---|---|---|
//! | ${}^0\mathbf T_1$ (17) | $R_y(\phi_1) R_y(\Delta\phi_{y1}) R_z(\Delta\alpha_{z1}) R_x(\Delta\alpha_{x1})$ | $R_y(\phi_1)\,(I + [\Delta\alpha_{x1}, \Delta\phi_{y1}, \Delta\alpha_{z1}]_\times)$ |
//! | ${}^1\mathbf T_2$ (18) | $R_y(\Delta\varepsilon_y) R_x(\Delta\varepsilon_x)\,\mathrm{Trans}_x(\Delta\eta)$ | $(I + [\Delta\varepsilon_x, \Delta\varepsilon_y, 0]_\times)\,\mathrm{Trans}_x(\Delta\eta)$ |
//! | ${}^2\mathbf T_3$ (19) | $R_z(\phi_2) R_y(\Delta\alpha_{y2}) R_z(\Delta\phi_{z2}) R_x(\Delta\alpha_{x2})$ | $R_z(\phi_2)\,(I + [\Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\phi_{z2}]_\times)$ |
//! | ${}^3\mathbf T_4$ (20) | $I$ | $I$ |
//!
//! The exact rotation order is Table 3's. Table 3 words link 1 as "a translation $\Delta\eta$
//! along $x$, followed by" the orthogonality rotations, while eq 18 prints the rotation first;
//! we follow eq 18 in both kinds. The order changes only the translation part of
//! $\mathbf T_t$, never $\Delta\mathbf R$ (the intersection error has no effect on the
//! orientation; see the claim under eq 25).

use crate::errors::{ErrorComponent, TurntableErrors};
use crate::pose::Pose;
use crate::rotation::{Axis, homogeneous, rot, small_angle, translation};
use nalgebra::{Matrix3, Matrix4, Vector3};

/// Which link matrices to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ChainKind {
    /// Every error a finite rotation (orthonormal), in the order of Table 3.
    #[default]
    Exact,
    /// The small-angle matrices $I + [\delta]_\times$ exactly as printed in eq 17-19.
    SmallAngle,
}

/// One elementary rotation of the exact chain: its axis, its angle and, for an error rotation,
/// which component of $\chi$ it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Factor {
    /// Rotation axis.
    pub axis: Axis,
    /// Rotation angle, rad.
    pub angle_rad: f64,
    /// The error component, or `None` for a commanded rotation ($\phi_1$, $\phi_2$).
    pub component: Option<ErrorComponent>,
}

/// The ten elementary rotations of $\mathbf R_t$ in the order of Table 3 (left to right).
///
/// This list is the single definition of the rotation order used by the exact chain and by
/// the analytic Jacobian ([`crate::sensitivity::exact_jacobian`]).
#[must_use]
pub fn exact_factors(pose: &Pose, errors: &TurntableErrors) -> [Factor; 10] {
    use ErrorComponent as C;
    let f = |axis, c: C| Factor {
        axis,
        angle_rad: errors.get(c),
        component: Some(c),
    };
    let cmd = |axis, angle_rad| Factor {
        axis,
        angle_rad,
        component: None,
    };
    [
        cmd(Axis::Y, pose.phi1_rad),
        f(Axis::Y, C::DphiY1),
        f(Axis::Z, C::DalphaZ1),
        f(Axis::X, C::DalphaX1),
        f(Axis::Y, C::DepsY),
        f(Axis::X, C::DepsX),
        cmd(Axis::Z, pose.phi2_rad),
        f(Axis::Y, C::DalphaY2),
        f(Axis::Z, C::DphiZ2),
        f(Axis::X, C::DalphaX2),
    ]
}

fn product(factors: &[Factor]) -> Matrix3<f64> {
    factors
        .iter()
        .fold(Matrix3::identity(), |m, f| m * rot(f.axis, f.angle_rad))
}

/// The link transforms $[{}^0\mathbf T_1, {}^1\mathbf T_2, {}^2\mathbf T_3, {}^3\mathbf T_4]$
/// of eq 17-20 (translations in metres).
#[must_use]
pub fn link_transforms(
    pose: &Pose,
    errors: &TurntableErrors,
    kind: ChainKind,
) -> [Matrix4<f64>; 4] {
    use ErrorComponent as C;
    let e = |c| errors.get(c);
    let shift = translation(&Vector3::new(errors.deta_m(), 0.0, 0.0));
    match kind {
        ChainKind::Exact => {
            let f = exact_factors(pose, errors);
            [
                homogeneous(&product(&f[0..4])),
                homogeneous(&product(&f[4..6])) * shift,
                homogeneous(&product(&f[6..10])),
                Matrix4::identity(),
            ]
        }
        ChainKind::SmallAngle => [
            homogeneous(
                &(rot(Axis::Y, pose.phi1_rad)
                    * small_angle(&Vector3::new(e(C::DalphaX1), e(C::DphiY1), e(C::DalphaZ1)))),
            ),
            homogeneous(&small_angle(&Vector3::new(e(C::DepsX), e(C::DepsY), 0.0))) * shift,
            homogeneous(
                &(rot(Axis::Z, pose.phi2_rad)
                    * small_angle(&Vector3::new(e(C::DalphaX2), e(C::DalphaY2), e(C::DphiZ2)))),
            ),
            Matrix4::identity(),
        ],
    }
}

/// The ideal transform $\mathbf T_d$ of eq 21.
#[must_use]
pub fn ideal_transform(pose: &Pose) -> Matrix4<f64> {
    homogeneous(&(rot(Axis::Y, pose.phi1_rad) * rot(Axis::Z, pose.phi2_rad)))
}

/// The actual transform $\mathbf T_t = \prod_{i=0}^{3} {}^i\mathbf T_{i+1}$ of eq 22.
#[must_use]
pub fn actual_transform(pose: &Pose, errors: &TurntableErrors, kind: ChainKind) -> Matrix4<f64> {
    link_transforms(pose, errors, kind)
        .iter()
        .fold(Matrix4::identity(), |m, t| m * t)
}

/// The orientation error matrix $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ of eq 23
/// (GyroWheel frame as intended, from GyroWheel frame as built).
///
/// For [`ChainKind::Exact`] it is a rotation; for [`ChainKind::SmallAngle`] it is the product
/// of the printed matrices and is orthonormal only to first order.
#[must_use]
pub fn delta_r(pose: &Pose, errors: &TurntableErrors, kind: ChainKind) -> Matrix3<f64> {
    let rd = ideal_transform(pose).fixed_view::<3, 3>(0, 0).into_owned();
    let rt = actual_transform(pose, errors, kind)
        .fixed_view::<3, 3>(0, 0)
        .into_owned();
    rd.transpose() * rt
}
