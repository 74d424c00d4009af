//! Magnitude (disc) bounds on pairs of errors (issue 22): a vendor prints one wobble per axis
//! and one perpendicularity per pair of axes, the magnitude of a tilt with two components,
//! $\sqrt{\chi_a(\phi)^2 + \chi_b(\phi)^2} \le w$ for every shaft angle $\phi$, where the
//! description has two errors. One tolerance (the radius $w$) bounds both.
//!
//! # Worst case
//! A row $r$ of the first-order model is a linear functional $s$ of the expansion's
//! coefficients ([`crate::angle`]); over a pair's bound set its worst case is $w\,D(s)$ with
//! $D$ the set's dual norm ([`PairModel::dual`]):
//!
//! - both errors constant: $D = \lVert(s_a, s_b)\rVert_2$ (exact: the worst point of a disc
//!   is along the functional);
//! - both `any` of the same joint: $D = \sum_{\text{angles}} \lVert(s_{a,\phi}, s_{b,\phi})
//!   \rVert_2$ (exact: one disc per angle);
//! - otherwise, in particular harmonics: an upper bound, the smaller of the square's
//!   $d_a + d_b$ (each error's dual norm, the disc lies in the square) and, when both errors
//!   follow the same joint, the `any` disc over the schedule's angles (a harmonic pair,
//!   restricted to the schedule, is one value of the disc per angle). Both are rigorous, so the
//!   smaller is; it is never above the square's harmonic bound and never below the constant
//!   disc's. A certified lower bound comes with it: $\lVert(\ell_a, \ell_b)\rVert_2$ with
//!   $\ell$ each error's certified lower dual value, reached by the pair $(\cos t\,p_a,
//!   \sin t\,p_b)$ of the two worst shapes $p$, which lies in the disc.
//!
//! The square of side $w$ ([`PairShape::Square`], every value copied into both components)
//! has $D = d_a + d_b$.
//!
//! # Allocation
//! The direct allocation gives a pair one variable, its radius: the pair's two columns merge
//! into one with entries $D(s_r)$ ([`PairModel::merged`]; for constant errors
//! $\lVert(M_{ra}, M_{rb})\rVert_2$), its weight is $\sqrt{w_a^2 + w_b^2}$ (so $J$ counts both
//! errors' terms, $J$ of the box with both members at the radius), its lower bound the larger
//! of the two. For the certified allocation the second-order bound needs $\sum_j
//! \lvert\chi_j\rvert$: a disc of radius $w$ gives at most $\sqrt2\,w$, a square $2w$; the
//! allocation runs on the variable $c\,w$ ($c = \sqrt2$ or 2) so that the $\ell_1$ size it
//! certifies is that sum ([`crate::AngleQuestions::allocate_direct_paired`]).
//!
//! # Monte Carlo
//! [`crate::AngleQuestions::angle_yield_with_discs`] draws each pair inside its disc by
//! [`tt_kinematics::draw_disc_pair`]'s law (uniform in the disc for constant errors, $r =
//! w\sqrt{u_1}$, $\theta = 2\pi u_2$).

use crate::DirectAllocation;
use crate::allocate::CertifyParams;
use crate::error::E2eError;
use crate::linear::Linearization;
use nalgebra::DMatrix;
use tt_kinematics::{ErrorVariation, Expansion, GroupShape};

/// How one tolerance bounds a pair of errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairShape {
    /// $\sqrt{\chi_a^2 + \chi_b^2} \le w$ (a vendor's magnitude).
    Disc,
    /// $\lvert\chi_a\rvert \le w$ and $\lvert\chi_b\rvert \le w$ (the value copied into both
    /// components).
    Square,
}

impl PairShape {
    /// The largest $\lvert\chi_a\rvert + \lvert\chi_b\rvert$ over the shape of radius (half
    /// side) one: $\sqrt2$ for the disc, 2 for the square.
    #[must_use]
    pub(crate) fn l1_gain(self) -> f64 {
        match self {
            Self::Disc => std::f64::consts::SQRT_2,
            Self::Square => 2.0,
        }
    }
}

/// A pair of errors (indices in $\chi$) under one tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pair {
    /// The two errors; the first carries the merged column.
    pub errors: [usize; 2],
    /// The bound set.
    pub shape: PairShape,
}

