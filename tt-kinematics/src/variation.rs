//! Errors that vary with a shaft angle: the error model of each angular error, the expansion of
//! $\chi$ into coefficients (one *bound group* per error) and the dual norm of each group's
//! bound set.
//!
//! A real axis does not hold one constant error: bearing wobble and encoder errors vary with
//! the shaft angle $\phi$ of the joint that carries them, as a sum of harmonics (Qu and Yao
//! 2006 measure the wobble of an axis as a function of its angle). Each angular error $\chi_j$
//! declares one of
//!
//! - [`ErrorVariation::Constant`] (the paper's model, the default): one value, coefficient
//!   $c_0$;
//! - [`ErrorVariation::Harmonics`] of a joint: $\chi_j(\phi) = c_0 + \sum_{k \in K} a_k\cos k\phi
//!   + b_k\sin k\phi$, coefficients $(c_0, a_{k_1}, b_{k_1}, \dots)$;
//! - [`ErrorVariation::Any`] function of a joint's angle: one free value per distinct angle
//!   of that joint in the schedule.
//!
//! A tolerance bounds the error over the whole revolution, $\lvert\chi_j(\phi)\rvert \le
//! \mathrm{UB}_j$ for all $\phi$. Everything downstream of the chain is linear in the
//! coefficients at first order, so a linear functional $s$ of one group's coefficients has the
//! worst case $\mathrm{UB}_j\,d_j(s)$ over the group's bound set, with $d_j$ the dual norm of
//! the set ([`BoundGroup::dual_norm`]):
//!
//! - constant: $\lvert s_0\rvert$;
//! - any: $\sum_{\text{angles}} \lvert s_a\rvert$ (the $\ell_1$ norm);
//! - harmonics: $\max\{s\cdot c : \lVert p_c\rVert_\infty \le 1\}$, a linear program over the
//!   trigonometric polynomials bounded by one, solved on a grid and made rigorous by weak
//!   duality (see [`harmonic_dual_norm`]).
//!
//! The worst case of an output is then $\sum_j \mathrm{UB}_j\,d_j(s_j)$: still linear in the
//! bounds, so the worst case, the check and the allocation take $d_j$ where the constant model
//! has $\lvert c_j\rvert$. Since the sets are nested (constant $\subset$ harmonics $\subset$
//! any, restricted to the schedule), $d_{\text{const}} \le d_{\text{harm}} \le
//! d_{\text{any}}$. At a single pose every model lets $\chi_j$ take any value in
//! $[-\mathrm{UB}_j, \mathrm{UB}_j]$, so the orientation worst case of one pose (eq 31-33,
//! Lemma 1) does not change; what changes is the calibration, which sees a different error at
//! each test position.

use crate::error::{KinematicsError, description};
use crate::turntable::Turntable;
use tt_core::Pose;

/// The largest harmonic order a study may declare (a 64th harmonic of a shaft angle is far
/// beyond what a bearing or an encoder shows; the grid of the dual norm grows with it).
pub const MAX_HARMONIC_ORDER: u32 = 64;

/// Grid points per harmonic order of the dual-norm program ([`harmonic_dual_norm`]): with
/// $M = 128K$ equispaced points, the grid value is within the factor $1 - \pi K/M = 1 -
/// \pi/128$ (2.5%) of the true dual norm (Bernstein), and the bound used is rigorous either way.
pub const GRID_POINTS_PER_ORDER: usize = 128;

/// Two angles of a joint closer than this (rad, modulo a turn) are one angle of an
/// [`ErrorVariation::Any`] error: schedule angles are written in degrees with a few decimals,
/// far coarser than 1e-9 rad.
pub(crate) const SAME_ANGLE_RAD: f64 = 1e-9;

/// How one angular error varies with the shaft angle.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum ErrorVariation {
    /// One value over the whole revolution (the paper's model).
    #[default]
    Constant,
    /// $c_0 + \sum_{k} a_k \cos k\phi + b_k \sin k\phi$ of the joint `joint`; `orders` may be
    /// empty (then the error is constant, coefficient $c_0$).
    Harmonics {
        /// The joint whose angle $\phi$ the error follows.
        joint: String,
        /// The harmonic orders $k \ge 1$, distinct.
        orders: Vec<u32>,
    },
    /// An arbitrary bounded function of the joint's angle: one free value per distinct angle
    /// of the joint in the schedule.
    Any {
        /// The joint whose angle the error follows.
        joint: String,
    },
}

impl ErrorVariation {
    /// The model's name as a study writes it (`constant`, `harmonics`, `any`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            ErrorVariation::Constant => "constant",
            ErrorVariation::Harmonics { .. } => "harmonics",
            ErrorVariation::Any { .. } => "any",
        }
    }

    /// Whether the error varies with an angle (harmonics with at least one order, or any).
    #[must_use]
    pub fn varies(&self) -> bool {
        match self {
            ErrorVariation::Constant => false,
            ErrorVariation::Harmonics { orders, .. } => !orders.is_empty(),
            ErrorVariation::Any { .. } => true,
        }
    }
}

