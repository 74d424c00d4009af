//! A turntable as data: an ordered list of factors from the base to the platform, validated
//! and compiled once into everything the other modules evaluate.
//!
//! # Formula
//! With factors $F_1, \dots, F_n$ (joint rotations $R_a(\phi_j)$, error rotations
//! $R_a(\chi_i)$, error translations, fixed rotations $R_a(\alpha)$), each about or along an
//! axis of the current (moving) frame,
//! $$\mathbf T_t = \prod_{k=1}^{n} \mathbf T(F_k), \qquad \mathbf R_t = \prod_{k=1}^{n} \mathbf R(F_k)
//! \quad (22),$$
//! the nominal $\mathbf R_d$ is the same product with every error zero (eq 21), and
//! $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ (eq 23). The angles are read off $\Delta\mathbf R$ as
//! eq 24 does: $\Delta\psi = \Delta R_{13}$ (about $y$), $\Delta\theta = \Delta R_{21}$ (about $z$),
//! $\Delta\gamma = \Delta R_{32}$ (about $x$).
//!
//! # Rotation order
//! Post-multiplication, base to platform, exactly the order of the list: the first factor acts
//! in the base frame, each next one about an axis of the frame the previous ones produced.
//! This is the order of the paper's Table 3 (see `paper::table3_description`).
//!
//! # The evaluation plan
//! Group the factors into nominal blocks $\mathbf A_s$ (joints and fixed rotations) and error
//! blocks $\mathbf E_s$ (error rotations; translations do not rotate):
//! $\mathbf R_t = \mathbf A_0\mathbf E_1\mathbf A_1\cdots\mathbf E_m\mathbf A_m$ and
//! $\mathbf R_d = \mathbf A_0\mathbf A_1\cdots\mathbf A_m$, so
//! $$\Delta\mathbf R = \prod_{s=1}^{m} \mathbf B_s^T\mathbf E_s\mathbf B_s,\qquad
//! \mathbf B_s = \mathbf A_s\mathbf A_{s+1}\cdots\mathbf A_m.$$
//! The leading block $\mathbf A_0$ (for example the outer axis of a table whose first factor is
//! a joint) cancels exactly. [`Turntable::plan`] lists the steps of the sequential evaluation
//! $q \leftarrow q\,\mathbf E_s$, then $q \leftarrow \mathbf A_s^{-1} q\,\mathbf A_s$: a flat
//! program a hot loop runs without looking at the description.

use crate::error::{KinematicsError, description, finite, length};
use crate::pose::TurntableErrors;
use crate::rotation::{Axis, SignedAxis, homogeneous, rot_signed, skew, translation};
use nalgebra::{DMatrix, Matrix3, Matrix4};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;
use tt_core::Pose;

/// One factor of a turntable description, as a user writes it (names, not indices).
#[derive(Debug, Clone, PartialEq)]
pub enum FactorSpec {
    /// The commanded rotation of a joint by its angle about an axis of the current frame.
    Joint {
        /// Joint name (`[a-z][a-z0-9_]*`).
        name: String,
        /// Rotation axis.
        about: SignedAxis,
    },
    /// A small error rotation about an axis of the current frame.
    Error {
        /// Error name (`[a-z][a-z0-9_]*`).
        name: String,
        /// Rotation axis.
        about: SignedAxis,
    },
    /// An error translation along an axis of the current frame (no effect on orientation).
    Translation {
        /// Error name.
        name: String,
        /// Translation axis.
        along: SignedAxis,
    },
    /// A fixed nominal rotation (mounting, tilted axes).
    Fixed {
        /// Angle, rad.
        angle_rad: f64,
        /// Rotation axis.
        about: SignedAxis,
    },
}

impl FactorSpec {
    /// [`FactorSpec::Joint`]: the commanded rotation of joint `name` about `about`.
    #[must_use]
    pub fn joint(name: &str, about: SignedAxis) -> Self {
        Self::Joint {
            name: name.into(),
            about,
        }
    }

    /// [`FactorSpec::Error`]: the small error rotation `name` about `about`.
    #[must_use]
    pub fn error(name: &str, about: SignedAxis) -> Self {
        Self::Error {
            name: name.into(),
            about,
        }
    }

    /// [`FactorSpec::Translation`]: the error translation `name` along `along`.
    #[must_use]
    pub fn translation(name: &str, along: SignedAxis) -> Self {
        Self::Translation {
            name: name.into(),
            along,
        }
    }

    /// [`FactorSpec::Fixed`]: a fixed nominal rotation by `angle_rad` about `about`.
    #[must_use]
    pub fn fixed(angle_rad: f64, about: SignedAxis) -> Self {
        Self::Fixed { angle_rad, about }
    }
}