/// The dual norm of a pair's bound set at a functional: a rigorous upper bound and a value the
/// worst case certainly reaches (equal when exact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairDual {
    /// Rigorous upper bound (the value used).
    pub upper: f64,
    /// Certified lower bound.
    pub lower: f64,
}

/// The first-order model of a schedule under an expansion, with what the pairs' dual norms
/// need: the expansion, its linearisation ([`crate::AngleQuestions::linearization_expanded`]) and, when an
/// error is harmonic, the same model with every harmonic error as `any` of its joint.
#[derive(Debug, Clone)]
pub struct PairModel {
    expansion: Expansion,
    expanded: Linearization,
    any: Option<(Expansion, Linearization)>,
}

fn dual_of(
    ga: &tt_kinematics::BoundGroup,
    gb: &tt_kinematics::BoundGroup,
    sa: &[f64],
    sb: &[f64],
) -> Option<f64> {
    // closed forms only for two groups of the same shape (joint and angles alike)
    if ga.shape != gb.shape {
        return None;
    }
    match ga.shape {
        GroupShape::Constant => Some(sa[0].hypot(sb[0])),
        GroupShape::Any { .. } => Some(sa.iter().zip(sb).map(|(p, q)| p.hypot(*q)).sum()),
        GroupShape::Harmonics { .. } => None,
    }
}

/// The disc's dual norm at the functional `s` of `expansion`'s coefficients, for the errors
/// `a` and `b` (see the [module](self)); `any` is the same functional on the expansion with
/// every harmonic error as `any` of its joint (tightens a harmonic pair; `None`: the square's
/// bound for it).
#[must_use]
pub fn disc_dual(
    expansion: &Expansion,
    s: &[f64],
    any: Option<(&Expansion, &[f64])>,
    a: usize,
    b: usize,
) -> PairDual {
    let (ga, gb) = (&expansion.groups()[a], &expansion.groups()[b]);
    let sa = &s[ga.first..ga.first + ga.len()];
    let sb = &s[gb.first..gb.first + gb.len()];
    if let Some(d) = dual_of(ga, gb, sa, sb) {
        return PairDual { upper: d, lower: d };
    }
    let (ba, bb) = (ga.dual_norm_bracket(sa), gb.dual_norm_bracket(sb));
    let mut upper = ba.upper + bb.upper;
    if let Some((ex, t)) = any {
        let (ha, hb) = (&ex.groups()[a], &ex.groups()[b]);
        let ta = &t[ha.first..ha.first + ha.len()];
        let tb = &t[hb.first..hb.first + hb.len()];
        if let (GroupShape::Any { .. }, GroupShape::Any { .. }, Some(d)) =
            (&ha.shape, &hb.shape, dual_of(ha, hb, ta, tb))
        {
            upper = upper.min(d);
        }
    }
    PairDual {
        upper,
        lower: ba.lower.hypot(bb.lower).min(upper),
    }
}

impl PairModel {
    /// The expansion.
    #[must_use]
    pub fn expansion(&self) -> &Expansion {
        &self.expansion
    }

    /// The expansion's linearisation.
    #[must_use]
    pub fn expanded(&self) -> &Linearization {
        &self.expanded
    }

    /// The dual norm of pair `p` at row `r` of the first-order model (rows output-major).
    #[must_use]
    pub fn dual(&self, r: usize, p: Pair) -> PairDual {
        let [a, b] = p.errors;
        let s: Vec<f64> = self.expanded.matrix().row(r).iter().copied().collect();
        match p.shape {
            PairShape::Square => {
                let d = self.expansion.dual_norms(&s);
                let g = &self.expansion.groups();
                let (ga, gb) = (&g[a], &g[b]);
                let lo = ga
                    .dual_norm_bracket(&s[ga.first..ga.first + ga.len()])
                    .lower
                    + gb.dual_norm_bracket(&s[gb.first..gb.first + gb.len()])
                        .lower;
                PairDual {
                    upper: d[a] + d[b],
                    lower: lo.min(d[a] + d[b]),
                }
            }
            PairShape::Disc => {
                let t: Option<Vec<f64>> = self
                    .any
                    .as_ref()
                    .map(|(_, l)| l.matrix().row(r).iter().copied().collect());
                let any = self
                    .any
                    .as_ref()
                    .zip(t.as_deref())
                    .map(|((ex, _), t)| (ex, t));
                disc_dual(&self.expansion, &s, any, a, b)
            }
        }
    }