/// Check the error models of a turntable's angular errors (in the order of $\chi$): each named
/// joint exists and comes before the error in the chain (the error rides on that joint's
/// shaft), harmonic orders are in $[1,$ [`MAX_HARMONIC_ORDER`]$]$ and distinct.
///
/// # Errors
/// [`KinematicsError::Description`] naming `factors[i].of` or `factors[i].harmonics[k]` (the
/// factor of the error), or a length error when `variations` is not one per angular error.
pub fn validate_variations(
    turntable: &Turntable,
    variations: &[ErrorVariation],
) -> Result<(), KinematicsError> {
    crate::error::length(
        "variations",
        turntable.n_rotation_errors(),
        variations.len(),
    )?;
    for (e, v) in turntable.rotation_errors().iter().zip(variations) {
        let (joint, orders) = match v {
            ErrorVariation::Constant => continue,
            ErrorVariation::Harmonics { joint, orders } => (joint, orders.as_slice()),
            ErrorVariation::Any { joint } => (joint, &[][..]),
        };
        let key = |k: &str| format!("factors[{}].{k}", e.factor);
        let j = turntable.joint_index(joint).ok_or_else(|| {
            description(
                key("of"),
                format!(
                    "`{joint}` is not a joint of the turntable ({})",
                    turntable.joint_names().join(", ")
                ),
            )
        })?;
        if turntable.joints()[j].factor > e.factor {
            return Err(description(
                key("of"),
                format!(
                    "error `{}` comes before joint `{joint}` in the chain: it does not ride on that joint's shaft and cannot follow its angle",
                    e.name
                ),
            ));
        }
        for (k, &o) in orders.iter().enumerate() {
            if o == 0 || o > MAX_HARMONIC_ORDER {
                return Err(description(
                    key(&format!("harmonics[{k}]")),
                    format!(
                        "a harmonic order is an integer in [1, {MAX_HARMONIC_ORDER}] (the constant term c0 is always included), found {o}"
                    ),
                ));
            }
            if orders[..k].contains(&o) {
                return Err(description(
                    key(&format!("harmonics[{k}]")),
                    format!("harmonic order {o} is listed twice"),
                ));
            }
        }
    }
    Ok(())
}

/// Every angular error following the shaft it rides on: the last joint before it in the chain
/// (`make(joint)` gives its model); an error before every joint (a base tilt) stays constant.
/// With `make = |j| Any { joint: j }` this is the model a sheet supports that bounds each
/// error over the whole revolution and says nothing more.
#[must_use]
pub fn on_shafts(
    turntable: &Turntable,
    make: impl Fn(&str) -> ErrorVariation,
) -> Vec<ErrorVariation> {
    turntable
        .rotation_errors()
        .iter()
        .map(|e| {
            turntable
                .joints()
                .iter()
                .rfind(|j| j.factor < e.factor)
                .map_or(ErrorVariation::Constant, |j| make(&j.name))
        })
        .collect()
}

/// The bound set of one group of coefficients.
#[derive(Debug, Clone, PartialEq)]
pub enum GroupShape {
    /// One constant, $\lvert c_0\rvert \le 1$.
    Constant,
    /// Harmonic coefficients $(c_0, a_{k_1}, b_{k_1}, \dots)$ of joint `joint`, bounded by
    /// $\lVert p\rVert_\infty \le 1$.
    Harmonics {
        /// Pose index of the joint.
        joint: usize,
        /// The orders.
        orders: Vec<u32>,
    },
    /// One value per distinct angle (`angles_rad`, in $[0, 2\pi)$) of joint `joint`, each
    /// bounded by one.
    Any {
        /// Pose index of the joint.
        joint: usize,
        /// The distinct angles of the joint in the schedule, rad in $[0, 2\pi)$.
        angles_rad: Vec<f64>,
    },
}

/// One angular error's coefficients: their place in the expanded vector, the bound set's
/// shape and each coefficient's value at every test position (the basis).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundGroup {
    /// Index of the error in $\chi$.
    pub error: usize,
    /// The error's name.
    pub name: String,
    /// Index of the group's first coefficient in the expanded vector.
    pub first: usize,
    /// The bound set.
    pub shape: GroupShape,
    /// `basis[c][p]`: coefficient `c`'s contribution to $\chi_j$ at test position `p` per unit
    /// coefficient.
    pub basis: Vec<Vec<f64>>,
    /// Schedule angles of the group's joint (rad, one per position; empty for a constant).
    angles: Vec<f64>,
    /// For an `any` error, the coefficient of each test position (its angle's index in
    /// `angles_rad`): the error's value at a position is one look-up, not a sum over every
    /// angle of the schedule. Empty otherwise.
    slot: Vec<usize>,
}

fn wrap(phi: f64) -> f64 {
    let t = phi.rem_euclid(std::f64::consts::TAU);
    if std::f64::consts::TAU - t <= SAME_ANGLE_RAD {
        0.0
    } else {
        t
    }
}

/// The harmonic basis at $\phi$: $1, \cos k_1\phi, \sin k_1\phi, \dots$.
fn harmonic_basis(orders: &[u32], phi: f64, out: &mut Vec<f64>) {
    out.clear();
    out.push(1.0);
    for &k in orders {
        let (s, c) = (f64::from(k) * phi).sin_cos();
        out.push(c);
        out.push(s);
    }
}

impl BoundGroup {
    /// Number of coefficients.
    #[must_use]
    pub fn len(&self) -> usize {
        self.basis.len()
    }