/// A turntable as data: factors from the base to the platform plus optional error order, joint
/// ranges and wording. Validated and compiled by [`Turntable::new`].
///
/// # Example: a single-axis rate table with a tilted axis
/// ```
/// use tt_kinematics::{FactorSpec, SignedAxis, Turntable, TurntableDescription};
/// let d = TurntableDescription::new(vec![
///     FactorSpec::Error { name: "tilt_x".into(), about: SignedAxis::X },
///     FactorSpec::Joint { name: "phi".into(), about: SignedAxis::Z },
///     FactorSpec::Error { name: "dphi".into(), about: SignedAxis::Z },
/// ]);
/// let t = Turntable::new(&d)?;
/// assert_eq!(t.rotation_error_names(), ["tilt_x", "dphi"]);
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TurntableDescription {
    /// Factors from the base to the platform.
    pub factors: Vec<FactorSpec>,
    /// Order of the error vector (every rotation and translation error once); `None` for the
    /// order of appearance. Rotation errors form $\chi$ in this order, translations their own
    /// vector.
    pub error_order: Option<Vec<String>>,
    /// Joint ranges `(joint, [min, max])`, rad; a joint not listed has the full turn
    /// $[0, 2\pi]$.
    pub joint_ranges_rad: Vec<(String, [f64; 2])>,
    /// Wording of joints and errors for reports `(name, text)`.
    pub descriptions: Vec<(String, String)>,
}

impl TurntableDescription {
    /// A description with these factors and every option at its default.
    #[must_use]
    pub fn new(factors: Vec<FactorSpec>) -> Self {
        Self {
            factors,
            ..Self::default()
        }
    }
}

/// A joint of a compiled turntable.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Name.
    pub name: String,
    /// Rotation axis.
    pub about: SignedAxis,
    /// Range $[\min, \max]$, rad.
    pub range_rad: [f64; 2],
    /// Index of its factor in the description.
    pub factor: usize,
}

/// An error of a compiled turntable (rotation or translation).
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorInfo {
    /// Name.
    pub name: String,
    /// Rotation or translation axis.
    pub axis: SignedAxis,
    /// Index of its factor in the description.
    pub factor: usize,
}

/// A compiled factor (indices into the joint and error vectors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Factor {
    /// Joint `joint` rotates about `about` by its pose angle.
    Joint {
        /// Index of the joint (pose order).
        joint: usize,
        /// Axis.
        about: SignedAxis,
    },
    /// Angular error `error` (index in $\chi$) rotates about `about`.
    Rotation {
        /// Index in $\chi$.
        error: usize,
        /// Axis.
        about: SignedAxis,
    },
    /// Translation error `error` (index in the translation vector) along `along`.
    Translation {
        /// Index in the translation vector.
        error: usize,
        /// Axis.
        along: SignedAxis,
    },
    /// A fixed rotation.
    Fixed {
        /// Angle, rad.
        angle_rad: f64,
        /// Axis.
        about: SignedAxis,
    },
}

/// One step of the flat evaluation plan of $\Delta\mathbf R$ (see the [module](self)).
///
/// Start from the identity quaternion $q$ and apply the steps in order:
/// - [`PlanStep::Error`]: $q \leftarrow q \otimes (\cos\tfrac x2, \sin\tfrac x2\,\hat e)$ with
///   $x = $ `sign` $\cdot\,\chi_{\text{chi}}$, $\hat e$ the unit vector of `axis`;
/// - [`PlanStep::Joint`] and [`PlanStep::Fixed`]: conjugation
///   $q \leftarrow n^{-1} \otimes q \otimes n$ by the nominal rotation $n$ about `axis` by
///   `sign` $\cdot\,\phi_{\text{joint}}$ (or the fixed angle): the scalar part is kept and the
///   vector part is turned by $R_{\text{axis}}(-\text{angle})$.
///
/// Then $q$ is the quaternion of $\Delta\mathbf R$ and eq 24 reads
/// $\Delta\psi = 2(xz + wy)$, $\Delta\theta = 2(xy + wz)$, $\Delta\gamma = 2(yz + wx)$.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanStep {
    /// Multiply by the error rotation of $\chi_{\text{chi}}$.
    Error {
        /// Index in $\chi$.
        chi: usize,
        /// Axis.
        axis: Axis,
        /// $\pm1$ (negative axes).
        sign: f64,
    },
    /// Conjugate by a joint's rotation.
    Joint {
        /// Joint index (pose order).
        joint: usize,
        /// Axis.
        axis: Axis,
        /// $\pm1$.
        sign: f64,
    },
    /// Conjugate by a fixed rotation with the given sine and cosine.
    Fixed {
        /// Axis.
        axis: Axis,
        /// $\sin$ of the (signed) angle.
        sin: f64,
        /// $\cos$ of the angle.
        cos: f64,
    },
}

/// Per-pose nominal data of the segmented evaluation of $\Delta\mathbf R$ (see
/// [`Turntable::pose_frames`]): $\mathbf B_1$ and the transposed nominal blocks
/// $\mathbf A_s^T$ after each error segment.
#[doc(hidden)]
#[derive(Debug, Clone, PartialEq)]
pub struct PoseFrames {
    b1: Matrix3<f64>,
    /// $\mathbf A_s^T$, `None` where the block is the identity (no nominal rotation after the
    /// segment): skipped.
    blocks_t: Vec<Option<Matrix3<f64>>>,
}