    /// The linearised worst case of every output (output unit) over the bounds `ub_rad` (one
    /// per error; a pair member's entry is ignored) and the pairs `pairs` of radius `w` (rad):
    /// $\max_r \sum_{j\notin\text{pairs}} \mathrm{UB}_j d_j + \sum_{\text{pairs}} w\,D$, with
    /// `upper` (rigorous) and `lower` (certified) duals: `(upper, lower)`.
    #[must_use]
    pub fn worst_case(&self, ub_rad: &[f64], pairs: &[(Pair, f64)]) -> (Vec<f64>, Vec<f64>) {
        let n = self.expanded.positions();
        let outputs = self.expanded.outputs();
        let (mut up, mut lo) = (vec![0.0_f64; outputs], vec![0.0_f64; outputs]);
        for k in 0..outputs {
            for i in 0..n {
                let r = k * n + i;
                let s: Vec<f64> = self.expanded.matrix().row(r).iter().copied().collect();
                let g = self.expansion.groups();
                let mut in_pair = vec![false; g.len()];
                let (mut u, mut l) = (0.0, 0.0);
                for &(p, w) in pairs {
                    in_pair[p.errors[0]] = true;
                    in_pair[p.errors[1]] = true;
                    if w.is_finite() {
                        let d = self.dual(r, p);
                        u += w * d.upper;
                        l += w * d.lower;
                    }
                }
                for (j, gj) in g.iter().enumerate() {
                    if !in_pair[j] && ub_rad[j].is_finite() {
                        let b = gj.dual_norm_bracket(&s[gj.first..gj.first + gj.len()]);
                        u += ub_rad[j] * b.upper;
                        l += ub_rad[j] * b.lower;
                    }
                }
                up[k] = up[k].max(u);
                lo[k] = lo[k].max(l);
            }
        }
        (up, lo)
    }

    /// The allocation model with each pair's two columns merged into the first's (entries
    /// the pair's dual norm, `upper`) and the second's zero; the other columns are the reduced
    /// linearisation's (each error's dual norm). Rounding levels of a pair add up.
    #[must_use]
    pub fn merged(&self, pairs: &[Pair]) -> Linearization {
        let rows = self.expanded.matrix().nrows();
        let errors = self.expansion.groups().len();
        let mut m = DMatrix::zeros(rows, errors);
        for r in 0..rows {
            let s: Vec<f64> = self.expanded.matrix().row(r).iter().copied().collect();
            for (j, d) in self.expansion.dual_norms(&s).into_iter().enumerate() {
                m[(r, j)] = d;
            }
            for &p in pairs {
                m[(r, p.errors[0])] = self.dual(r, p).upper;
                m[(r, p.errors[1])] = 0.0;
            }
        }
        let outputs = self.expanded.outputs();
        let mut noise = DMatrix::zeros(outputs, errors);
        for k in 0..outputs {
            for g in self.expansion.groups() {
                let sum: f64 = (g.first..g.first + g.len())
                    .map(|c| self.expanded.rounding()[(k, c)])
                    .sum();
                noise[(k, g.error)] = if g.len() == 1 { sum } else { 2.0 * sum };
            }
            for &p in pairs {
                let [a, b] = p.errors;
                noise[(k, a)] += noise[(k, b)];
                noise[(k, b)] = 0.0;
            }
        }
        Linearization::from_parts(m, self.expanded.positions(), outputs, noise)
    }
}

/// Every pair's two errors distinct, in range and in no other pair.
fn check_pairs(n_errors: usize, names: &[String], pairs: &[Pair]) -> Result<(), E2eError> {
    let mut seen = vec![false; n_errors];
    for p in pairs {
        for &j in &p.errors {
            if j >= n_errors || seen[j] || p.errors[0] == p.errors[1] {
                return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: format!(
                        "pairs.{}",
                        names.get(j).map_or_else(|| j.to_string(), Clone::clone)
                    ),
                    value: j as f64,
                    range: "an error of the turntable in one pair only, beside another error"
                        .into(),
                }));
            }
            seen[j] = true;
        }
    }
    Ok(())
}

