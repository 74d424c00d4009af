//! The paper's two-axis turntable (Zhao et al. 2017, §3, Tables 2-3, eq 17-26) as one
//! instance of a [`TurntableDescription`], and what is specific to it: the closed form of
//! eq 26 and the printed link matrices of eq 17-19.
//!
//! The same description is written in the paper's study file
//! (`studies/gyrowheel-2017.toml`); this module exists so that the library's claim tests and
//! examples can use the paper's table without a file, and to hold eq 26 as printed.

use crate::error::KinematicsError;
use crate::model::{OrientationError, OrientationErrorModel};
use crate::pose::{Pose, TurntableErrors};
use crate::rotation::{Axis, SignedAxis, homogeneous, rot, small_angle, translation};
use crate::turntable::{FactorSpec, Turntable, TurntableDescription};
use nalgebra::{Matrix3, Matrix4, Vector3};

/// The angular errors of the paper's table in the order of $\chi$ (eq 25) with Table 2's
/// definitions.
pub const CHI: [(&str, &str); 8] = [
    ("dphi_y1", "position error of outer axis"),
    ("dphi_z2", "position error of inner axis"),
    ("dalpha_x1", "wobble error of outer axis about x"),
    ("dalpha_z1", "wobble error of outer axis about z"),
    ("dalpha_x2", "wobble error of inner axis about x"),
    ("dalpha_y2", "wobble error of inner axis about y"),
    ("deps_x", "orthogonality error about x"),
    ("deps_y", "orthogonality error about y"),
];

/// Index of a named error in $\chi$ of eq 25.
///
/// # Panics
/// Never for the eight names of [`CHI`]; panics on any other name (a programming error in a
/// caller that names the paper's errors).
#[must_use]
pub fn chi_index(name: &str) -> usize {
    CHI.iter()
        .position(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("`{name}` is not an error of the paper's turntable"))
}

/// Table 3 as a description: outer joint $\phi_1$ about $y$, its position error and wobbles,
/// the intersection error and orthogonality errors, inner joint $\phi_2$ about $z$, its wobble
/// and position errors; errors ordered as $\chi$ of eq 25, then $\Delta\eta$.
///
/// | Table 3 row | factors |
/// |---|---|
/// | 0 | $R_y(\phi_1)$, $R_y(\Delta\phi_{y1})$, $R_z(\Delta\alpha_{z1})$, $R_x(\Delta\alpha_{x1})$ |
/// | 1 | $\mathrm{Trans}_x(\Delta\eta)$, $R_y(\Delta\varepsilon_y)$, $R_x(\Delta\varepsilon_x)$ |
/// | 2 | $R_z(\phi_2)$, $R_y(\Delta\alpha_{y2})$, $R_z(\Delta\phi_{z2})$, $R_x(\Delta\alpha_{x2})$ |
///
/// Table 3 words row 1 as "a translation $\Delta\eta$ along $x$, followed by" the
/// orthogonality rotations; eq 18 prints the rotation first. The order changes only the
/// translation part of $\mathbf T_t$, never $\Delta\mathbf R$.
#[must_use]
pub fn table3_description() -> TurntableDescription {
    let joint = |name: &str, about| FactorSpec::Joint {
        name: name.into(),
        about,
    };
    let error = |name: &str, about| FactorSpec::Error {
        name: name.into(),
        about,
    };
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    let mut error_order: Vec<String> = CHI.iter().map(|(n, _)| (*n).to_string()).collect();
    error_order.push("deta".into());
    let mut descriptions: Vec<(String, String)> = CHI
        .iter()
        .map(|(n, d)| ((*n).to_string(), (*d).to_string()))
        .collect();
    descriptions.push(("deta".into(), "intersection error".into()));
    descriptions.push(("phi1".into(), "outer axis".into()));
    descriptions.push(("phi2".into(), "inner axis".into()));
    TurntableDescription {
        factors: vec![
            joint("phi1", y),
            error("dphi_y1", y),
            error("dalpha_z1", z),
            error("dalpha_x1", x),
            FactorSpec::Translation {
                name: "deta".into(),
                along: x,
            },
            error("deps_y", y),
            error("deps_x", x),
            joint("phi2", z),
            error("dalpha_y2", y),
            error("dphi_z2", z),
            error("dalpha_x2", x),
        ],
        error_order: Some(error_order),
        joint_ranges_rad: Vec::new(),
        descriptions,
    }
}

/// The paper's turntable, compiled.
#[must_use]
pub fn table3() -> Turntable {
    Turntable::new(&table3_description())
        .unwrap_or_else(|e| unreachable!("Table 3 is a valid description: {e}"))
}