    /// Whether the group has no coefficient (never: every group has at least one).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.basis.is_empty()
    }

    /// Names of the coefficients: `name` (constant), `name.c0`, `name.a1`, `name.b1`, ...
    /// (harmonics), `name@90deg` (any).
    #[must_use]
    pub(crate) fn coefficient_names(&self) -> Vec<String> {
        match &self.shape {
            GroupShape::Constant => vec![self.name.clone()],
            GroupShape::Harmonics { orders, .. } => {
                let mut v = vec![format!("{}.c0", self.name)];
                for k in orders {
                    v.push(format!("{}.a{k}", self.name));
                    v.push(format!("{}.b{k}", self.name));
                }
                v
            }
            GroupShape::Any { angles_rad, .. } => angles_rad
                .iter()
                .map(|a| format!("{}@{}deg", self.name, a.to_degrees()))
                .collect(),
        }
    }

    /// The dual norm of the group's bound set at the functional `s` (one entry per
    /// coefficient): the largest $s \cdot c$ over the coefficients $c$ of an error bounded by
    /// one over the whole revolution. Rigorous upper bound for harmonics
    /// ([`harmonic_dual_norm`]), exact otherwise.
    ///
    /// # Panics
    /// Never for `s` of the group's length (checked with a debug assertion).
    #[must_use]
    pub fn dual_norm(&self, s: &[f64]) -> f64 {
        debug_assert_eq!(s.len(), self.len());
        match &self.shape {
            GroupShape::Constant => s[0].abs(),
            GroupShape::Any { .. } => s.iter().map(|v| v.abs()).sum(),
            GroupShape::Harmonics { orders, .. } => {
                harmonic_dual_norm(orders, s, &self.angles).upper
            }
        }
    }

    /// The dual norm's bracket at the functional `s`: `upper` as [`BoundGroup::dual_norm`]
    /// (rigorous), `lower` a value an error bounded by one over the revolution certainly
    /// reaches (equal to `upper` for a constant or an `any` error; the program's certified
    /// lower value for harmonics, [`harmonic_dual_norm`]).
    #[must_use]
    pub fn dual_norm_bracket(&self, s: &[f64]) -> HarmonicDualNorm {
        debug_assert_eq!(s.len(), self.len());
        match &self.shape {
            GroupShape::Harmonics { orders, .. } => harmonic_dual_norm(orders, s, &self.angles),
            _ => {
                let d = self.dual_norm(s);
                HarmonicDualNorm { upper: d, lower: d }
            }
        }
    }

    /// Coefficients of an error bounded by one over the revolution at which the functional
    /// `s` reaches (or, for harmonics, comes within the certified bracket of) its dual norm:
    /// the worst error shape, to be scaled by the bound.
    #[must_use]
    pub fn worst_point(&self, s: &[f64]) -> Vec<f64> {
        let sign = |v: f64| if v < 0.0 { -1.0 } else { 1.0 };
        match &self.shape {
            GroupShape::Constant | GroupShape::Any { .. } => s.iter().map(|v| sign(*v)).collect(),
            GroupShape::Harmonics { orders, .. } => harmonic_worst_shape(orders, s, &self.angles),
        }
    }

    /// The error's value at test position `p` for the group's coefficients `c`.
    #[must_use]
    pub(crate) fn value_at(&self, c: &[f64], p: usize) -> f64 {
        match self.slot.get(p) {
            // the basis is one at the position's angle and zero at every other
            Some(&a) => c[a],
            None => self.basis.iter().zip(c).map(|(b, v)| b[p] * v).sum(),
        }
    }
}

/// The expansion of $\chi$ into coefficients for a schedule: one [`BoundGroup`] per angular
/// error (order of $\chi$), the coefficients concatenated in that order.
#[derive(Debug, Clone, PartialEq)]
pub struct Expansion {
    groups: Vec<BoundGroup>,
    n_coefficients: usize,
    positions: usize,
}

impl Expansion {
    /// The expansion of `turntable`'s errors under `variations` (one per angular error, order
    /// of $\chi$) at the test positions `poses`.
    ///
    /// # Errors
    /// As [`validate_variations`]; a pose of the wrong length.
    pub fn new(
        turntable: &Turntable,
        variations: &[ErrorVariation],
        poses: &[Pose],
    ) -> Result<Self, KinematicsError> {
        validate_variations(turntable, variations)?;
        for p in poses {
            crate::error::length("pose", turntable.n_joints(), p.angles_rad().len())?;
        }
        let mut groups = Vec::with_capacity(variations.len());
        let mut first = 0;
        let mut buf = Vec::new();
        for (e, v) in turntable.rotation_errors().iter().zip(variations) {
            let error = groups.len();
            let name = e.name.clone();
            let joint_of = |j: &str| {
                turntable
                    .joint_index(j)
                    .unwrap_or_else(|| unreachable!("validated"))
            };
            let mut slot = Vec::new();
            let (shape, basis, angles) = match v {
                ErrorVariation::Constant => {
                    (GroupShape::Constant, vec![vec![1.0; poses.len()]], vec![])
                }
                ErrorVariation::Harmonics { joint, orders } => {
                    let j = joint_of(joint);
                    let all: Vec<f64> = poses.iter().map(|p| p.angles_rad()[j]).collect();
                    let mut basis = vec![Vec::with_capacity(poses.len()); 1 + 2 * orders.len()];
                    // the dual-norm program takes each distinct angle once (first seen)
                    let mut angles: Vec<f64> = Vec::new();
                    let mut seen: Vec<f64> = Vec::new();
                    for &phi in &all {
                        let w = wrap(phi);
                        let at = seen.partition_point(|d| *d < w - SAME_ANGLE_RAD);
                        if seen.get(at).is_none_or(|d| (d - w).abs() > SAME_ANGLE_RAD) {
                            seen.insert(at, w);
                            angles.push(phi);
                        }
                    }
                    for &phi in &all {
                        harmonic_basis(orders, phi, &mut buf);
                        for (b, v) in basis.iter_mut().zip(&buf) {
                            b.push(*v);
                        }
                    }
                    let shape = GroupShape::Harmonics {
                        joint: j,
                        orders: orders.clone(),
                    };
                    (shape, basis, angles)
                }
                ErrorVariation::Any { joint } => {
                    let j = joint_of(joint);
                    let angles: Vec<f64> = poses.iter().map(|p| wrap(p.angles_rad()[j])).collect();
                    let mut distinct: Vec<f64> = Vec::new();
                    for &a in &angles {
                        if !distinct.iter().any(|d| (d - a).abs() <= SAME_ANGLE_RAD) {
                            distinct.push(a);
                        }
                    }
                    distinct.sort_by(f64::total_cmp);
                    slot = angles
                        .iter()
                        .map(|a| {
                            let at = distinct.partition_point(|d| *d < a - SAME_ANGLE_RAD);
                            (at..distinct.len())
                                .find(|&i| (distinct[i] - a).abs() <= SAME_ANGLE_RAD)
                                .unwrap_or_else(|| unreachable!("every angle has its own"))
                        })
                        .collect();
                    let basis = distinct
                        .iter()
                        .map(|d| {
                            angles
                                .iter()
                                .map(|a| f64::from(u8::from((d - a).abs() <= SAME_ANGLE_RAD)))
                                .collect()
                        })
                        .collect();
                    let shape = GroupShape::Any {
                        joint: j,
                        angles_rad: distinct,
                    };
                    (shape, basis, angles)
                }
            };
            let g = BoundGroup {
                error,
                name,
                first,
                shape,
                basis,
                angles,
                slot,
            };
            first += g.len();
            groups.push(g);
        }
        Ok(Self {
            groups,
            n_coefficients: first,
            positions: poses.len(),
        })
    }