impl PoseFrames {
    /// $\Delta\mathbf R^T\mathbf v$ for the segment rotations `e` ($\mathbf E_s$, from
    /// [`Turntable::segment_rotations`]): the vector $\mathbf v$ of the intended platform frame
    /// seen from the actual one (eq 8).
    ///
    /// # Formula
    /// $\mathbf w \leftarrow \mathbf B_1\mathbf v$, then for every segment
    /// $\mathbf w \leftarrow \mathbf A_s^T\mathbf E_s^T\mathbf w$ (because
    /// $\mathbf B_{s+1}\mathbf B_s^T = \mathbf A_s^T$).
    #[inline]
    #[must_use]
    pub fn delta_r_transpose_times(
        &self,
        e: &[Matrix3<f64>],
        v: &nalgebra::Vector3<f64>,
    ) -> nalgebra::Vector3<f64> {
        self.delta_r_transpose_times_pre(e, &self.pre(v))
    }

    /// $\mathbf B_1\mathbf v$: the part of [`PoseFrames::delta_r_transpose_times`] that does not
    /// depend on the errors (compute it once per pose and vector).
    #[inline]
    #[must_use]
    pub fn pre(&self, v: &nalgebra::Vector3<f64>) -> nalgebra::Vector3<f64> {
        self.b1 * v
    }

    /// [`PoseFrames::delta_r_transpose_times`] from $\mathbf B_1\mathbf v$ ([`PoseFrames::pre`]).
    #[inline]
    #[must_use]
    pub fn delta_r_transpose_times_pre(
        &self,
        e: &[Matrix3<f64>],
        pre: &nalgebra::Vector3<f64>,
    ) -> nalgebra::Vector3<f64> {
        let mut w = *pre;
        for (es, at) in e.iter().zip(&self.blocks_t) {
            w = es.tr_mul(&w);
            if let Some(at) = at {
                w = at * w;
            }
        }
        w
    }

    /// $\mathbf A_s^T$ after each error segment $s$ (`None` where the block is the identity
    /// and [`PoseFrames::delta_r_transpose_times_pre`] skips it): for kernels that lay several
    /// poses out side by side.
    #[doc(hidden)]
    #[must_use]
    pub fn blocks_t(&self) -> &[Option<Matrix3<f64>>] {
        &self.blocks_t
    }

    /// $\Delta\mathbf R = \mathbf B_1^T\mathbf E_1\mathbf A_1\cdots\mathbf E_m\mathbf A_m$.
    #[must_use]
    pub fn delta_r(&self, e: &[Matrix3<f64>]) -> Matrix3<f64> {
        e.iter()
            .zip(&self.blocks_t)
            .fold(self.b1.transpose(), |m, (es, at)| match at {
                Some(at) => m * es * at.transpose(),
                None => m * es,
            })
    }
}

/// Which link matrices a chain uses for the error rotations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ChainKind {
    /// Every error a finite rotation, in the order of the description.
    #[default]
    Exact,
    /// Every maximal run of consecutive error rotations (not separated by a joint, a fixed
    /// rotation or a translation) replaced by one small-angle matrix
    /// $I + [\sum_i \chi_i \hat e_i]_\times$: for the paper's Table 3 these are exactly the
    /// printed matrices of eq 17-19.
    SmallAngle,
}

/// A validated, compiled turntable. Cheap to clone.
#[derive(Debug, Clone, PartialEq)]
pub struct Turntable {
    factors: Vec<Factor>,
    joints: Vec<Joint>,
    errors: Vec<ErrorInfo>,
    translations: Vec<ErrorInfo>,
    plan: Vec<PlanStep>,
    free_joints: Vec<usize>,
    descriptions: BTreeMap<String, String>,
    /// Factor indices of the error segments $\mathbf E_s$ and of the nominal blocks
    /// $\mathbf A_s$ after them (rotations only).
    segments: Vec<(Vec<usize>, Vec<usize>)>,
}

/// Whether `name` matches `[a-z][a-z0-9_]*`.
#[must_use]
pub fn is_valid_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('a'..='z'))
        && chars.all(|c| matches!(c, 'a'..='z' | '0'..='9' | '_'))
}

/// The named factors of a description: each name's factor, the joints, the angular errors and
/// the translations in order of appearance.
struct Named<'d> {
    seen: BTreeMap<&'d str, usize>,
    joints: Vec<Joint>,
    rotations: Vec<ErrorInfo>,
    translations: Vec<ErrorInfo>,
}

