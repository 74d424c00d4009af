//! The paper's two-axis turntable (Zhao et al. 2017, §3, Tables 2-3, eq 17-26) as one
//! instance of a [`TurntableDescription`], and what is specific to it: the closed form of
//! eq 26 and the printed link matrices of eq 17-19.
//!
//! The same description is written in the paper's study file
//! (`studies/gyrowheel-2017.toml`); this module exists so that the library's claim tests and
//! examples can use the paper's table without a file, and to hold eq 26 as printed.

use crate::error::KinematicsError;
use crate::model::OrientationErrorModel;
use crate::pose::TurntableErrors;
use crate::rotation::{Axis, SignedAxis, homogeneous, rot, small_angle, translation};
use crate::turntable::{FactorSpec, Turntable, TurntableDescription};
use nalgebra::{Matrix3, Matrix4, Vector3};
use tt_core::OrientationError;
use tt_core::Pose;

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
    let joint = FactorSpec::joint;
    let error = FactorSpec::error;
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
    fn error_names(&self) -> Vec<String> {
        table3()
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect()
    }

    /// The rotation of eq 26's angles (stated fallback: eq 26 is first order).
    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<nalgebra::Matrix3<f64>, KinematicsError> {
        crate::delta_r_of_angles(self, pose, errors)
    }

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

/// The paper's claims about the turntable model (§3-4), each a function returning its
/// evidence (the numbers a report prints) and whether it holds. The claim tests of this crate
/// call them and assert; the reproduction report calls the same functions and prints them.
pub mod claims {
    use crate::error::KinematicsError;
    use crate::linear::LinearModel;
    use crate::pose::TurntableErrors;
    use crate::turntable::{ChainKind, Turntable};
    use std::fmt;
    use tt_core::OrientationAxis;
    use tt_core::Pose;

    /// Deterministic test points spread over the joint ranges with errors up to `max_rad`
    /// (an additive recurrence: reproducible, well spread).
    fn points(t: &Turntable, n: usize, max_rad: f64) -> Vec<(Pose, TurntableErrors)> {
        let frac = |k: usize, a: f64| (k as f64 * a).fract();
        (0..n)
            .map(|k| {
                let pose: Vec<f64> = t
                    .joint_ranges_rad()
                    .iter()
                    .enumerate()
                    .map(|(j, [lo, hi])| {
                        lo + (hi - lo) * frac(k + 1, 0.618_033_988_749_895 + 0.1 * j as f64)
                    })
                    .collect();
                let chi: Vec<f64> = (0..t.n_rotation_errors())
                    .map(|i| max_rad * (2.0 * frac(k * 7 + i + 1, 0.754_877_666_246_693) - 1.0))
                    .collect();
                (
                    Pose::new(pose).unwrap_or_else(|_| unreachable!("finite")),
                    TurntableErrors::new(chi, vec![0.0; t.n_translation_errors()])
                        .unwrap_or_else(|_| unreachable!("finite")),
                )
            })
            .collect()
    }

    /// Claim under eq 25: the intersection error has no effect on the orientation error.
    #[derive(Debug, Clone, PartialEq)]
    pub struct IntersectionEvidence {
        /// Test points (poses and error vectors).
        pub points: usize,
        /// Translation applied to every error translation, m.
        pub translation_m: f64,
        /// Largest change of any element of $\Delta\mathbf R$ (exact chain), rad.
        pub max_change_rad: f64,
    }