    /// The number of coefficients [`Expansion::new`] would give, counted without forming
    /// the basis (an `any` error's is one value per position and distinct angle): a caller
    /// refuses a model too large before it is built.
    ///
    /// # Errors
    /// As [`Expansion::new`].
    pub fn count_coefficients(
        turntable: &Turntable,
        variations: &[ErrorVariation],
        poses: &[Pose],
    ) -> Result<usize, KinematicsError> {
        validate_variations(turntable, variations)?;
        let mut total = 0usize;
        for v in variations {
            total += match v {
                ErrorVariation::Constant => 1,
                ErrorVariation::Harmonics { orders, .. } => 1 + 2 * orders.len(),
                ErrorVariation::Any { joint } => {
                    let j = turntable
                        .joint_index(joint)
                        .unwrap_or_else(|| unreachable!("validated"));
                    let mut a = Vec::with_capacity(poses.len());
                    for p in poses {
                        crate::error::length("pose", turntable.n_joints(), p.angles_rad().len())?;
                        a.push(wrap(p.angles_rad()[j]));
                    }
                    a.sort_by(f64::total_cmp);
                    a.dedup_by(|x, y| (*x - *y).abs() <= SAME_ANGLE_RAD);
                    a.len()
                }
            };
        }
        Ok(total)
    }

    /// The groups, order of $\chi$.
    #[must_use]
    pub fn groups(&self) -> &[BoundGroup] {
        &self.groups
    }

    /// Length of the expanded coefficient vector.
    #[must_use]
    pub fn n_coefficients(&self) -> usize {
        self.n_coefficients
    }

    /// Number of test positions.
    #[must_use]
    pub fn positions(&self) -> usize {
        self.positions
    }

    /// Whether every error is constant over the schedule (each group one coefficient of
    /// constant basis): the expansion is then $\chi$ itself.
    #[must_use]
    pub fn is_constant(&self) -> bool {
        self.groups.iter().all(|g| g.len() == 1)
    }

    /// Names of all coefficients, in order.
    #[must_use]
    pub fn coefficient_names(&self) -> Vec<String> {
        self.groups
            .iter()
            .flat_map(BoundGroup::coefficient_names)
            .collect()
    }

    /// The coefficients of the constant errors `chi` (rad): $c_0 = \chi_j$ and every
    /// harmonic zero; every angle's value $\chi_j$ for an `any` error.
    ///
    /// # Errors
    /// `chi` of the wrong length.
    pub fn constant_coefficients(&self, chi: &[f64]) -> Result<Vec<f64>, KinematicsError> {
        crate::error::length("chi", self.groups.len(), chi.len())?;
        let mut c = vec![0.0; self.n_coefficients];
        for (g, &x) in self.groups.iter().zip(chi) {
            match g.shape {
                GroupShape::Any { .. } => c[g.first..g.first + g.len()].fill(x),
                _ => c[g.first] = x,
            }
        }
        Ok(c)
    }

    /// $\chi$ at test position `p` (rad) for the coefficients `c`, written to `chi`.
    ///
    /// # Panics
    /// Debug assertion on the lengths.
    pub fn chi_at(&self, c: &[f64], p: usize, chi: &mut [f64]) {
        debug_assert_eq!(c.len(), self.n_coefficients);
        debug_assert_eq!(chi.len(), self.groups.len());
        for (g, x) in self.groups.iter().zip(chi.iter_mut()) {
            *x = g.value_at(&c[g.first..g.first + g.len()], p);
        }
    }

    /// The errors at test position `p` for the coefficients `c` (and the translations,
    /// metres): the input of any [`crate::OrientationErrorModel`], so the exact chain with
    /// angle-dependent errors is the one exact chain evaluated at $\chi(\phi_p)$.
    ///
    /// # Errors
    /// `c` of the wrong length, a non-finite value.
    pub fn errors_at(
        &self,
        c: &[f64],
        p: usize,
        translations_m: &[f64],
    ) -> Result<crate::TurntableErrors, KinematicsError> {
        crate::error::length("coefficients", self.n_coefficients, c.len())?;
        let mut chi = vec![0.0; self.groups.len()];
        self.chi_at(c, p, &mut chi);
        crate::TurntableErrors::new(chi, translations_m.to_vec())
    }

    /// The worst case of the linear functional `s` of the coefficients (one entry per
    /// coefficient) over the bounds `ub` (one per error, $\lvert\chi_j(\phi)\rvert \le
    /// \mathrm{UB}_j$ for every $\phi$): $\sum_j \mathrm{UB}_j\,d_j(s_j)$. An infinite bound
    /// counts 0 (an error no output depends on).
    ///
    /// # Panics
    /// Debug assertion on the lengths.
    #[must_use]
    pub fn worst_case(&self, s: &[f64], ub: &[f64]) -> f64 {
        debug_assert_eq!(s.len(), self.n_coefficients);
        self.dual_norms(s)
            .iter()
            .zip(ub)
            .map(|(d, u)| if u.is_finite() { d * u } else { 0.0 })
            .sum()
    }