/// Check every factor's name (valid, unique) and its fixed angle (finite); collect the joints
/// and the errors in order of appearance.
fn named_factors(factors: &[FactorSpec]) -> Result<Named<'_>, KinematicsError> {
    let mut n = Named {
        seen: BTreeMap::new(),
        joints: Vec::new(),
        rotations: Vec::new(),
        translations: Vec::new(),
    };
    for (i, f) in factors.iter().enumerate() {
        let (kind, name) = match f {
            FactorSpec::Joint { name, .. } => ("joint", name),
            FactorSpec::Error { name, .. } | FactorSpec::Translation { name, .. } => {
                ("error", name)
            }
            FactorSpec::Fixed { angle_rad, .. } => {
                finite(format!("factors[{i}].fixed"), *angle_rad).map_err(|_| {
                    description(format!("factors[{i}].fixed_deg"), "must be finite")
                })?;
                continue;
            }
        };
        let key = format!("factors[{i}].{kind}");
        if !is_valid_name(name) {
            return Err(description(
                key,
                format!(
                    "`{name}` is not a valid name (lower-case letter, then lower-case letters, digits or `_`)"
                ),
            ));
        }
        if let Some(first) = n.seen.insert(name, i) {
            return Err(description(
                key,
                format!("`{name}` is already the name of factors[{first}]"),
            ));
        }
        match f {
            FactorSpec::Joint { name, about } => n.joints.push(Joint {
                name: name.clone(),
                about: *about,
                range_rad: [0.0, TAU],
                factor: i,
            }),
            FactorSpec::Error { name, about } => n.rotations.push(ErrorInfo {
                name: name.clone(),
                axis: *about,
                factor: i,
            }),
            FactorSpec::Translation { name, along } => {
                n.translations.push(ErrorInfo {
                    name: name.clone(),
                    axis: *along,
                    factor: i,
                });
            }
            FactorSpec::Fixed { .. } => {}
        }
    }
    Ok(n)
}

/// The angular errors and the translations in the order `error_order` gives (a permutation of
/// all errors, checked).
fn ordered_errors(
    order: &[String],
    rotations: &[ErrorInfo],
    translations: &[ErrorInfo],
    joints: &[Joint],
) -> Result<(Vec<ErrorInfo>, Vec<ErrorInfo>), KinematicsError> {
    let mut listed = BTreeSet::new();
    let mut errors = Vec::new();
    let mut ordered_translations = Vec::new();
    for (k, name) in order.iter().enumerate() {
        let key = format!("error_order[{k}]");
        if !listed.insert(name.as_str()) {
            return Err(description(key, format!("`{name}` is listed twice")));
        }
        if let Some(e) = rotations.iter().find(|e| &e.name == name) {
            errors.push(e.clone());
        } else if let Some(e) = translations.iter().find(|e| &e.name == name) {
            ordered_translations.push(e.clone());
        } else if joints.iter().any(|j| &j.name == name) {
            return Err(description(
                key,
                format!("`{name}` is a joint, not an error"),
            ));
        } else {
            return Err(description(
                key,
                format!("`{name}` is not an error of the factors"),
            ));
        }
    }
    let missing: Vec<&str> = rotations
        .iter()
        .chain(translations)
        .map(|e| e.name.as_str())
        .filter(|n| !listed.contains(n))
        .collect();
    if !missing.is_empty() {
        return Err(description(
            "error_order",
            format!(
                "must list every error once; missing: {}",
                missing.join(", ")
            ),
        ));
    }
    Ok((errors, ordered_translations))
}

/// Each `joint_ranges_deg` entry checked (a joint, finite, min below max, at most one turn)
/// and set on its joint.
fn joint_ranges(
    ranges: &[(String, [f64; 2])],
    joints: &mut [Joint],
) -> Result<(), KinematicsError> {
    for (name, [lo, hi]) in ranges {
        let key = format!("joint_ranges_deg.{name}");
        let Some(j) = joints.iter_mut().find(|j| &j.name == name) else {
            return Err(description(key, format!("`{name}` is not a joint")));
        };
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(description(key, "min and max must be finite"));
        }
        if lo >= hi {
            return Err(description(
                key,
                format!(
                    "min must be below max, found [{}, {}] deg",
                    lo.to_degrees(),
                    hi.to_degrees()
                ),
            ));
        }
        if hi - lo > TAU * (1.0 + 1e-12) {
            return Err(description(
                key,
                format!(
                    "a range spans at most one turn (360 deg), found {} deg",
                    (hi - lo).to_degrees()
                ),
            ));
        }
        j.range_rad = [*lo, *hi];
    }
    Ok(())
}

/// The compiled factors: each joint and error by its index in its (ordered) list.
fn compile_factors(
    specs: &[FactorSpec],
    joints: &[Joint],
    errors: &[ErrorInfo],
    translations: &[ErrorInfo],
) -> Vec<Factor> {
    let index_of = |list: &[ErrorInfo], i: usize| list.iter().position(|e| e.factor == i);
    specs
        .iter()
        .enumerate()
        .map(|(i, f)| match f {
            FactorSpec::Joint { about, .. } => Factor::Joint {
                joint: joints
                    .iter()
                    .position(|j| j.factor == i)
                    .unwrap_or_else(|| unreachable!("every joint was recorded")),
                about: *about,
            },
            FactorSpec::Error { about, .. } => Factor::Rotation {
                error: index_of(errors, i)
                    .unwrap_or_else(|| unreachable!("every error was recorded")),
                about: *about,
            },
            FactorSpec::Translation { along, .. } => Factor::Translation {
                error: index_of(translations, i)
                    .unwrap_or_else(|| unreachable!("every translation was recorded")),
                along: *along,
            },
            FactorSpec::Fixed { angle_rad, about } => Factor::Fixed {
                angle_rad: *angle_rad,
                about: *about,
            },
        })
        .collect()
}