impl crate::AngleQuestions<'_> {
    /// The pair model of `expansion` (see [`PairModel`]).
    ///
    /// # Errors
    /// As [`crate::AngleQuestions::linearization_expanded`].
    pub fn pair_model(&self, expansion: &Expansion) -> Result<PairModel, E2eError> {
        let expanded = self.linearization_expanded(expansion)?;
        let harmonic = expansion
            .groups()
            .iter()
            .any(|g| matches!(g.shape, GroupShape::Harmonics { .. }));
        let any = if harmonic {
            let joints = self.turntable().joint_names();
            let v: Vec<ErrorVariation> = expansion
                .groups()
                .iter()
                .map(|g| match &g.shape {
                    GroupShape::Constant => ErrorVariation::Constant,
                    GroupShape::Harmonics { joint, .. } | GroupShape::Any { joint, .. } => {
                        ErrorVariation::Any {
                            joint: joints[*joint].to_string(),
                        }
                    }
                })
                .collect();
            let ex = Expansion::new(self.turntable(), &v, self.poses())?;
            let lin = self.linearization_expanded(&ex)?;
            Some((ex, lin))
        } else {
            None
        };
        Ok(PairModel {
            expansion: expansion.clone(),
            expanded,
            any,
        })
    }

    /// The direct allocation with one tolerance per pair (see the [module](self)): `merged`
    /// is [`PairModel::merged`] of the same `pairs`; both members of a pair get the pair's
    /// radius; $J$ is [`crate::EndToEnd::objective`] of the returned bounds. With `certify`, the
    /// certified allocation ([`crate::EndToEnd::allocate_direct_certified_with`]) on the same model.
    ///
    /// # Errors
    /// As [`crate::EndToEnd::allocate_direct`] / [`crate::EndToEnd::allocate_direct_certified`];
    /// [`E2eError::Field`] naming `pairs.<error>` for a pair with an error out of range, twice
    /// or in two pairs.
    pub fn allocate_direct_paired(
        &self,
        merged: &Linearization,
        lower_bounds_rad: &[f64],
        pairs: &[Pair],
        certify: Option<&CertifyParams>,
    ) -> Result<DirectAllocation, E2eError> {
        let n_errors = self.n_errors();
        check_pairs(n_errors, &self.error_names(), pairs)?;
        tt_core::length("lower bounds", n_errors, lower_bounds_rad.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let base = self.combined_weights();
        let mut weights = base.clone();
        let mut lb = lower_bounds_rad.to_vec();
        let mut scale = vec![1.0; n_errors];
        for p in pairs {
            let [a, b] = p.errors;
            let c = p.shape.l1_gain();
            weights[a] = base[a].hypot(base[b]) * c;
            weights[b] = 0.0;
            lb[a] = c * lower_bounds_rad[a].max(lower_bounds_rad[b]);
            lb[b] = 0.0;
            scale[a] = c;
        }
        let mut m = merged.matrix().clone();
        for (j, c) in scale.iter().enumerate() {
            m.column_mut(j).unscale_mut(*c);
        }
        let scaled = Linearization::from_parts(
            m,
            merged.positions(),
            merged.outputs(),
            merged.rounding().clone(),
        );
        let zeros = vec![0.0; self.n_outputs()];
        let mut d = match certify {
            None => self.allocate_direct_weighted(&weights, &scaled, &lb, &zeros, None, &[])?,
            Some(params) => self.certified_weighted(&weights, &scaled, &lb, &zeros, params, &[])?,
        };
        for (u, c) in d.upper_bounds_rad.iter_mut().zip(&scale) {
            *u /= c;
        }
        for p in pairs {
            let [a, b] = p.errors;
            d.upper_bounds_rad[b] = d.upper_bounds_rad[a];
            if d.upper_bounds_rad[a].is_finite() {
                d.unconstrained.retain(|&x| x != b);
            }
        }
        d.lower_bounds_rad = lower_bounds_rad.to_vec();
        d.objective = self.objective(&d.upper_bounds_rad);
        Ok(d)
    }
}