    /// The worst coefficients for the functional `s` within the bounds `ub` (one per error;
    /// an infinite bound gives 0): each group's [`BoundGroup::worst_point`] times its bound.
    #[must_use]
    pub fn worst_point(&self, s: &[f64], ub: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0; self.n_coefficients];
        for (g, &u) in self.groups.iter().zip(ub) {
            if u.is_finite() {
                let w = g.worst_point(&s[g.first..g.first + g.len()]);
                for (o, v) in c[g.first..g.first + g.len()].iter_mut().zip(w) {
                    *o = u * v;
                }
            }
        }
        c
    }

    /// The dual norm of every group at the functional `s` (one entry per coefficient): the
    /// effect per unit bound of each error, $d_j(s_j)$, in place of the constant model's
    /// $\lvert s_j\rvert$.
    #[must_use]
    pub fn dual_norms(&self, s: &[f64]) -> Vec<f64> {
        self.groups
            .iter()
            .map(|g| g.dual_norm(&s[g.first..g.first + g.len()]))
            .collect()
    }

    /// [`Expansion::draw`] with magnitude bounds: every pair `discs[i] = (errors, w)` (rad)
    /// is drawn by [`draw_disc_pair`]'s law inside its disc, the other errors as
    /// [`Expansion::draw`] draws them (their stream first). With no disc it is
    /// [`Expansion::draw`] exactly.
    pub fn draw_with_discs(
        &self,
        ub: &[f64],
        discs: &[([usize; 2], f64)],
        mut uniform: impl FnMut() -> f64,
        out: &mut [f64],
    ) {
        self.draw(ub, &mut uniform, out);
        for &([a, b], w) in discs {
            let (ga, gb) = (&self.groups[a], &self.groups[b]);
            let mut ca = vec![0.0; ga.len()];
            let mut cb = vec![0.0; gb.len()];
            draw_disc_pair(ga, gb, w, &mut uniform, &mut ca, &mut cb);
            out[ga.first..ga.first + ga.len()].copy_from_slice(&ca);
            out[gb.first..gb.first + gb.len()].copy_from_slice(&cb);
        }
    }

    /// Coefficients of errors drawn inside the bounds `ub` (one per error) from the uniform
    /// numbers in $[0, 1)$ that `uniform` returns. The law: a constant is uniform in
    /// $[-\mathrm{UB}, \mathrm{UB}]$; an `any` error takes an independent uniform value in
    /// $[-\mathrm{UB}, \mathrm{UB}]$ at each angle; a harmonic error with $K$ orders draws an
    /// amplitude $A = U\,\mathrm{UB}$ ($U$ uniform in $[0, 1]$), splits it over the constant and
    /// the orders by weights $w_0, \dots, w_K$ uniform in $[0, 1]$ normalised to sum one, and
    /// gives each order a uniform phase and the constant a fair sign: $c_0 = \pm w_0 A$,
    /// $(a_k, b_k) = w_k A(\cos\theta_k, \sin\theta_k)$. Then $\lvert\chi(\phi)\rvert \le
    /// \lvert c_0\rvert + \sum_k \sqrt{a_k^2 + b_k^2} = A \le \mathrm{UB}$ for every $\phi$:
    /// always inside the bound, with no grid per draw.
    pub fn draw(&self, ub: &[f64], mut uniform: impl FnMut() -> f64, out: &mut [f64]) {
        debug_assert_eq!(out.len(), self.n_coefficients);
        for (g, &u) in self.groups.iter().zip(ub) {
            let c = &mut out[g.first..g.first + g.len()];
            match &g.shape {
                GroupShape::Constant | GroupShape::Any { .. } => {
                    for v in c.iter_mut() {
                        *v = u * (2.0 * uniform() - 1.0);
                    }
                }
                GroupShape::Harmonics { orders, .. } => {
                    let amplitude = u * uniform();
                    // weights into the even slots (c0, a_k), normalised below
                    let mut total = 0.0;
                    c[0] = uniform();
                    total += c[0];
                    for k in 0..orders.len() {
                        c[1 + 2 * k] = uniform();
                        total += c[1 + 2 * k];
                    }
                    let scale = if total > 0.0 { amplitude / total } else { 0.0 };
                    c[0] *= if uniform() < 0.5 { -scale } else { scale };
                    for k in 0..orders.len() {
                        let r = c[1 + 2 * k] * scale;
                        let (sn, cs) = (std::f64::consts::TAU * uniform()).sin_cos();
                        c[1 + 2 * k] = r * cs;
                        c[2 + 2 * k] = r * sn;
                    }
                }
            }
        }
    }
}