impl Turntable {
    /// Validate and compile a description.
    ///
    /// # Errors
    /// [`KinematicsError::Description`] naming the key (`factors[3].joint`,
    /// `error_order[1]`, `joint_ranges_deg.phi2`, `descriptions.foo`) and the reason: an
    /// invalid or duplicate name, no joint at all, a non-finite fixed angle, an error order
    /// that is not a permutation of the errors, a range for an unknown joint or with
    /// $\min \ge \max$ or wider than a turn, wording for an unknown name.
    pub fn new(d: &TurntableDescription) -> Result<Self, KinematicsError> {
        if d.factors.is_empty() {
            return Err(description(
                "factors",
                "a turntable needs at least one factor",
            ));
        }
        let Named {
            seen,
            mut joints,
            rotations,
            translations,
        } = named_factors(&d.factors)?;
        if joints.is_empty() {
            return Err(description(
                "factors",
                "a turntable needs at least one joint (`{ joint = \"...\", about = \"...\" }`)",
            ));
        }
        let (errors, translations) = match &d.error_order {
            None => (rotations, translations),
            Some(order) => ordered_errors(order, &rotations, &translations, &joints)?,
        };
        joint_ranges(&d.joint_ranges_rad, &mut joints)?;
        let mut descriptions = BTreeMap::new();
        for (name, text) in &d.descriptions {
            if !seen.contains_key(name.as_str()) {
                return Err(description(
                    format!("descriptions.{name}"),
                    format!("`{name}` is neither a joint nor an error"),
                ));
            }
            descriptions.insert(name.clone(), text.clone());
        }
        let factors = compile_factors(&d.factors, &joints, &errors, &translations);
        let (plan, free_joints) = compile_plan(&factors);
        let segments = compile_segments(&factors);
        Ok(Self {
            segments,
            factors,
            joints,
            errors,
            translations,
            plan,
            free_joints,
            descriptions,
        })
    }

    /// The compiled factors, base to platform.
    #[must_use]
    pub fn factors(&self) -> &[Factor] {
        &self.factors
    }

    /// The joints, in pose order (order of appearance).
    #[must_use]
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The angular errors, in the order of $\chi$.
    #[must_use]
    pub fn rotation_errors(&self) -> &[ErrorInfo] {
        &self.errors
    }

    /// The error translations, in the order of the translation vector.
    #[must_use]
    pub fn translation_errors(&self) -> &[ErrorInfo] {
        &self.translations
    }