/// The closed form of eq 26 (the first-order expansion of eq 23-24 about $\chi = 0$), for the
/// paper's table only (eight angular errors in the order of eq 25, poses $(\phi_1, \phi_2)$).
///
/// # Formula
/// $$\begin{aligned}
/// \Delta\psi &= \Delta\phi_{y1}\cos\phi_2 - \Delta\alpha_{x1}\sin\phi_2 + \Delta\alpha_{y2} -
///   \Delta\varepsilon_x\sin\phi_2 + \Delta\varepsilon_y\cos\phi_2,\\
/// \Delta\theta &= \Delta\phi_{z2} + \Delta\alpha_{z1},\\
/// \Delta\gamma &= \Delta\phi_{y1}\sin\phi_2 + \Delta\alpha_{x1}\cos\phi_2 + \Delta\alpha_{x2} +
///   \Delta\varepsilon_x\cos\phi_2 + \Delta\varepsilon_y\sin\phi_2.
/// \end{aligned}$$
///
/// # Reference
/// Zhao et al. 2017, eq 26-27.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ClosedForm;

impl ClosedForm {
    /// Eq 26 at inner-axis angle `phi2_rad` for $\chi$ (rad, order of eq 25).
    #[must_use]
    pub fn eq26(phi2_rad: f64, chi: &[f64; 8]) -> [f64; 3] {
        let [
            dphi_y1,
            dphi_z2,
            dalpha_x1,
            dalpha_z1,
            dalpha_x2,
            dalpha_y2,
            deps_x,
            deps_y,
        ] = *chi;
        let (s, c) = phi2_rad.sin_cos();
        [
            dphi_y1 * c - dalpha_x1 * s + dalpha_y2 - deps_x * s + deps_y * c,
            dphi_z2 + dalpha_z1,
            dphi_y1 * s + dalpha_x1 * c + dalpha_x2 + deps_x * c + deps_y * s,
        ]
    }
}

impl OrientationErrorModel for ClosedForm {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let wrong = || KinematicsError::WrongTurntable {
            model: "eq 26 (ClosedForm)",
            applies_to: "the paper's two-axis table (2 joints, 8 angular errors)",
        };
        let [_, phi2] = pose.angles_rad() else {
            return Err(wrong());
        };
        let chi: &[f64; 8] = errors.chi_rad().try_into().map_err(|_| wrong())?;
        Ok(OrientationError::from_array(Self::eq26(*phi2, chi)))
    }
}

/// The link transforms $[{}^0\mathbf T_1, {}^1\mathbf T_2, {}^2\mathbf T_3, {}^3\mathbf T_4]$ of
/// eq 17-20 exactly as printed (small-angle matrices, translation in metres, eq 18's rotation
/// before translation), for $\chi$ in the order of eq 25 and $\Delta\eta$.
#[must_use]
pub fn printed_links(
    phi1_rad: f64,
    phi2_rad: f64,
    chi: &[f64; 8],
    deta_m: f64,
) -> [Matrix4<f64>; 4] {
    let [
        dphi_y1,
        dphi_z2,
        dalpha_x1,
        dalpha_z1,
        dalpha_x2,
        dalpha_y2,
        deps_x,
        deps_y,
    ] = *chi;
    [
        homogeneous(
            &(rot(Axis::Y, phi1_rad) * small_angle(&Vector3::new(dalpha_x1, dphi_y1, dalpha_z1))),
        ),
        homogeneous(&small_angle(&Vector3::new(deps_x, deps_y, 0.0)))
            * translation(&Vector3::new(deta_m, 0.0, 0.0)),
        homogeneous(
            &(rot(Axis::Z, phi2_rad) * small_angle(&Vector3::new(dalpha_x2, dalpha_y2, dphi_z2))),
        ),
        Matrix4::identity(),
    ]
}

/// $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ with $\mathbf R_t$ the product of the printed
/// links of eq 17-19 and $\mathbf R_d = R_y(\phi_1) R_z(\phi_2)$ (eq 21).
#[must_use]
pub fn printed_delta_r(phi1_rad: f64, phi2_rad: f64, chi: &[f64; 8]) -> Matrix3<f64> {
    let t = printed_links(phi1_rad, phi2_rad, chi, 0.0)
        .iter()
        .fold(Matrix4::identity(), |m, l| m * l);
    let rt = t.fixed_view::<3, 3>(0, 0).into_owned();
    let rd = rot(Axis::Y, phi1_rad) * rot(Axis::Z, phi2_rad);
    rd.transpose() * rt
}

/// Figure 8's averaged sensitivities as implied by eq 26 and eq 28 (the figure prints no
/// numbers): $2/\pi$ for every $\sin\phi_2$/$\cos\phi_2$ term, 1 for a constant term, 0 where
/// an error is not involved. Rows $\psi, \theta, \gamma$; columns in the order of $\chi$.
#[must_use]
pub fn figure8_expected() -> [[f64; 8]; 3] {
    let h = std::f64::consts::FRAC_2_PI;
    [
        [h, 0.0, h, 0.0, 0.0, 1.0, h, h],
        [0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        [h, 0.0, h, 0.0, 1.0, 0.0, h, h],
    ]
}