/// Draws a pair of errors inside a magnitude (disc) bound $\sqrt{\chi_a(\phi)^2 +
/// \chi_b(\phi)^2} \le w$ for every $\phi$, writing both groups' coefficients. The law,
/// from the uniform numbers $u_1, u_2, \dots$ in $[0, 1)$ of `uniform`:
///
/// - both constant: uniform in the disc, $r = w\sqrt{u_1}$, $\theta = 2\pi u_2$,
///   $(\chi_a, \chi_b) = r(\cos\theta, \sin\theta)$;
/// - both `any` of the same joint (same angles): independently uniform in the disc at each
///   angle, as above;
/// - both harmonics of the same joint with the same orders: the vector polynomial
///   $\mathbf v(\phi) = \mathbf c_0 + \sum_k \mathbf a_k\cos k\phi + \mathbf b_k\sin k\phi$
///   ($\mathbf c_0, \mathbf a_k, \mathbf b_k \in \mathbb R^2$, component $a$ and $b$) gets an
///   amplitude $A = w u$, split over the constant and the orders by weights uniform in $[0,
///   1]$ normalised to sum one; $\mathbf c_0$ takes a uniform direction in the plane and
///   $(\mathbf a_k, \mathbf b_k)$ a uniform direction on the sphere $S^3$ (Hopf coordinates:
///   $\sin^2\eta$ uniform, two uniform phases). Then $\lvert\mathbf v(\phi)\rvert \le
///   \lvert\mathbf c_0\rvert + \sum_k \sqrt{\lvert\mathbf a_k\rvert^2 + \lvert\mathbf
///   b_k\rvert^2} = A \le w$ (Cauchy-Schwarz in $(\cos k\phi, \sin k\phi)$): inside the disc
///   for every $\phi$;
/// - any other pair: each error drawn by [`Expansion::draw`]'s law within $w/\sqrt2$ (the
///   square inscribed in the disc), inside the disc, conservative.
///
/// # Panics
/// Debug assertion on the lengths.
pub fn draw_disc_pair(
    ga: &BoundGroup,
    gb: &BoundGroup,
    w: f64,
    mut uniform: impl FnMut() -> f64,
    ca: &mut [f64],
    cb: &mut [f64],
) {
    debug_assert_eq!(ca.len(), ga.len());
    debug_assert_eq!(cb.len(), gb.len());
    let tau = std::f64::consts::TAU;
    let in_disc = |uniform: &mut dyn FnMut() -> f64| {
        let r = w * uniform().sqrt();
        let (s, c) = (tau * uniform()).sin_cos();
        (r * c, r * s)
    };
    match (&ga.shape, &gb.shape) {
        (GroupShape::Constant, GroupShape::Constant) => {
            (ca[0], cb[0]) = in_disc(&mut uniform);
        }
        (
            GroupShape::Any {
                joint: ja,
                angles_rad: x,
            },
            GroupShape::Any {
                joint: jb,
                angles_rad: y,
            },
        ) if ja == jb && x == y => {
            for (a, b) in ca.iter_mut().zip(cb.iter_mut()) {
                (*a, *b) = in_disc(&mut uniform);
            }
        }
        (
            GroupShape::Harmonics {
                joint: ja,
                orders: oa,
            },
            GroupShape::Harmonics {
                joint: jb,
                orders: ob,
            },
        ) if ja == jb && oa == ob => {
            let amplitude = w * uniform();
            let k = oa.len();
            let weights: Vec<f64> = (0..=k).map(|_| uniform()).collect();
            let total: f64 = weights.iter().sum();
            let scale = if total > 0.0 { amplitude / total } else { 0.0 };
            let (s, c) = (tau * uniform()).sin_cos();
            ca[0] = weights[0] * scale * c;
            cb[0] = weights[0] * scale * s;
            for i in 0..k {
                let r = weights[1 + i] * scale;
                let eta = uniform().sqrt().asin();
                let (s1, c1) = (tau * uniform()).sin_cos();
                let (s2, c2) = (tau * uniform()).sin_cos();
                let (ce, se) = (eta.cos(), eta.sin());
                // (a_k, b_k) of component a, then of component b
                ca[1 + 2 * i] = r * ce * c1;
                ca[2 + 2 * i] = r * ce * s1;
                cb[1 + 2 * i] = r * se * c2;
                cb[2 + 2 * i] = r * se * s2;
            }
        }
        _ => {
            let inner = w / std::f64::consts::SQRT_2;
            for (g, c) in [(ga, ca), (gb, cb)] {
                let one = Expansion {
                    groups: vec![BoundGroup {
                        first: 0,
                        ..g.clone()
                    }],
                    n_coefficients: g.len(),
                    positions: g.basis.first().map_or(0, Vec::len),
                };
                one.draw(&[inner], &mut uniform, c);
            }
        }
    }
}

/// The value $p(\phi) = c_0 + \sum_k a_k\cos k\phi + b_k\sin k\phi$ of harmonic coefficients.
#[must_use]
pub fn harmonic_value(orders: &[u32], c: &[f64], phi: f64) -> f64 {
    let mut v = c[0];
    for (i, &k) in orders.iter().enumerate() {
        let (s, co) = (f64::from(k) * phi).sin_cos();
        v += c[1 + 2 * i] * co + c[2 + 2 * i] * s;
    }
    v
}

fn grid_size(orders: &[u32]) -> (usize, f64) {
    let k = orders.iter().copied().max().unwrap_or(0) as usize;
    let m = GRID_POINTS_PER_ORDER * k.max(1);
    let factor = 1.0 - std::f64::consts::PI * k as f64 / m as f64;
    (m, factor)
}

/// A certified upper bound of $\lVert p\rVert_\infty$ for harmonic coefficients `c`: the
/// largest $\lvert p\rvert$ on $M$ equispaced points divided by $1 - \pi K/M$ ($K$ the largest
/// order). Proof: Bernstein's inequality for trigonometric polynomials of degree $K$,
/// $\lVert p'\rVert_\infty \le K\lVert p\rVert_\infty$ (Zygmund, *Trigonometric Series*,
/// ch. X, 3.13), and every $\phi$ lies within $\pi/M$ of a grid point, so $\lVert p\rVert_\infty
/// \le \max_{\text{grid}}\lvert p\rvert + (\pi K/M)\lVert p\rVert_\infty$.
#[must_use]
pub fn sup_norm_upper(orders: &[u32], c: &[f64]) -> f64 {
    if orders.is_empty() {
        return c[0].abs();
    }
    let (m, factor) = grid_size(orders);
    let max = (0..m)
        .map(|i| harmonic_value(orders, c, std::f64::consts::TAU * i as f64 / m as f64).abs())
        .fold(0.0, f64::max);
    max / factor
}