    /// Joint names, pose order.
    #[must_use]
    pub fn joint_names(&self) -> Vec<&str> {
        self.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// Angular error names, order of $\chi$.
    #[must_use]
    pub fn rotation_error_names(&self) -> Vec<&str> {
        self.errors.iter().map(|e| e.name.as_str()).collect()
    }

    /// Translation error names.
    #[must_use]
    pub fn translation_error_names(&self) -> Vec<&str> {
        self.translations.iter().map(|e| e.name.as_str()).collect()
    }

    /// Number of joints.
    #[must_use]
    pub fn n_joints(&self) -> usize {
        self.joints.len()
    }

    /// Number of angular errors (length of $\chi$).
    #[must_use]
    pub fn n_rotation_errors(&self) -> usize {
        self.errors.len()
    }

    /// Number of error translations.
    #[must_use]
    pub fn n_translation_errors(&self) -> usize {
        self.translations.len()
    }

    /// Index in $\chi$ of the angular error called `name`.
    #[must_use]
    pub fn rotation_error_index(&self, name: &str) -> Option<usize> {
        self.errors.iter().position(|e| e.name == name)
    }

    /// Index of the joint called `name`.
    #[must_use]
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The wording of a joint or error for reports, if the description gives one.
    #[must_use]
    pub fn description_of(&self, name: &str) -> Option<&str> {
        self.descriptions.get(name).map(String::as_str)
    }

    /// Joint ranges $[\min, \max]$, rad, pose order.
    #[must_use]
    pub fn joint_ranges_rad(&self) -> Vec<[f64; 2]> {
        self.joints.iter().map(|j| j.range_rad).collect()
    }

    /// The flat evaluation plan of $\Delta\mathbf R$ (see [`PlanStep`]); the leading nominal
    /// block is left out (it cancels).
    #[doc(hidden)]
    #[must_use]
    pub fn plan(&self) -> &[PlanStep] {
        &self.plan
    }

    /// The joints the orientation error depends on: those after the first error rotation
    /// (the joints before it cancel from $\Delta\mathbf R$), pose indices in order of
    /// appearance.
    #[must_use]
    pub fn free_joints(&self) -> &[usize] {
        &self.free_joints
    }

    /// Number of error segments $m$ (maximal runs of error rotations between nominal
    /// rotations).
    #[doc(hidden)]
    #[must_use]
    pub fn n_segments(&self) -> usize {
        self.segments.len()
    }

    /// The nominal data of the segmented evaluation at `pose`: $\mathbf B_1 = \mathbf A_1
    /// \cdots\mathbf A_m$ and every $\mathbf A_s^T$, where
    /// $\mathbf R_t = \mathbf A_0\mathbf E_1\mathbf A_1\cdots\mathbf E_m\mathbf A_m$ (see the
    /// [module](self)). Compute it once per pose; then [`PoseFrames::delta_r_transpose_times`]
    /// costs $2m$ matrix-vector products per vector and turntable.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a pose of the wrong length.
    #[doc(hidden)]
    pub fn pose_frames(&self, pose: &Pose) -> Result<PoseFrames, KinematicsError> {
        self.check_pose(pose)?;
        let p = pose.angles_rad();
        let blocks: Vec<Matrix3<f64>> = self
            .segments
            .iter()
            .map(|(_, block)| {
                block.iter().fold(Matrix3::identity(), |m, &f| {
                    m * self.factor_rotation(&self.factors[f], p, None)
                })
            })
            .collect();
        let b1 = blocks.iter().fold(Matrix3::identity(), |m, a| m * a);
        let blocks_t = self
            .segments
            .iter()
            .zip(&blocks)
            .map(|((_, block), a)| (!block.is_empty()).then(|| a.transpose()))
            .collect();
        Ok(PoseFrames { b1, blocks_t })
    }

    /// The error segment rotations $\mathbf E_s$ for $\chi$ into `out` (one per segment,
    /// see [`Turntable::n_segments`]): the part of a turntable's orientation error that does
    /// not depend on the pose.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a $\chi$ or an `out` of the wrong length.
    #[doc(hidden)]
    pub fn segment_rotations(
        &self,
        chi: &[f64],
        out: &mut [Matrix3<f64>],
    ) -> Result<(), KinematicsError> {
        length("chi", self.n_rotation_errors(), chi.len())?;
        length("segment rotations", self.n_segments(), out.len())?;
        for ((errs, _), o) in self.segments.iter().zip(out.iter_mut()) {
            *o = errs.iter().fold(Matrix3::identity(), |m, &f| {
                m * self.factor_rotation(&self.factors[f], &[], Some(chi))
            });
        }
        Ok(())
    }

    /// Zero errors of the right lengths.
    #[must_use]
    pub fn zero_errors(&self) -> TurntableErrors {
        TurntableErrors::zero(self.n_rotation_errors(), self.n_translation_errors())
    }

    /// Check that `pose` has one angle per joint.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) naming `pose`.
    pub fn check_pose(&self, pose: &Pose) -> Result<(), KinematicsError> {
        Ok(length("pose", self.n_joints(), pose.len())?)
    }

    /// Check that `errors` has one value per angular error and per translation.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) naming `chi` or `translations`.
    pub(crate) fn check_errors(&self, errors: &TurntableErrors) -> Result<(), KinematicsError> {
        length("chi", self.n_rotation_errors(), errors.chi_rad().len())?;
        Ok(length(
            "translations",
            self.n_translation_errors(),
            errors.translations_m().len(),
        )?)
    }

    /// The joint angles of `pose` and the angular errors of `errors` (rad), both checked
    /// ([`Turntable::check_pose`], [`Turntable::check_errors`]).
    ///
    /// # Errors
    /// As [`Turntable::check_pose`] and [`Turntable::check_errors`].
    pub(crate) fn checked<'a>(
        &self,
        pose: &'a Pose,
        errors: &'a TurntableErrors,
    ) -> Result<(&'a [f64], &'a [f64]), KinematicsError> {
        self.check_pose(pose)?;
        self.check_errors(errors)?;
        Ok((pose.angles_rad(), errors.chi_rad()))
    }

    /// The rotation of one factor (identity for a translation), `chi = None` for the nominal
    /// chain (errors zero).
    pub(crate) fn factor_rotation(
        &self,
        f: &Factor,
        pose: &[f64],
        chi: Option<&[f64]>,
    ) -> Matrix3<f64> {
        match *f {
            Factor::Joint { joint, about } => rot_signed(about, pose[joint]),
            Factor::Rotation { error, about } => match chi {
                Some(chi) => rot_signed(about, chi[error]),
                None => Matrix3::identity(),
            },
            Factor::Translation { .. } => Matrix3::identity(),
            Factor::Fixed { angle_rad, about } => rot_signed(about, angle_rad),
        }
    }

    /// The nominal rotation $\mathbf R_d$ (platform to base), eq 21, for angles (rad) already
    /// checked.
    pub(crate) fn nominal_rotation_unchecked(&self, pose: &[f64]) -> Matrix3<f64> {
        self.factors.iter().fold(Matrix3::identity(), |m, f| {
            m * self.factor_rotation(f, pose, None)
        })
    }