    impl IntersectionEvidence {
        /// Holds when nothing changes, bit for bit.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.max_change_rad == 0.0
        }
    }

    impl fmt::Display for IntersectionEvidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "largest change of ΔR from a {} mm translation at {} poses: {} rad",
                self.translation_m * 1e3,
                self.points,
                if self.max_change_rad == 0.0 {
                    "0".to_string()
                } else {
                    format!("{:e}", self.max_change_rad)
                }
            )
        }
    }

    /// Evaluate the claim under eq 25 on `table`.
    ///
    /// # Errors
    /// [`KinematicsError`] from the chain (never for a valid table).
    pub fn eq25_intersection_error_has_no_effect(
        table: &Turntable,
    ) -> Result<IntersectionEvidence, KinematicsError> {
        const TRANSLATION_M: f64 = 1e-3;
        let pts = points(table, 200, 10.0 * tt_core::units::RAD_PER_ARCMIN);
        let mut max: f64 = 0.0;
        for (pose, e) in &pts {
            let moved = e
                .clone()
                .with_translations_m(vec![TRANSLATION_M; table.n_translation_errors()])?;
            for kind in [ChainKind::Exact, ChainKind::SmallAngle] {
                let d = table.delta_r(pose, e, kind)? - table.delta_r(pose, &moved, kind)?;
                max = max.max(d.amax());
            }
        }
        Ok(IntersectionEvidence {
            points: pts.len(),
            translation_m: TRANSLATION_M,
            max_change_rad: max,
        })
    }

    /// Eq 26 approximates the exact orientation error (25) to second order.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Eq26Evidence {
        /// Largest error magnitude tested, rad.
        pub max_error_rad: f64,
        /// Largest difference between the exact chain and eq 26 found, rad.
        pub max_difference_rad: f64,
        /// The derived bound $K m^2$ ($K = 33$: $e^s - 1 - s$ with $s = 8m$), rad.
        pub bound_rad: f64,
        /// Largest difference between the first-order model built from the description and
        /// the printed eq 26, relative to the largest coefficient (dimensionless; the
        /// description recovers eq 26).
        pub eq26_recovery_rel: f64,
    }

    impl Eq26Evidence {
        /// Holds when the difference is within the bound and the description recovers eq 26
        /// to 1e-12.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.max_difference_rad <= self.bound_rad && self.eq26_recovery_rel <= 1e-12
        }
    }

    impl fmt::Display for Eq26Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "errors up to {:.1} arcmin: exact chain minus eq 26 at most {:.3e} rad (bound 33 m² = {:.3e} rad); the description's first-order model equals eq 26 to {}",
                self.max_error_rad / tt_core::units::RAD_PER_ARCMIN,
                self.max_difference_rad,
                self.bound_rad,
                if self.eq26_recovery_rel == 0.0 {
                    "rounding (0)".to_string()
                } else {
                    format!("{:.1e} (relative)", self.eq26_recovery_rel)
                }
            )
        }
    }

    /// Evaluate eq 26 against the exact chain of the paper's table (errors up to 10 arcmin).
    ///
    /// # Errors
    /// [`KinematicsError::WrongTurntable`] unless `table` is the paper's (eight errors, two
    /// joints).
    pub fn eq26_approximates_the_exact_chain(
        table: &Turntable,
    ) -> Result<Eq26Evidence, KinematicsError> {
        use crate::model::OrientationErrorModel;
        let m = 10.0 * tt_core::units::RAD_PER_ARCMIN;
        let exact = crate::model::ExactChain::new(table);
        let linear = LinearModel::new(table);
        let (mut diff, mut recovery): (f64, f64) = (0.0, 0.0);
        for (pose, e) in points(table, 400, m) {
            let a = exact.orientation_error(&pose, &e)?.to_array();
            let b = super::ClosedForm.orientation_error(&pose, &e)?.to_array();
            let c = linear.evaluate(&pose, &e)?.to_array();
            for k in 0..3 {
                diff = diff.max((a[k] - b[k]).abs());
                recovery =
                    recovery.max((b[k] - c[k]).abs() / e.max_abs_rad().max(f64::MIN_POSITIVE));
            }
        }
        Ok(Eq26Evidence {
            max_error_rad: m,
            max_difference_rad: diff,
            bound_rad: 33.0 * m * m,
            eq26_recovery_rel: recovery,
        })
    }

    /// Figure 8 and §4.3: only $\Delta\theta$ is sensitive to $\Delta\phi_{z2}$ and
    /// $\Delta\alpha_{z1}$, and $\Delta\theta$ only to them.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Fig8Evidence {
        /// Average sensitivities (rows $\psi, \theta, \gamma$; error order of $\chi$).
        pub averages: Vec<[f64; 3]>,
        /// Error names, order of $\chi$.
        pub names: Vec<String>,
        /// The errors $\Delta\theta$ depends on.
        pub theta_errors: Vec<String>,
        /// Of those, the ones $\Delta\psi$ or $\Delta\gamma$ also depend on.
        pub shared_with_other_angles: Vec<String>,
    }

    impl Fig8Evidence {
        /// Holds when $\Delta\theta$ depends exactly on `dphi_z2` and `dalpha_z1`, and no other
        /// angle on them.
        #[must_use]
        pub fn holds(&self) -> bool {
            self.theta_errors == ["dphi_z2", "dalpha_z1"]
                && self.shared_with_other_angles.is_empty()
        }
    }

    impl fmt::Display for Fig8Evidence {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let theta: Vec<String> = self
                .theta_errors
                .iter()
                .map(|n| {
                    let k = self.names.iter().position(|m| m == n).unwrap_or(0);
                    format!("{n} ({:.4})", self.averages.get(k).map_or(0.0, |a| a[1]))
                })
                .collect();
            write!(
                f,
                "Δθ depends on {} (average sensitivity); shared with Δψ or Δγ: {}",
                theta.join(", "),
                if self.shared_with_other_angles.is_empty() {
                    "none".into()
                } else {
                    self.shared_with_other_angles.join(", ")
                },
            )
        }
    }

    /// Evaluate the Figure 8 claim on `table` (its first-order model).
    #[must_use]
    pub fn fig8_theta_depends_only_on_dphi_z2_and_dalpha_z1(table: &Turntable) -> Fig8Evidence {
        let m = LinearModel::new(table);
        let names: Vec<String> = table
            .rotation_error_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        let avg = m.average_abs_coefficients();
        let theta = m.involved(OrientationAxis::Theta);
        let shared = theta
            .iter()
            .filter(|&&i| {
                m.is_involved(OrientationAxis::Psi, i) || m.is_involved(OrientationAxis::Gamma, i)
            })
            .map(|&i| names[i].clone())
            .collect();
        Fig8Evidence {
            averages: (0..names.len())
                .map(|i| [avg[(0, i)], avg[(1, i)], avg[(2, i)]])
                .collect(),
            theta_errors: theta.iter().map(|&i| names[i].clone()).collect(),
            shared_with_other_angles: shared,
            names,
        }
    }
}