/// The dual norm of the harmonic bound set at a functional, with its certificate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicDualNorm {
    /// A rigorous upper bound of $\max\{s\cdot c : \lVert p_c\rVert_\infty \le 1\}$ (the value
    /// used).
    pub upper: f64,
    /// A value the maximum certainly reaches (a polynomial of sup norm at most one attains
    /// it).
    pub lower: f64,
}

/// The coefficients of a polynomial of certified sup norm at most one at which
/// [`HarmonicDualNorm::lower`] is attained (the worst error shape found), or $\pm$ the
/// constant one when the program gives nothing better.
#[must_use]
pub fn harmonic_worst_shape(orders: &[u32], s: &[f64], extra: &[f64]) -> Vec<f64> {
    let mut best = vec![0.0; s.len()];
    best[0] = if s[0] < 0.0 { -1.0 } else { 1.0 };
    if orders.is_empty()
        || s[1..].iter().all(|v| *v == 0.0)
        || harmonic_program_work(orders, extra) > MAX_PROGRAM_WORK
    {
        return best;
    }
    let (rows, factor) = lp_rows(orders, extra, s.len());
    let (_, c) = solve_lp(&rows, s);
    if let Some(c) = c {
        let grid_max = rows
            .iter()
            .map(|row| row.iter().zip(&c).map(|(b, v)| b * v).sum::<f64>().abs())
            .fold(0.0, f64::max);
        if grid_max > 0.0 {
            let scaled: Vec<f64> = c.iter().map(|v| v * factor / grid_max).collect();
            let dot = |x: &[f64]| s.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
            if dot(&scaled) > dot(&best) {
                best = scaled;
            }
        }
    }
    best
}

/// Largest size of the dual-norm program of one functional ([`harmonic_program_work`]):
/// first and second harmonics take $(256 + D) \cdot 25$, orders 1 to 4 about $42\,000$ for
/// $D = 8$ schedule angles. Beyond it [`harmonic_dual_norm`] bounds the functional through the
/// schedule's angles alone ([`schedule_dual_bound`]), so the work of a dual norm never
/// exceeds this size whatever the orders (up to [`MAX_HARMONIC_ORDER`]).
pub const MAX_PROGRAM_WORK: usize = 50_000;

/// The size of the dual-norm program of a functional of `orders` with the schedule's angles
/// `extra` (rad; each distinct angle counted once): its rows ($M$ grid points plus the
/// distinct schedule angles) times the square of its coefficients $1 + 2\lvert K\rvert$, the
/// work of one interior-point iteration of the dense program. A program above
/// [`MAX_PROGRAM_WORK`] is not solved.
#[must_use]
pub fn harmonic_program_work(orders: &[u32], extra: &[f64]) -> usize {
    let (m, _) = grid_size(orders);
    let n = 1 + 2 * orders.len();
    let mut seen: Vec<f64> = extra.iter().map(|a| wrap(*a)).collect();
    seen.sort_by(f64::total_cmp);
    seen.dedup_by(|a, b| (*a - *b).abs() <= SAME_ANGLE_RAD);
    (m + seen.len()).saturating_mul(n * n)
}

/// A rigorous upper bound of the harmonic dual norm at `s` through the schedule's angles
/// `extra` alone, for programs above [`MAX_PROGRAM_WORK`]: with multipliers $y$ on those
/// angles only (least squares of $\mathbf B_D^T y = s$, $\mathbf B_D$ the basis at the $D$
/// angles) and the residual $r = s - \mathbf B_D^T y$, weak duality gives $\lVert y\rVert_1 +
/// \lvert r_0\rvert + 2\sum_{k\ge1}\lvert r_k\rvert$ as [`harmonic_dual_norm`] does. For a
/// functional of the values at those angles (every row of a calibration) and a basis of full
/// rank $D$ this is $\sum_a \lvert w_a\rvert$, the `any` dual norm: once the orders
/// outnumber the schedule's angles they alias there, and the harmonic set seen by the
/// calibration approaches the `any` set. Work $O(D\,n^2 + n^3)$ with $n$ coefficients.
#[must_use]
pub fn schedule_dual_bound(orders: &[u32], s: &[f64], extra: &[f64]) -> f64 {
    let n = s.len();
    let mut angles: Vec<f64> = extra.iter().map(|a| wrap(*a)).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|a, b| (*a - *b).abs() <= SAME_ANGLE_RAD);
    let d = angles.len();
    // B_D: one row per angle, one column per coefficient
    let mut b = nalgebra::DMatrix::zeros(d, n);
    let mut buf = Vec::with_capacity(n);
    for (i, &phi) in angles.iter().enumerate() {
        harmonic_basis(orders, phi, &mut buf);
        for (j, v) in buf.iter().enumerate() {
            b[(i, j)] = *v;
        }
    }
    let sv = nalgebra::DVector::from_column_slice(s);
    // y minimising |B_D^T y - s| (minimum norm when D > n): solved on the smaller Gram matrix
    let y = if d <= n {
        (&b * b.transpose()).lu().solve(&(&b * &sv))
    } else {
        (b.transpose() * &b).lu().solve(&sv).map(|z| &b * z)
    };
    let y = y
        .filter(|y| y.iter().all(|v| v.is_finite()))
        .unwrap_or_else(|| nalgebra::DVector::zeros(d));
    let r = &sv - b.transpose() * &y;
    let dual = y.iter().map(|v| v.abs()).sum::<f64>()
        + r[0].abs()
        + 2.0 * r.iter().skip(1).map(|v| v.abs()).sum::<f64>();
    (dual * (1.0 + 4.0 * f64::EPSILON)).max(s[0].abs())
}