    /// The intended direction-cosine matrix $\mathbf R_d$ (platform frame to base frame),
    /// eq 21.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a pose of the wrong length.
    pub fn nominal_rotation(&self, pose: &Pose) -> Result<Matrix3<f64>, KinematicsError> {
        self.check_pose(pose)?;
        Ok(self.nominal_rotation_unchecked(pose.angles_rad()))
    }

    /// $\mathbf R_t$ for checked inputs.
    pub(crate) fn actual_rotation_unchecked(
        &self,
        pose: &[f64],
        chi: &[f64],
        kind: ChainKind,
    ) -> Matrix3<f64> {
        match kind {
            ChainKind::Exact => self.factors.iter().fold(Matrix3::identity(), |m, f| {
                m * self.factor_rotation(f, pose, Some(chi))
            }),
            ChainKind::SmallAngle => {
                let mut m = Matrix3::identity();
                let mut group = nalgebra::Vector3::zeros();
                let mut open = false;
                for f in &self.factors {
                    if let Factor::Rotation { error, about } = *f {
                        group += about.unit() * chi[error];
                        open = true;
                        continue;
                    }
                    if open {
                        m *= Matrix3::identity() + skew(&group);
                        group = nalgebra::Vector3::zeros();
                        open = false;
                    }
                    m *= self.factor_rotation(f, pose, None);
                }
                if open {
                    m *= Matrix3::identity() + skew(&group);
                }
                m
            }
        }
    }

    /// The actual direction-cosine matrix $\mathbf R_t$ (eq 22's rotation part).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn actual_rotation(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
        kind: ChainKind,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        self.checked(pose, errors)
            .map(|(p, chi)| self.actual_rotation_unchecked(p, chi, kind))
    }

    /// The orientation error matrix $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ of eq 23
    /// (platform frame as intended, from platform frame as built).
    ///
    /// For [`ChainKind::Exact`] it is a rotation; for [`ChainKind::SmallAngle`] it is
    /// orthonormal only to first order.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
        kind: ChainKind,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        Ok(self.nominal_rotation(pose)?.transpose() * self.actual_rotation(pose, errors, kind)?)
    }

    /// The nominal homogeneous transform $\mathbf T_d$ (eq 21).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for a pose of the wrong length.
    pub fn nominal_transform(&self, pose: &Pose) -> Result<Matrix4<f64>, KinematicsError> {
        Ok(homogeneous(&self.nominal_rotation(pose)?))
    }

    /// The actual homogeneous transform $\mathbf T_t$ with every error exact (eq 22), error
    /// translations in metres.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn actual_transform(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<Matrix4<f64>, KinematicsError> {
        let (p, chi) = self.checked(pose, errors)?;
        let tr = errors.translations_m();
        Ok(self.factors.iter().fold(Matrix4::identity(), |m, f| {
            m * match *f {
                Factor::Translation { error, along } => translation(&(along.unit() * tr[error])),
                _ => homogeneous(&self.factor_rotation(f, p, Some(chi))),
            }
        }))
    }

    /// Analytic Jacobian of the exact chain's eq-24 read-out
    /// $(\Delta R_{13}, \Delta R_{21}, \Delta R_{32})$ with respect to $\chi$, at any pose and
    /// any (not only small) errors: rows $\psi, \theta, \gamma$, one column per angular error.
    ///
    /// # Formula
    /// With $\mathbf R_t = F_1 \cdots F_n$ and $F_j = R_{\hat e_j}(\chi_i)$,
    /// $$\frac{\partial \Delta\mathbf R}{\partial \chi_i} = \mathbf R_d^T\, F_1\cdots F_j\,[\hat e_j]_\times\, F_{j+1}\cdots F_n.$$
    /// At $\chi = 0$ it equals the first-order model ([`crate::LinearModel`]).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn jacobian(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<DMatrix<f64>, KinematicsError> {
        self.checked(pose, errors)
            .map(|(p, chi)| self.jacobian_unchecked(p, chi))
    }

    pub(crate) fn jacobian_unchecked(&self, pose: &[f64], chi: &[f64]) -> DMatrix<f64> {
        let mats: Vec<Matrix3<f64>> = self
            .factors
            .iter()
            .map(|f| self.factor_rotation(f, pose, Some(chi)))
            .collect();
        let n = mats.len();
        let mut prefix = vec![Matrix3::identity(); n + 1];
        for j in 0..n {
            prefix[j + 1] = prefix[j] * mats[j];
        }
        let mut suffix = vec![Matrix3::identity(); n + 1];
        for j in (0..n).rev() {
            suffix[j] = mats[j] * suffix[j + 1];
        }
        let rd_t = self.nominal_rotation_unchecked(pose).transpose();
        let mut jac = DMatrix::zeros(3, self.n_rotation_errors());
        for (j, f) in self.factors.iter().enumerate() {
            if let Factor::Rotation { error, about } = *f {
                let d = rd_t * prefix[j + 1] * skew(&about.unit()) * suffix[j + 1];
                jac[(0, error)] = d[(0, 2)];
                jac[(1, error)] = d[(1, 0)];
                jac[(2, error)] = d[(2, 1)];
            }
        }
        jac
    }

    /// $(\Delta\psi, \Delta\theta, \Delta\gamma)$ (eq 24 read-out, rad) of the exact chain by
    /// the flat plan with unit quaternions ([`PlanStep`]): equal to the matrix chain to
    /// rounding, and the reference for specialised evaluators of the plan.
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) for inputs of the wrong length.
    pub fn plan_orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<[f64; 3], KinematicsError> {
        self.checked(pose, errors)
            .map(|(p, chi)| self.plan_unchecked(p, chi))
    }

    pub(crate) fn plan_unchecked(&self, pose: &[f64], chi: &[f64]) -> [f64; 3] {
        let mut q = [1.0, 0.0, 0.0, 0.0];
        for step in &self.plan {
            match *step {
                PlanStep::Error { chi: i, axis, sign } => {
                    let (s, c) = (0.5 * sign * chi[i]).sin_cos();
                    q = quat_mul_axis(q, axis, s, c);
                }
                PlanStep::Joint { joint, axis, sign } => {
                    let (s, c) = (sign * pose[joint]).sin_cos();
                    q = quat_conjugate_axis(q, axis, s, c);
                }
                PlanStep::Fixed { axis, sin, cos } => {
                    q = quat_conjugate_axis(q, axis, sin, cos);
                }
            }
        }
        quat_readout(q)
    }
}