fn lp_rows(orders: &[u32], extra: &[f64], n: usize) -> (Vec<Vec<f64>>, f64) {
    let (m, factor) = grid_size(orders);
    let mut angles: Vec<f64> = (0..m)
        .map(|i| std::f64::consts::TAU * i as f64 / m as f64)
        .collect();
    for &a in extra {
        let a = wrap(a);
        if !angles.iter().any(|b| (a - b).abs() <= SAME_ANGLE_RAD) {
            angles.push(a);
        }
    }
    let rows = angles
        .iter()
        .map(|&phi| {
            let mut b = Vec::with_capacity(n);
            harmonic_basis(orders, phi, &mut b);
            b
        })
        .collect();
    (rows, factor)
}

/// $\max\{s\cdot c : \lVert p_c\rVert_\infty \le 1\}$ over harmonic coefficients $c = (c_0,
/// a_{k_1}, b_{k_1}, \dots)$.
///
/// # Method
/// The linear program $\max s\cdot c$ subject to $\lvert p_c(\phi_m)\rvert \le 1$ on $M =$
/// [`GRID_POINTS_PER_ORDER`]$\,K$ equispaced angles plus the schedule's angles `extra`
/// (clarabel). Its dual multipliers $y$ (one per angle) give the rigorous bound: with the
/// residual $r = s - \mathbf B^T y$, every $c$ with $\lVert p_c\rVert_\infty \le 1$ has $s\cdot
/// c = y\cdot \mathbf B c + r\cdot c \le \lVert y\rVert_1 + \lvert r_0\rvert + 2\sum_{k\ge1}
/// \lvert r_k\rvert$ (the Fourier coefficients of a function bounded by one satisfy
/// $\lvert c_0\rvert \le 1$, $\lvert a_k\rvert, \lvert b_k\rvert \le 2$), whatever the solver's
/// accuracy. The bound is also at most $\sum_a\lvert s_a\rvert$ over the schedule's angles
/// (the `any` dual norm) and at least $\lvert s_0\rvert$ (the constant's). The primal solution
/// $c^*$, scaled by $(1 - \pi K/M)/\max_{\text{grid}}\lvert p_{c^*}\rvert$, has sup norm at most
/// one ([`sup_norm_upper`]) and gives `lower`.
///
/// `extra` are the angles at which the functional was built (the schedule's, rad); they make
/// the bound never exceed the `any` dual norm when $s$ is a combination of point evaluations
/// there.
#[must_use]
pub fn harmonic_dual_norm(orders: &[u32], s: &[f64], extra: &[f64]) -> HarmonicDualNorm {
    let s0 = s[0].abs();
    if orders.is_empty() || s[1..].iter().all(|v| *v == 0.0) {
        return HarmonicDualNorm {
            upper: s0,
            lower: s0,
        };
    }
    if harmonic_program_work(orders, extra) > MAX_PROGRAM_WORK {
        // the constant +-1 reaches |s_0|; the schedule's angles bound the rest
        return HarmonicDualNorm {
            upper: schedule_dual_bound(orders, s, extra),
            lower: s0,
        };
    }
    let (rows, factor) = lp_rows(orders, extra, s.len());
    let (y, c) = solve_lp(&rows, s);
    // the rigorous bound from any multipliers y
    let mut r = s.to_vec();
    for (row, yi) in rows.iter().zip(&y) {
        for (rj, bj) in r.iter_mut().zip(row) {
            *rj -= yi * bj;
        }
    }
    let dual: f64 = y.iter().map(|v| v.abs()).sum::<f64>()
        + r[0].abs()
        + 2.0 * r[1..].iter().map(|v| v.abs()).sum::<f64>();
    // the `any` bound over the schedule angles the functional lives on is not available here
    // in general; the dual bound includes those angles, so it is never above it up to the
    // solver's accuracy.
    let upper = (dual * (1.0 + 4.0 * f64::EPSILON)).max(s0);
    let lower = c
        .map(|c| {
            let grid_max = rows
                .iter()
                .map(|row| row.iter().zip(&c).map(|(b, v)| b * v).sum::<f64>().abs())
                .fold(0.0, f64::max);
            if grid_max > 0.0 {
                s.iter().zip(&c).map(|(a, b)| a * b).sum::<f64>() * factor / grid_max
            } else {
                0.0
            }
        })
        .unwrap_or(0.0)
        .max(s0)
        .min(upper);
    HarmonicDualNorm { upper, lower }
}

/// Solve $\max s\cdot c$ s.t. $-1 \le \mathbf B c \le 1$; returns the multipliers $y$ (one
/// per row; zeros when the solver fails, which still gives a rigorous, if loose, bound) and
/// the primal $c$ when solved.
fn solve_lp(rows: &[Vec<f64>], s: &[f64]) -> (Vec<f64>, Option<Vec<f64>>) {
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{
        DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
    };
    let m = rows.len();
    let n = s.len();
    let (mut ri, mut ci, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    for (i, row) in rows.iter().enumerate() {
        for (j, &b) in row.iter().enumerate() {
            ri.push(i);
            ci.push(j);
            vals.push(b);
            ri.push(m + i);
            ci.push(j);
            vals.push(-b);
        }
    }
    let a = CscMatrix::new_from_triplets(2 * m, n, ri, ci, vals);
    let p = CscMatrix::zeros((n, n));
    let q: Vec<f64> = s.iter().map(|v| -v).collect();
    let b = vec![1.0; 2 * m];
    let cones = [SupportedConeT::NonnegativeConeT(2 * m)];
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 200,
        tol_gap_abs: 1e-12,
        tol_gap_rel: 1e-12,
        tol_feas: 1e-12,
        ..DefaultSettings::default()
    };
    let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &b, &cones, settings) else {
        return (vec![0.0; m], None);
    };
    solver.solve();
    let sol = &solver.solution;
    let ok = matches!(
        sol.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) && sol.z.iter().chain(&sol.x).all(|v| v.is_finite());
    if !ok {
        return (vec![0.0; m], None);
    }
    let y = (0..m).map(|i| sol.z[i] - sol.z[m + i]).collect();
    (y, Some(sol.x.clone()))
}