/// $q \otimes (c, s\,\hat e_{\text{axis}})$ for a quaternion `q = [w, x, y, z]`.
#[doc(hidden)]
#[inline(always)]
#[must_use]
pub fn quat_mul_axis(q: [f64; 4], axis: Axis, s: f64, c: f64) -> [f64; 4] {
    let [w, x, y, z] = q;
    match axis {
        Axis::X => [w * c - x * s, w * s + x * c, y * c + z * s, z * c - y * s],
        Axis::Y => [w * c - y * s, x * c - z * s, w * s + y * c, x * s + z * c],
        Axis::Z => [w * c - z * s, x * c + y * s, y * c - x * s, w * s + z * c],
    }
}

/// $n^{-1} \otimes q \otimes n$ for the rotation $n$ about `axis` whose angle has sine `s` and
/// cosine `c`: the vector part turned by $R_{\text{axis}}(-\text{angle})$.
#[doc(hidden)]
#[inline(always)]
#[must_use]
pub fn quat_conjugate_axis(q: [f64; 4], axis: Axis, s: f64, c: f64) -> [f64; 4] {
    let [w, x, y, z] = q;
    match axis {
        Axis::X => [w, x, c * y + s * z, c * z - s * y],
        Axis::Y => [w, c * x - s * z, y, s * x + c * z],
        Axis::Z => [w, c * x + s * y, c * y - s * x, z],
    }
}

/// The eq-24 read-out $(\Delta R_{13}, \Delta R_{21}, \Delta R_{32})$ of a unit quaternion.
#[doc(hidden)]
#[inline(always)]
#[must_use]
pub fn quat_readout(q: [f64; 4]) -> [f64; 3] {
    let [w, x, y, z] = q;
    [
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        2.0 * (y * z + w * x),
    ]
}

/// The error segments and the nominal blocks after them (factor indices; translations
/// skipped; the leading nominal block dropped).
fn compile_segments(factors: &[Factor]) -> Vec<(Vec<usize>, Vec<usize>)> {
    let mut out: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
    for (i, f) in factors.iter().enumerate() {
        match f {
            Factor::Rotation { .. } => match out.last_mut() {
                Some((errs, block)) if block.is_empty() => errs.push(i),
                _ => out.push((vec![i], Vec::new())),
            },
            Factor::Joint { .. } | Factor::Fixed { .. } => {
                if let Some((_, block)) = out.last_mut() {
                    block.push(i);
                }
            }
            Factor::Translation { .. } => {}
        }
    }
    out
}

/// The plan of the factors and the free joints (see the module documentation).
fn compile_plan(factors: &[Factor]) -> (Vec<PlanStep>, Vec<usize>) {
    let mut plan = Vec::new();
    let mut free = Vec::new();
    let mut started = false;
    for f in factors {
        match *f {
            Factor::Rotation { error, about } => {
                started = true;
                plan.push(PlanStep::Error {
                    chi: error,
                    axis: about.axis,
                    sign: about.sign(),
                });
            }
            Factor::Joint { joint, about } if started => {
                free.push(joint);
                plan.push(PlanStep::Joint {
                    joint,
                    axis: about.axis,
                    sign: about.sign(),
                });
            }
            Factor::Fixed { angle_rad, about } if started => {
                let (s, c) = (about.sign() * angle_rad).sin_cos();
                plan.push(PlanStep::Fixed {
                    axis: about.axis,
                    sin: s,
                    cos: c,
                });
            }
            _ => {}
        }
    }
    // Trailing conjugations after the last error are needed (B_m), leading ones are not.
    (plan, free)
}
